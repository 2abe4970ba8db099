#pragma once
// A Google Benchmark reporter that prints as usual and keeps each benchmark's median, so that a
// benchmark program can end with a table of ratios between runs measured in the same process.
#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace coloc::bench {

class MedianCollector : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& run : runs)
      if (run.run_type == Run::RT_Aggregate && run.aggregate_name == "median")
        medians[run.run_name.function_name][run.run_name.args] = run.GetAdjustedRealTime();
  }
  /// function name -> "arg/arg" -> median, in the benchmark's time unit
  std::map<std::string, std::map<std::string, double>> medians;
};

}  // namespace coloc::bench
