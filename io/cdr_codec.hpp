#pragma once
// Fast CDR glue shared by the message codecs: the encapsulation header, the layout walk, then the
// generated type's own (de)serialize. Private to io: it includes Fast CDR.
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>
#include <fastcdr/exceptions/Exception.h>

#include <cstdint>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "cdr_check.hpp"
#include "coloc/core/error.hpp"

namespace coloc::io::detail {

/// The walk of one type's layout, field by field.
using LayoutCheck = void (*)(CdrChecker&);

/// Checks the encapsulation header and the layout; returns whether the body is big endian.
/// Throws CdrFormatError.
bool checkSerializedMessage(const std::uint8_t* data, std::size_t size, LayoutCheck check);

[[noreturn]] void throwCodecError(std::string_view ros_type, const std::string& reason);

template <class Generated>
Generated deserializeCdr(const std::uint8_t* data, std::size_t size, std::string_view ros_type, LayoutCheck check) {
  try {
    checkSerializedMessage(data, size, check);
    // Fast CDR only reads through the buffer; its interface is not const-correct.
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(const_cast<std::uint8_t*>(data)), size);
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.read_encapsulation();
    Generated message;
    message.deserialize(cdr);
    return message;
  } catch (const CdrFormatError& e) {
    throwCodecError(ros_type, e.what());
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    throwCodecError(ros_type, std::string("Fast CDR: ") + e.what());
  } catch (const std::bad_alloc&) {
    throwCodecError(ros_type, "out of memory while deserializing");
  }
}

template <class Generated>
std::vector<std::uint8_t> serializeCdr(const Generated& message, std::string_view ros_type) {
  std::vector<std::uint8_t> bytes(4 + Generated::getCdrSerializedSize(message));
  try {
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(bytes.data()), bytes.size());
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS, eprosima::fastcdr::Cdr::DDS_CDR);
    cdr.serialize_encapsulation();
    message.serialize(cdr);
    bytes.resize(cdr.getSerializedDataLength());
  } catch (const eprosima::fastcdr::exception::Exception& e) {
    throwCodecError(ros_type, std::string("Fast CDR: ") + e.what());
  }
  return bytes;
}

}  // namespace coloc::io::detail
