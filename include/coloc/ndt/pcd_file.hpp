#pragma once
// PCD files (ASCII, binary and binary_compressed, as PCL writes them).
#include <string>

#include "coloc/ndt/point_cloud.hpp"

namespace coloc::ndt {

struct PcdLoadReport {
  std::size_t points_in_file = 0;
  std::size_t non_finite_dropped = 0;  ///< points with a NaN or infinite coordinate, left out
};

/// Reads x, y, z (and a per-point "time"/"t"/"timestamp" field if present). Throws coloc::Error naming
/// the file for a missing or unreadable file, a file without x/y/z, or one with no finite point.
PointCloud loadPcd(const std::string& path, PcdLoadReport* report = nullptr);

/// Writes a binary PCD with x y z. Throws coloc::Error naming the file.
void savePcd(const std::string& path, const PointCloud& cloud);

}  // namespace coloc::ndt
