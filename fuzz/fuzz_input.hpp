#pragma once
// Readers that take a path get the fuzzer's bytes through a file of their own, one per process, in
// the temporary directory (on tmpfs where the system has one).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace coloc::fuzz {

/// This process's scratch directory, removed when the process ends normally (a fuzzer's run ends so;
/// a crash leaves it beside the crash's input, which is then worth keeping).
struct ScratchDirectory {
  std::filesystem::path path;
  ScratchDirectory() : path(std::filesystem::temp_directory_path() / ("coloc-fuzz-" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path);
  }
  ~ScratchDirectory() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

/// Writes `data` to a file named `name` in this process's scratch directory and returns its path.
inline std::string inputFile(const std::uint8_t* data, std::size_t size, const std::string& name) {
  static const ScratchDirectory dir;
  const std::string path = (dir.path / name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace coloc::fuzz
