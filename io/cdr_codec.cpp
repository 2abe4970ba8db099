#include "cdr_codec.hpp"

#include <cstdio>

namespace coloc::io::detail {
namespace {

// XCDR1 messages may end with up to 3 bytes of padding (Cyclone DDS pads payloads to 4 bytes); more
// than that means the bytes were written for another type.
constexpr std::size_t kMaxTrailingPadding = 7;

std::string hex16(unsigned value) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%04x", value & 0xFFFFu);
  return text;
}

void checkEncapsulation(const std::uint8_t* data, std::size_t size) {
  if (size < 4) {
    throw CdrFormatError("truncated: " + std::to_string(size) +
                         " bytes, shorter than the 4-byte encapsulation header");
  }
  const unsigned id = unsigned{data[0]} << 8 | data[1];
  if (id == 0x0000 || id == 0x0001) return;
  if (id >= 0x0006 && id <= 0x000b) {
    throw CdrFormatError("encapsulation " + hex16(id) +
                         " is XCDR2, not supported (only XCDR1: 0x0000 CDR_BE, 0x0001 CDR_LE)");
  }
  throw CdrFormatError("unsupported encapsulation " + hex16(id) + " (only XCDR1: 0x0000 CDR_BE, 0x0001 CDR_LE)");
}

}  // namespace

bool checkSerializedMessage(const std::uint8_t* data, std::size_t size, LayoutCheck check) {
  checkEncapsulation(data, size);
  const bool big_endian = data[1] == 0x00;
  CdrChecker checker(data + 4, size - 4, big_endian);
  check(checker);
  if (checker.remaining() > kMaxTrailingPadding) {
    throw CdrFormatError(std::to_string(checker.remaining()) + " unexpected bytes after the end of the message (" +
                         std::to_string(size) + " bytes in all): written for another type?");
  }
  return big_endian;
}

void throwCodecError(std::string_view ros_type, const std::string& reason) {
  throw Error(std::string(ros_type) + ": " + reason);
}

}  // namespace coloc::io::detail
