// rosbag2 metadata.yaml of any shape, every version's layout: parsed, then written back and re-read.
#include "bag_metadata.hpp"
#include "coloc/core/error.hpp"
#include "fuzz_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = coloc::fuzz::inputFile(data, size, "metadata.yaml");
  try {
    const coloc::io::detail::BagMetadata metadata = coloc::io::detail::readBagMetadata(path);
    // What coloc writes from what it read must read back.
    const std::string again = coloc::io::detail::bagMetadataYaml(metadata, true);
    const std::string path2 = coloc::fuzz::inputFile(reinterpret_cast<const std::uint8_t*>(again.data()), again.size(), "again.yaml");
    coloc::io::detail::readBagMetadata(path2);
  } catch (const coloc::Error&) {
  }
  return 0;
}
