#include "cdr_check.hpp"

#include <cstring>

#include "coloc/core/utf8.hpp"

namespace coloc::io::detail {

CdrChecker::CdrChecker(const std::uint8_t* body, std::size_t size, bool big_endian)
    : body_(body), size_(size), big_endian_(big_endian) {}

void CdrChecker::require(std::size_t bytes, const char* what, const char* field) const {
  if (bytes > remaining()) {
    throw CdrFormatError("truncated at " + std::string(field) + ": " + what + " needs " + std::to_string(bytes) +
                         " bytes at body offset " + std::to_string(position_) + ", " + std::to_string(remaining()) +
                         " left");
  }
}

void CdrChecker::align(std::size_t alignment, const char* field) {
  const std::size_t padding = (alignment - position_ % alignment) % alignment;
  require(padding, "alignment padding", field);
  position_ += padding;
}

void CdrChecker::primitives(std::size_t size, std::size_t count, const char* field) {
  align(size, field);
  require(size * count, "the value", field);
  position_ += size * count;
}

void CdrChecker::boolean(const char* field) {
  require(1, "the boolean", field);
  const std::uint8_t value = body_[position_];
  if (value > 1) {
    throw CdrFormatError(std::string(field) + ": boolean byte " + std::to_string(value) + " at body offset " +
                         std::to_string(position_) + " is neither 0 nor 1");
  }
  ++position_;
}

std::uint32_t CdrChecker::readUint32() {
  std::uint8_t b[4];
  std::memcpy(b, body_ + position_, 4);
  position_ += 4;
  if (big_endian_) return std::uint32_t{b[0]} << 24 | std::uint32_t{b[1]} << 16 | std::uint32_t{b[2]} << 8 | b[3];
  return std::uint32_t{b[3]} << 24 | std::uint32_t{b[2]} << 16 | std::uint32_t{b[1]} << 8 | b[0];
}

std::uint32_t CdrChecker::uint32(const char* field) {
  align(4, field);
  require(4, "the value", field);
  return readUint32();
}

void CdrChecker::string(const char* field) {
  const std::uint32_t length = uint32(field);
  const std::size_t start = position_;
  if (length == 0) {
    throw CdrFormatError(std::string(field) + ": string length 0 at body offset " + std::to_string(start - 4) +
                         " (a CDR string holds at least its terminating NUL)");
  }
  if (length > remaining()) {
    throw CdrFormatError(std::string(field) + ": string length " + std::to_string(length) + " at body offset " +
                         std::to_string(start - 4) + " exceeds the " + std::to_string(remaining()) +
                         " bytes left (truncated or corrupt)");
  }
  const char* text = reinterpret_cast<const char*>(body_ + start);
  if (text[length - 1] != '\0') {
    throw CdrFormatError(std::string(field) + ": string at body offset " + std::to_string(start) +
                         " is not NUL-terminated");
  }
  if (std::memchr(text, '\0', length - 1) != nullptr) {
    throw CdrFormatError(std::string(field) + ": string at body offset " + std::to_string(start) +
                         " contains a NUL byte before its end");
  }
  if (!isValidUtf8(text, length - 1)) {
    throw CdrFormatError(std::string(field) + ": string at body offset " + std::to_string(start) +
                         " is not valid UTF-8");
  }
  position_ += length;
}

std::uint32_t CdrChecker::sequenceLength(std::size_t min_element_size, const char* field) {
  const std::uint32_t count = uint32(field);
  // Division instead of multiplication: count * size could overflow on 32-bit size_t.
  if (count > 0 && min_element_size > 0 && count > remaining() / min_element_size) {
    throw CdrFormatError(std::string(field) + ": sequence length " + std::to_string(count) + " at body offset " +
                         std::to_string(position_ - 4) + " needs at least " +
                         std::to_string(static_cast<unsigned long long>(count) * min_element_size) + " bytes, " +
                         std::to_string(remaining()) + " left (truncated or corrupt)");
  }
  return count;
}

}  // namespace coloc::io::detail
