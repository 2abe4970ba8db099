#pragma once
// TUM trajectory files, as evo and the TUM RGB-D tools read them: one pose per line,
// "t x y z qx qy qz qw", space separated, no trailing delimiter, '#' starts a comment line.
// t is written in seconds with all nine decimals of the int64 nanosecond stamp, and read back exactly
// (the decimal digits are parsed as integers, not through a double).
#include <iosfwd>
#include <memory>
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

/// A TUM file written as the trajectory grows, so that a node running for hours keeps none of it in
/// memory. Each point is written when appended; the stream is flushed every `flush_every` points and
/// when closed. Throws coloc::Error naming the file when it cannot be created or written.
class TumWriter {
 public:
  TumWriter(const std::string& path, const std::string& comment = "", std::size_t flush_every = 50);
  ~TumWriter();
  TumWriter(const TumWriter&) = delete;
  TumWriter& operator=(const TumWriter&) = delete;
  void append(const TrajectoryPoint& point);
  /// Flushes and closes; nothing can be appended afterwards. Throws if writing failed.
  void close();
  std::size_t points() const { return points_; }
  const std::string& path() const { return path_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string path_;
  std::size_t points_ = 0, flush_every_;
};

/// Reads a TUM file. Blank and '#' lines are skipped; any other line must hold exactly 8 finite
/// numbers with a quaternion of norm 1 (within 1e-3; it is normalised). Throws coloc::Error naming the
/// file, line number and reason.
std::vector<TrajectoryPoint> readTumTrajectory(const std::string& path);
/// `source` names the stream in error messages.
std::vector<TrajectoryPoint> readTumTrajectory(std::istream& in, const std::string& source);

}  // namespace coloc::io
