// The CDR decoders of every message type coloc reads: the first byte picks the type, the rest is the
// serialized message (encapsulation header first), as a log or a DDS sample carries it.
#include "coloc/core/error.hpp"
#include "coloc/io/ros_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const auto kind = static_cast<coloc::io::MessageKind>(data[0] % coloc::io::kMessageKindCount);
  try {
    coloc::io::decodeMessage(kind, data + 1, size - 1);
  } catch (const coloc::Error&) {
  }
  return 0;
}
