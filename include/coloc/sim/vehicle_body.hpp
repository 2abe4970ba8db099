#pragma once
// The ego vehicle's body as the roadside LiDAR sees it: a chassis box (its length and width are the
// CAM's dimensions), a narrower cabin on top, and side mirrors that stick out beyond the chassis width
// at about 1 m, the parts the paper's 0.8 m height cut keeps out of the L-shape fit.
#include "coloc/sim/mesh.hpp"

namespace coloc::sim {

struct VehicleBody {
  double length = 4.5;           ///< m, chassis, bumper to bumper (sent in the CAM)
  double width = 1.8;            ///< m, chassis, without mirrors (sent in the CAM)
  double ground_clearance = 0.2; ///< m
  double chassis_height = 0.8;   ///< m, from the clearance up
  double cabin_length = 2.6, cabin_width = 1.6, cabin_height = 0.55;  ///< m
  double mirror_reach = 0.2;     ///< m beyond the chassis side
  double mirror_height = 1.05;   ///< m above the road
  bool mirrors = true;

  /// The mesh with the body centre (of the chassis footprint) at (x, y) on the road and heading `yaw`.
  TriangleMesh mesh(double x, double y, double yaw) const;
};

}  // namespace coloc::sim
