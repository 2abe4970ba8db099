#pragma once
// The DDS options every networked command shares (domain, QoS, interfaces, DDS Security files).
#include <CLI/CLI.hpp>
#include <string>

#include "coloc/rsu_client/dds_transport.hpp"

namespace coloc::tools {

struct DdsOptions {
  int domain = 0;
  bool reliable = false;
  bool any_interface = false;
  std::string security_dir;  ///< folder with identity_ca.pem, <name>.pem, <name>_key.pem, governance.p7s, <name>_permissions.p7s
  std::string name;
};

void addDdsOptions(CLI::App* cmd, DdsOptions& o);
rsu_client::DdsConfig ddsConfig(const DdsOptions& o, const std::string& default_name);
/// Says whether DDS Security is on; off is said, never assumed.
void printSecurity(const rsu_client::DdsConfig& c);

}  // namespace coloc::tools
