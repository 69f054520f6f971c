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
// BM_CollinearityJacobian: the cost of one observation's Jacobian, autodiff against hand-written.
#include "calib/camera/rotation.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/frame_collinearity_cost_function.h"
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

// One frame-camera observation's residual and Jacobian (interior[10], quaternion[4], centre[3],
// point[3]): range(0) 0 residual only (autodiff twin), 1 with Jacobians by autodiff
// (CollinearityResidual: 20-dimensional Jets), 2 with the hand-written Jacobian
// (FrameCollinearityCostFunction). ns per evaluation in the time column.
void BM_CollinearityJacobian(benchmark::State& state) {
  const calib::PixelFrame frame{0.009, 14000, 12000};
  double interior[10] = {170.038, -0.0024, 0.0015, 3e-8, -2e-12, 1e-16, 2e-7, -1.5e-7, 1e-5, -8e-6};
  Eigen::Vector4d q = calib::QuaternionFromOpk(Eigen::Vector3d(0.01, -0.008, 0.3));
  double center[3] = {100.0, -50.0, 4700.0}, point[3] = {600.0, 300.0, 250.0};
  const Eigen::Vector2d pixel(3100.25, 9050.75);
  const auto autodiff = calib::CollinearityResidual::Create(frame, pixel, 0.2);
  const calib::FrameCollinearityCostFunction analytic(frame, pixel, 0.2);
  const ceres::CostFunction* cost =
      state.range(0) == 2 ? static_cast<const ceres::CostFunction*>(&analytic) : autodiff.get();
  const double* blocks[] = {interior, q.data(), center, point};
  double r[2], j0[20], j1[8], j2[6], j3[6];
  double* jacobians[] = {j0, j1, j2, j3};
  for (auto _ : state) {
    point[0] += 1e-9;  // not hoisted out of the loop
    benchmark::DoNotOptimize(cost->Evaluate(blocks, r, state.range(0) == 0 ? nullptr : jacobians));
    benchmark::DoNotOptimize(r);
    benchmark::DoNotOptimize(j3);
  }
  state.SetLabel(state.range(0) == 0   ? "residual only"
                 : state.range(0) == 1 ? "autodiff Jacobian"
                                       : "hand-written Jacobian");
}
BENCHMARK(BM_CollinearityJacobian)->DenseRange(0, 2)->Unit(benchmark::kNanosecond);

}  // namespace
}  // namespace aerocal::triangulation

BENCHMARK_MAIN();
