#pragma once
// Paths and reference values of the real data sets beside the repository.
#include <Eigen/Core>
#include <fstream>
#include <string>

namespace coloc::testing {

inline std::string realData(const std::string& relative) { return std::string(COLOC_SHARED_DATA_DIR) + "/" + relative; }

/// A 4x4 row-major matrix from a text file (the hdl32e_pair references).
inline Eigen::Matrix4d readMatrix4(const std::string& path) {
  std::ifstream in(path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  return m;
}

/// Translation distance and rotation angle (degrees) between two rigid transforms.
inline std::pair<double, double> poseDifference(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  const Eigen::Matrix4d d = a.inverse() * b;
  const double cos_angle = std::min(1.0, std::max(-1.0, (d.topLeftCorner<3, 3>().trace() - 1.0) / 2.0));
  return {d.topRightCorner<3, 1>().norm(), std::acos(cos_angle) * 180.0 / M_PI};
}

}  // namespace coloc::testing
