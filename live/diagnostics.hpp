#pragma once
// The live node's /diagnostics, under the names Autoware's monitors read where coloc stands in for
// ekf_localizer and ndt_scan_matcher (their status names and keys, docs/live.md, "coloc in an Autoware system"), and one status
// of coloc's own for its inputs and what the transport lost.
#include <cstdint>

#include "coloc/io/ros_node_interfaces.hpp"
#include "coloc/live/live_localizer.hpp"

namespace coloc::live {

/// What the diagnostics remember between two reports: when NDT's and the twists' counts last moved.
struct DiagnosticsMemory {
  std::uint64_t ndt_applied = 0, twists_applied = 0, lost = 0;
  Stamp ndt_moved = 0, twists_moved = 0;
};

/// One DiagnosticArray stamped `now` from the node's status. `tick` is the filter's period (the
/// no-update counts are in ticks, as ekf_localizer counts them).
io::DiagnosticArray diagnosticsOf(const LiveStatus& status, bool activated, Stamp now, double tick, DiagnosticsMemory& memory);

}  // namespace coloc::live
