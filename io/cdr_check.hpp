#pragma once
// Walks an XCDR1 message body field by field before Fast CDR deserializes it. Fast CDR trusts a
// sequence length as far as the remaining byte count, which still lets a corrupt length allocate tens
// of times the message size for struct sequences and says nothing about which field was wrong. The
// walk checks every length against the bytes left, booleans, and that strings are NUL-terminated
// UTF-8, and reports the field by name.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace coloc::io::detail {

/// Thrown by the checker; the codec prefixes the ROS type name and rethrows coloc::Error.
class CdrFormatError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class CdrChecker {
 public:
  /// `body` starts right after the 4-byte encapsulation header; alignment is relative to it.
  CdrChecker(const std::uint8_t* body, std::size_t size, bool big_endian);

  /// `count` primitives of `size` bytes (1, 2, 4 or 8), aligned to `size`.
  void primitives(std::size_t size, std::size_t count, const char* field);
  void primitive(std::size_t size, const char* field) { primitives(size, 1, field); }
  /// A boolean: one byte, 0 or 1.
  void boolean(const char* field);
  /// A string: uint32 length including the NUL, the bytes, the NUL.
  void string(const char* field);
  /// A uint32 value (e.g. builtin_interfaces/Time nanosec), returned for range checks.
  std::uint32_t uint32(const char* field);
  /// A sequence length, checked against the bytes left given the smallest serialized element size.
  std::uint32_t sequenceLength(std::size_t min_element_size, const char* field);

  std::size_t remaining() const { return size_ - position_; }

 private:
  void align(std::size_t alignment, const char* field);
  void require(std::size_t bytes, const char* what, const char* field) const;
  std::uint32_t readUint32();

  const std::uint8_t* body_;
  std::size_t size_;
  std::size_t position_ = 0;
  bool big_endian_;
};


}  // namespace coloc::io::detail
