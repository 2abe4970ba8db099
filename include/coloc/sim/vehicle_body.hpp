#pragma once
// The ego vehicle's body as the roadside LiDAR sees it. By default a mid-size sedan (the size of a
// Camry or an Accord: 4.88 x 1.84 x 1.445 m, wheelbase 2.825 m, 0.66 m wheels): rounded corners in plan,
// bumpers whose lower edge curves in, wheels set in from the body side and visible through their arches,
// 0.15 m ground clearance, a greenhouse narrowing to the roof and side mirrors, the parts that make a
// real car's points differ from a box's. `boxes()` is the ideal twin's car: a chassis box, a cabin box
// and mirrors. Either way, length and width are what the CAM sends: bumper to bumper, without mirrors.
#include "coloc/sim/mesh.hpp"

namespace coloc::sim {

struct VehicleBody {
  bool detailed = true;
  double length = 4.88;           ///< m, bumper to bumper (sent in the CAM)
  double width = 1.84;            ///< m, without mirrors (sent in the CAM)
  double height = 1.445;          ///< m, road to roof
  double ground_clearance = 0.15; ///< m, under the sills
  double mirror_reach = 0.2;      ///< m beyond the body side
  double mirror_height = 1.05;    ///< m above the road
  bool mirrors = true;
  // The detailed body:
  double wheelbase = 2.825, front_overhang = 0.97;  ///< m
  double wheel_radius = 0.33, wheel_width = 0.22;   ///< m
  double wheel_inset = 0.04;      ///< m from the body side to the tyre's outer face
  double arch_gap = 0.06;         ///< m between tyre and arch
  double corner_radius_front = 0.45, corner_radius_rear = 0.35;  ///< m, in plan
  double bumper_height = 0.22;    ///< m, lower edge of the bumpers
  double belt_height = 0.97;      ///< m, top of the lower body (bonnet, boot, window line)
  // The box body:
  double chassis_height = 0.8;    ///< m, from the clearance up
  double cabin_length = 2.6, cabin_width = 1.6, cabin_height = 0.55;  ///< m

  /// The ideal twin's car: 4.5 x 1.8 m boxes, 0.2 m clearance.
  static VehicleBody boxes();

  /// The mesh with the body centre (of the footprint) at (x, y) on the road and heading `yaw`. The same
  /// body always gives the same triangle count, so a moving vehicle's mesh can be updated in place.
  TriangleMesh mesh(double x, double y, double yaw) const;
};

}  // namespace coloc::sim
