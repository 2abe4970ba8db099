#pragma once
// The DDS options every networked command shares (domain, QoS, interfaces, DDS Security files).
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::tools {

struct DdsOptions {
  std::optional<int> domain;  ///< unset: ROS_DOMAIN_ID, else 0
  bool reliable = false;
  bool loopback_only = false;  ///< also when ROS_LOCALHOST_ONLY=1
  bool any_interface = false;  ///< overrides ROS_LOCALHOST_ONLY=1
  bool no_shared_memory = false;
  std::string security_dir;  ///< folder with identity_ca.pem, <name>.pem, <name>_key.pem, governance.p7s, <name>_permissions.p7s
  std::string name;
};

void addDdsOptions(CLI::App* cmd, DdsOptions& o);
rsu_client::DdsConfig ddsConfig(const DdsOptions& o, const std::string& default_name);
/// Says whether DDS Security is on; off is said, never assumed.
void printSecurity(const rsu_client::DdsConfig& c);

}  // namespace coloc::tools
