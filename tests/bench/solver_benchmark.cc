// The solve itself (issue 31): one self-calibrating adjustment of a simulated block
// (bench_blocks.h,
// `--self-calibration all`, no snooping, no covariance: the solver alone), per solver path and
// thread count. Counters:
//   solve_s, iterations, s_per_iteration      the final solve of the adjustment
//   evaluation_s, linear_solver_s             of solve_s: residuals + Jacobians, linear solver
//   rerun_identical                           1 when a second run gives the same bits (every
//                                             estimated value, sigma0)
//   max_rel_diff_vs_ceres_1                   largest |a - b| / max(|b|, 1) of the estimated values
//                                             against Ceres on one thread (the reference)
// Run: build with -DAEROCAL_BUILD_BENCHMARKS=ON, then
//      aheavy build/tests/bench/bench_solver --benchmark_filter=BM_Solve
#include "tests/bench/bench_blocks.h"
#include "tests/support/adjustment_values.h"
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

namespace aerocal::triangulation {
namespace {

using testing::AdjustmentValues;
using testing::MaxRelativeDifference;

const Project& Block(int exposures) {
  static std::map<int, Project> blocks;
  auto it = blocks.find(exposures);
  if (it == blocks.end())
    it = blocks.emplace(exposures, testing::ProjectFromFlight(bench::SimulateBlock(exposures)))
             .first;
  return it->second;
}

AdjustmentResult Run(const Project& project, calib::SolverOptions solver) {
  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("all");
  options.data_snooping = false;
  options.estimate_covariance = false;
  options.auto_robust_start = false;
  options.solver = solver;
  return Adjust(project, options);
}

// The reference: Ceres on one thread (the deterministic default before issue 31).
const std::vector<double>& Reference(int exposures) {
  static std::map<int, std::vector<double>> refs;
  auto it = refs.find(exposures);
  if (it == refs.end()) {
    calib::SolverOptions ceres;
    ceres.engine = calib::SolverEngine::kCeres;
    it = refs.emplace(exposures, AdjustmentValues(Run(Block(exposures), ceres))).first;
  }
  return it->second;
}

// range(0): exposures; range(1): 0 Ceres deterministic (1 thread), 1 Ceres non-deterministic,
// 2 aerocal's engine (levenberg_marquardt.h); range(2): threads.
void BM_Solve(benchmark::State& state) {
  const int exposures = static_cast<int>(state.range(0));
  const Project& project = Block(exposures);
  calib::SolverOptions solver;
  solver.engine = state.range(1) == 2 ? calib::SolverEngine::kAerocal : calib::SolverEngine::kCeres;
  solver.deterministic = state.range(1) == 0;
  solver.num_threads = static_cast<int>(state.range(2));
  AdjustmentResult r;
  for (auto _ : state) r = Run(project, solver);
  const std::vector<double> first = AdjustmentValues(r);
  const std::vector<double> second = AdjustmentValues(Run(project, solver));
  state.counters["solve_s"] = r.solve.seconds;
  state.counters["iterations"] = r.solve.iterations;
  state.counters["s_per_iteration"] = r.solve.seconds / std::max(1, r.solve.iterations);
  state.counters["evaluation_s"] = r.solve.evaluation_seconds;
  state.counters["linear_solver_s"] = r.solve.linear_solver_seconds;
  state.counters["rerun_identical"] = first == second;
  state.counters["max_rel_diff_vs_ceres_1"] = MaxRelativeDifference(first, Reference(exposures));
  state.counters["observations"] = static_cast<double>(project.observations.size());
  state.SetLabel(r.solve.linear_solver + (r.solve.converged ? "" : " NOT CONVERGED"));
}
BENCHMARK(BM_Solve)
    ->ArgsProduct({{150, 600}, {0}, {1}})
    ->ArgsProduct({{150, 600}, {1, 2}, {1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace aerocal::triangulation

BENCHMARK_MAIN();
