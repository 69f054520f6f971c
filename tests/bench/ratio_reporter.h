// A console reporter that also keeps the real time per iteration of every run, so that a
// benchmark program can print the time ratio of a run against its peer measured in the same run.
#pragma once

#include <map>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

namespace aerocal::testing {

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs)
      if (run.run_type == Run::RT_Iteration) seconds_[run.benchmark_name()] = run.GetAdjustedRealTime();
    ConsoleReporter::ReportRuns(runs);
  }
  /// Real time per iteration (the benchmark's unit) of the run named `prefix` or `prefix/...`;
  /// -1 when it did not run.
  double TimeOf(const std::string& prefix) const {
    for (const auto& [name, time] : seconds_)
      if (name.rfind(prefix + "/", 0) == 0 || name == prefix) return time;
    return -1.0;
  }

 private:
  std::map<std::string, double> seconds_;
};

}  // namespace aerocal::testing
