#pragma once
// A registry of one RSU with a VLP-32C, for tests of what happens to its fixes.
#include <string>

#include "coloc/rsu_client/rsu_registry.hpp"

namespace coloc::testing {

inline rsu_client::RsuRegistry oneRsu(const Eigen::Vector2d& position, double coverage, const std::string& id = "rsu_a",
                                      rsu_client::CovariancePlacement placement = rsu_client::CovariancePlacement::kPublished) {
  rsu_client::RsuInfo rsu;
  rsu.id = id;
  rsu.position = position;
  rsu.lidar = *rsu_client::findLidarModel("VLP-32C");
  rsu.coverage_radius = coverage;
  rsu.identity = "CN=" + id;
  return rsu_client::RsuRegistry({rsu}, placement);
}

}  // namespace coloc::testing
