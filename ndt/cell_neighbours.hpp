#pragma once
// Per target cell a scan point can fall into, the voxels of its 27-cell block that a point inside the
// cell can reach (their means within one resolution of the cell's box), in the 27-cell search's order.
// Gathering a cell's list costs 27 hash probes into the target's voxel table; the list depends only on
// the target, so it is gathered once and shared by every alignment against the target: the iterations
// of one alignment, the scans of a drive that fall on the same map structure, and the replays of one
// drive (the experiment matches each scan a score of times against the same targets).
//
// Thread-safe (sharded locks); lists, once given, stay where they are for the target's lifetime.
// About 1.3 MB per target once used, and 16 bytes and the list per cell kept.
// Memory is bounded: past about kMaxCells cells a list is gathered into the caller's buffer and not kept.
#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <vector>

#include "voxel_lookup.hpp"

namespace coloc::ndt {

/// Appends the voxels of `cell`'s 27-cell block whose means lie within one resolution of the cell's box.
void gatherCell(const VoxelLookup& voxels, double resolution, const Eigen::Vector3i& cell, std::vector<std::uint32_t>& out);

class CellNeighbours {
 public:
  struct List {
    const std::uint32_t* voxels = nullptr;  ///< indices into VoxelLookup::voxels()
    std::uint32_t size = 0;
    bool kept = true;  ///< false: in the caller's scratch (the bound reached), good until its next use
  };
  static constexpr std::size_t kMaxCells = std::size_t{1} << 18;  ///< about 12 MB of lists at most

  /// For the voxels of a target built at `resolution`; `voxels` must outlive this. At most about
  /// `max_cells` lists are kept.
  CellNeighbours(const VoxelLookup& voxels, double resolution, std::size_t max_cells = kMaxCells);
  ~CellNeighbours();
  CellNeighbours(const CellNeighbours&) = delete;
  CellNeighbours& operator=(const CellNeighbours&) = delete;

  double resolution() const { return resolution_; }
  /// `cell`'s list (`key`: VoxelLookup::pack(cell)). A list not kept (the bound reached) is gathered
  /// into `scratch`, which then backs it until its next use (List::kept false).
  List get(const Eigen::Vector3i& cell, std::uint64_t key, std::vector<std::uint32_t>& scratch) const;
  std::size_t cells() const;  ///< lists kept

 private:
  struct Shard;
  const VoxelLookup& voxels_;
  const double resolution_;
  const std::size_t max_per_shard_;
  std::unique_ptr<Shard[]> shards_;
};

}  // namespace coloc::ndt
