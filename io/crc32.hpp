#pragma once
// CRC-32 as MCAP uses it (the zlib/PNG polynomial 0xEDB88320, reflected, initial and final xor ~0).
#include <cstddef>
#include <cstdint>

namespace coloc::io::detail {

class Crc32 {
 public:
  void update(const void* data, std::size_t size);
  std::uint32_t value() const { return ~state_; }

 private:
  std::uint32_t state_ = 0xFFFFFFFFu;
};

inline std::uint32_t crc32(const void* data, std::size_t size) {
  Crc32 crc;
  crc.update(data, size);
  return crc.value();
}

}  // namespace coloc::io::detail
