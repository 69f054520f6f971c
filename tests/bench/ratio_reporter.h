// A console reporter that also keeps the real time per iteration of every run, so that a
// benchmark program can print the time ratio of a run against its peer measured in the same run.
#pragma once

#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace aerocal::testing {

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& run : runs)
      if (run.run_type == Run::RT_Iteration) {
        seconds_[run.benchmark_name()] = run.GetAdjustedRealTime();
        cpu_seconds_[run.benchmark_name()] = run.GetAdjustedCPUTime();
      }
    ConsoleReporter::ReportRuns(runs);
  }
  /// Real time per iteration (the benchmark's unit) of the run named `prefix` or `prefix/...`;
  /// -1 when it did not run.
  double TimeOf(const std::string& prefix) const { return Find(seconds_, prefix); }
  /// The same in CPU time of the benchmark's process (the better figure for a single-threaded
  /// run on a machine that other jobs share: time spent waiting for a core is not in it).
  double CpuTimeOf(const std::string& prefix) const { return Find(cpu_seconds_, prefix); }

 private:
  static double Find(const std::map<std::string, double>& times, const std::string& prefix) {
    for (const auto& [name, time] : times)
      if (name.rfind(prefix + "/", 0) == 0 || name == prefix) return time;
    return -1.0;
  }
  std::map<std::string, double> seconds_, cpu_seconds_;
};

}  // namespace aerocal::testing
