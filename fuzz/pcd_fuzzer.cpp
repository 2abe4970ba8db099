// PCD files of any shape: ascii, binary and binary_compressed (LZF) data, any header.
#include "coloc/core/error.hpp"
#include "coloc/ndt/pcd_file.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = coloc::fuzz::inputFile(data, size, "input.pcd");
  try {
    coloc::ndt::loadPcd(path);
  } catch (const coloc::Error&) {
  }
  return 0;
}
