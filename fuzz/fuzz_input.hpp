#pragma once
// Readers that take a path get the fuzzer's bytes through a file of their own, one per process, in
// the temporary directory (on tmpfs where the system has one).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace coloc::fuzz {

/// Writes `data` to a file named `name` in this process's scratch directory and returns its path.
inline std::string inputFile(const std::uint8_t* data, std::size_t size, const std::string& name) {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path d = std::filesystem::temp_directory_path() / ("coloc-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  const std::string path = (dir / name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace coloc::fuzz
