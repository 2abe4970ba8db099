#pragma once
// Paths and reference values of the real data sets in the repository's data/ folder.
#include <Eigen/Core>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

namespace coloc::testing {

/// The path of a file under data/. A missing file throws, naming it: the test that needs it fails with
/// that message (GoogleTest reports the exception) instead of crashing on an empty cloud.
inline std::string realData(const std::string& relative) {
  const std::string path = std::string(COLOC_DATA_DIR) + "/" + relative;
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error("real data file missing: " + path + " (the repository's data/ folder; see data/README.md)");
  return path;
}

/// A 4x4 row-major matrix from a text file (the hdl32e_pair references).
inline Eigen::Matrix4d readMatrix4(const std::string& path) {
  std::ifstream in(path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  if (!in) throw std::runtime_error(path + ": expected 16 numbers (a 4x4 row-major matrix)");
  return m;
}

/// Where the HDL-32E pair's source scan lies in its target (x, y of the reference transform): where
/// NDT puts a vehicle whose scan it is, with the target as the map.
inline Eigen::Vector2d wherePairsScansMatch() {
  const Eigen::Matrix4d gt1 = readMatrix4(realData("hdl32e_pair/T_target_source.gt1.txt"));
  return {gt1(0, 3), gt1(1, 3)};
}

/// Translation distance and rotation angle (degrees) between two rigid transforms.
inline std::pair<double, double> poseDifference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const Eigen::Matrix4d d = a.inverse() * b;
  const double cos_angle = std::min(1.0, std::max(-1.0, (d.topLeftCorner<3, 3>().trace() - 1.0) / 2.0));
  return {d.topRightCorner<3, 1>().norm(), std::acos(cos_angle) * 180.0 / M_PI};
}

}  // namespace coloc::testing
