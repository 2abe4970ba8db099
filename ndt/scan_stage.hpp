#pragma once
// A run of a scan's points that share one motion (a firing's time when deskewing, the whole scan
// otherwise), made ready for the voxel pass: cropped by range, moved into the sweep's start frame and
// given their voxels. Point by point, or the same arithmetic four points at a time with AVX2 where the
// CPU has it: every step the same IEEE operation in double (no fused multiply-add), so the same bits.
// The per-point work was most of a scan's preprocessing, and preprocessing about a third of a replay.
#include <Eigen/Core>
#include <cstddef>

#include "voxel_index.hpp"

namespace coloc::ndt {

/// How the run's points move: p' = (c x - s y + dx, s x + c y + dy, z), in double, rounded to float.
struct RunMotion {
  bool moves = false;  ///< false: the points as they are
  double c = 1.0, s = 0.0, dx = 0.0, dy = 0.0;
};

struct StageBounds {
  double lo = 0.0, hi = 0.0;  ///< squared ranges kept: a point with r2 < lo or r2 > hi is cropped
  double inverse = 1.0;       ///< 1 / voxel size
};

struct StagedPoint {
  Eigen::Vector3f p;      ///< moved
  VoxelCoordinates key;   ///< its voxel, when ok
  bool ok = false;        ///< not cropped, and has a voxel (finite, within integer reach)
};

/// Stages points[0 .. n - 1] into out[0 .. n - 1].
void stageRun(const Eigen::Vector3f* points, std::size_t n, const RunMotion& motion, const StageBounds& bounds, StagedPoint* out);
/// The same point by point on any CPU: the reference the vectorised path is tested against.
void stageRunPortable(const Eigen::Vector3f* points, std::size_t n, const RunMotion& motion, const StageBounds& bounds, StagedPoint* out);
/// Whether stageRun takes the vectorised path on this CPU.
bool stageRunVectorised();

}  // namespace coloc::ndt
