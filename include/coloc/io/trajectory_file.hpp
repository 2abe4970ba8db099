#pragma once
// TUM trajectory files, as evo and the TUM RGB-D tools read them: one pose per line,
// "t x y z qx qy qz qw", space separated, no trailing delimiter, '#' starts a comment line.
// t is written in seconds with all nine decimals of the int64 nanosecond stamp, and read back exactly
// (the decimal digits are parsed as integers, not through a double).
#include <iosfwd>
#include <string>
#include <vector>

#include "coloc/core/types.hpp"

namespace coloc::io {

struct TrajectoryPoint {
  Stamp stamp = 0;
  Pose pose;
};

/// Writes `points`; `comment` lines (split at '\n') are written first, each prefixed with "# ".
/// Positions and quaternion components get 9 decimals. Throws coloc::Error naming the file.
void writeTumTrajectory(const std::string& path, const std::vector<TrajectoryPoint>& points,
                        const std::string& comment = "");
void writeTumTrajectory(std::ostream& out, const std::vector<TrajectoryPoint>& points,
                        const std::string& comment = "");

/// Reads a TUM file. Blank and '#' lines are skipped; any other line must hold exactly 8 finite
/// numbers with a quaternion of norm 1 (within 1e-3; it is normalised). Throws coloc::Error naming the
/// file, line number and reason.
std::vector<TrajectoryPoint> readTumTrajectory(const std::string& path);
/// `source` names the stream in error messages.
std::vector<TrajectoryPoint> readTumTrajectory(std::istream& in, const std::string& source);

}  // namespace coloc::io
