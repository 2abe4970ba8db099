// The decoders of what other nodes send the live node besides data: service requests and replies
// (std_srvs/SetBool, NDT's alignment service) and diagnostics, and the CAMs the RSU node takes. Any
// participant on the domain may call a service or publish a CAM; the first byte picks the decoder, the
// rest is the payload (encapsulation header first).
#include "coloc/core/error.hpp"
#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/io/v2x_messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t* body = data + 1;
  const std::size_t n = size - 1;
  try {
    switch (data[0] % 6) {
      case 0: coloc::io::decodeSetBoolRequest(body, n); break;
      case 1: coloc::io::decodeSetBoolResponse(body, n); break;
      case 2: coloc::io::decodePoseAlignRequest(body, n); break;
      case 3: coloc::io::decodePoseAlignResponse(body, n); break;
      case 4: coloc::io::decodeDiagnosticArray(body, n); break;
      default: coloc::io::decodeCam(body, n); break;
    }
  } catch (const coloc::Error&) {
  }
  return 0;
}
