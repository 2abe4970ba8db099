// The DDS settings a ROS 2 node reads from its environment, read the same way, so that coloc and the
// nodes beside it meet on the same domain with the same reach without anyone setting them twice.
#include <cstdlib>
#include <string>

#include "coloc/core/error.hpp"
#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::rsu_client {

DdsConfig ddsConfigFromRosEnvironment() {
  DdsConfig config;
  if (const char* domain = std::getenv("ROS_DOMAIN_ID"); domain && *domain) {
    // 232 is the largest domain whose ports fit below 65535 with ROS 2's participant range.
    const std::string text = domain;
    char* end = nullptr;
    const long value = std::strtol(text.c_str(), &end, 10);
    if (*end != '\0' || value < 0 || value > 232)
      throw Error("ROS_DOMAIN_ID '" + text + "': expected a domain id from 0 to 232, as ROS 2 takes it");
    config.domain = static_cast<int>(value);
  }
  if (const char* local = std::getenv("ROS_LOCALHOST_ONLY"); local && *local) {
    const std::string text = local;
    if (text != "0" && text != "1") throw Error("ROS_LOCALHOST_ONLY '" + text + "': expected 0 or 1, as ROS 2 takes it");
    config.loopback_only = text == "1";
  }
  return config;
}

}  // namespace coloc::rsu_client
