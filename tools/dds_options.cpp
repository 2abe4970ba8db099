#include "dds_options.hpp"

#include <cstdio>

namespace coloc::tools {

void addDdsOptions(CLI::App* cmd, DdsOptions& o) {
  cmd->add_option("--domain", o.domain, "DDS domain, 0-232 (default: ROS_DOMAIN_ID, else 0)")->check(CLI::Range(0, 232));
  cmd->add_flag("--reliable", o.reliable, "reliable QoS instead of ROS 2 sensor data (best effort, keep last 5)");
  auto* loopback = cmd->add_flag("--loopback-only", o.loopback_only,
                                 "UDP on 127.0.0.1 only, unicast discovery: nothing leaves the machine (also ROS_LOCALHOST_ONLY=1); "
                                 "default: Fast DDS's defaults as a ROS 2 node uses them (multicast discovery on every interface, shared memory)");
  cmd->add_flag("--any-interface", o.any_interface, "every interface even when ROS_LOCALHOST_ONLY=1")->excludes(loopback);
  cmd->add_flag("--no-shared-memory", o.no_shared_memory,
                "UDP only, no shared memory between processes of this host (containers that share the network but not /dev/shm)");
  cmd->add_option("--security", o.security_dir,
                  "folder with DDS Security files: identity_ca.pem, permissions_ca.pem, governance.p7s, NAME.pem, "
                  "NAME_key.pem, NAME_permissions.p7s (NAME: --name)");
}

rsu_client::DdsConfig ddsConfig(const DdsOptions& o, const std::string& default_name) {
  rsu_client::DdsConfig c = rsu_client::ddsConfigFromRosEnvironment();
  if (o.domain) c.domain = *o.domain;
  c.reliable = o.reliable;
  if (o.loopback_only) c.loopback_only = true;
  if (o.any_interface) c.loopback_only = false;
  if (o.no_shared_memory) c.shared_memory = false;
  c.participant_name = o.name.empty() ? default_name : o.name;
  if (!o.security_dir.empty()) {
    const std::string d = o.security_dir + "/", n = c.participant_name;
    c.security = {true, d + "identity_ca.pem", d + n + ".pem", d + n + "_key.pem", d + "permissions_ca.pem", d + "governance.p7s",
                  d + n + "_permissions.p7s"};
  }
  return c;
}

void printSecurity(const rsu_client::DdsConfig& c) {
  if (c.security.enabled)
    std::printf("DDS Security on: PKI-DH authentication, access control, AES-GCM (identity %s)\n", c.security.identity_certificate.c_str());
  else
    std::printf("DDS Security OFF: fixes are accepted from any participant that publishes on the topics\n");
  std::fflush(stdout);
}

}  // namespace coloc::tools
