#pragma once
// The experiment's results as the paper reports them: Table I (error within each LiDAR's coverage,
// NDT only against fused, as the paper measures it and as a plain mean), Tables II and III (the
// network grid), the sweeps; the figures (error along the road, the spread over trials, the network
// grid) as SVG with the CSV behind each; and a README that puts them together.
#include <string>

#include "coloc/twin/experiment.hpp"

namespace coloc::twin {

struct ErrorInCoverage {
  double paper = 0.0;  ///< mean over the road's bins of the minimum error in each bin, m
  double plain = 0.0;  ///< mean of every sample, m
  std::size_t samples = 0;
};

/// The error of `run` where the vehicle is within `range` of the RSU. No samples: zeros.
ErrorInCoverage errorInCoverage(const ExperimentRun& run, double range, double bin_length);

/// The plain mean error of `run` where the vehicle is farther than `range` from every RSU (0: no samples).
double errorOutsideCoverage(const ExperimentRun& run, double range);

/// Writes tables, figures, CSVs and README.md into out_dir; returns Table I as Markdown.
std::string writeExperimentReport(const ExperimentResults& results, const std::string& out_dir, const std::string& command_line);

}  // namespace coloc::twin
