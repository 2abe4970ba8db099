#pragma once
// Ray casting against the world's meshes with Embree. Each mesh keeps an id, so a LiDAR return says
// what it hit (the roadside perception uses that only for ground truth, never to segment).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "coloc/sim/mesh.hpp"

namespace coloc::sim {

struct RayHit {
  float distance = -1.0f;  ///< m along the ray; < 0: no hit within range
  int mesh = -1;           ///< id given to addMesh
};

class RayCaster {
 public:
  RayCaster();
  ~RayCaster();
  RayCaster(RayCaster&&) noexcept;
  RayCaster& operator=(RayCaster&&) noexcept;

  /// Adds a static mesh; returns its id. Call commit() before casting.
  int addMesh(const TriangleMesh& mesh);
  /// Replaces the vertices of a mesh added with the same triangle count (a moving vehicle body).
  void updateMesh(int id, const TriangleMesh& mesh);
  void commit();

  /// Casts rays (unit directions) from their origins; thread-safe once committed. Packets of 8
  /// neighbouring rays (a LiDAR's rays are coherent) on every core; the hits are castOneByOne's.
  void cast(const std::vector<Eigen::Vector3f>& origins, const std::vector<Eigen::Vector3f>& directions, float max_range,
            std::vector<RayHit>& hits) const;
  /// The same, one ray at a time on the calling thread: the reference cast() is tested and measured against.
  void castOneByOne(const std::vector<Eigen::Vector3f>& origins, const std::vector<Eigen::Vector3f>& directions, float max_range,
                    std::vector<RayHit>& hits) const;

  std::size_t triangleCount() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace coloc::sim
