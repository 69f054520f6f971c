// The statistics of a bundle at growing block sizes: redundancy numbers of every image
// observation (ProblemBuilder::ComputeObservationCofactors, sparse selected inverse) and the
// covariance `aerocal adjust` asks for (interior, every exposure's rotation and centre, interior x
// everything), against the dense inversion of the same reduced matrix (SetDenseInverseLimit,
// the cost model of the former dense path: O(n_reduced^3) plus a dense row per observation).
// Simulated flights as in triangulation_benchmark.cc (about 4 exposures per strip and strip
// length, 16 tie points per exposure), self-calibration all, no snooping. Counters:
//   solve_s              the adjustment itself (Ceres), for scale
//   cofactors_s          r_ii of all image observations (with the Q_vv clusters per point)
//   covariance_s         the covariance of adjust
//   dense_cofactors_s    the same r_ii through the dense inverse (only up to 4000 reduced
//                        parameters: beyond, hours and > 1 GiB per matrix)
//   max_abs_difference   largest |r_sparse - r_dense| over all components
//   reduced_parameters, factor_nonzeros, peak_rss_mb (this process, the simulation included)
// Run: build with -DAEROCAL_BUILD_BENCHMARKS=ON, then build/tests/bench/bench_normal_equations
// (--benchmark_filter=/150 etc. for one size).
#include "calib/problem/problem_builder.h"
#include "tests/bench/bench_blocks.h"
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace aerocal::triangulation {
namespace {

using bench::Clock;
using bench::PeakRssMb;
using bench::Seconds;

void BM_Statistics(benchmark::State& state) {
  const int exposures = static_cast<int>(state.range(0));
  const Project project = testing::ProjectFromFlight(bench::SimulateBlock(exposures));
  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("all");
  options.data_snooping = false;
  options.estimate_covariance = false;
  BlockAdjustment adjustment(project, options);
  auto start = Clock::now();
  const AdjustmentResult r = adjustment.Run();
  state.counters["solve_s"] = Seconds(start);
  calib::ProblemBuilder& builder = adjustment.builder();
  std::vector<calib::ResidualId> ids;
  for (calib::ResidualId id = 0; id < builder.NumActiveResiduals(); ++id)
    if (builder.IsActive(id) && builder.ResidualGroup(id) == calib::kGroupImage) ids.push_back(id);
  std::vector<calib::BlockId> blocks = {adjustment.InteriorBlock("cam1")};
  for (const auto& e : r.exposures) {
    blocks.push_back(adjustment.RotationBlock(e.image));
    blocks.push_back(adjustment.CenterBlock(e.image));
  }
  calib::ObservationCofactors cofactors;
  calib::CovarianceReport covariance;
  for (auto _ : state) {
    start = Clock::now();
    cofactors = builder.ComputeObservationCofactors(ids, true);
    state.counters["cofactors_s"] = Seconds(start);
    start = Clock::now();
    covariance = builder.EstimateCovariance(blocks, r.sigma0, 0.95, {blocks[0]});
    state.counters["covariance_s"] = Seconds(start);
  }
  state.counters["observations"] = static_cast<double>(ids.size());
  state.counters["reduced_parameters"] = cofactors.reduced_parameters;
  state.counters["factor_nonzeros"] = static_cast<double>(cofactors.factor_nonzeros);
  state.counters["covariance_ok"] = covariance.ok;
  state.SetLabel(cofactors.method + (cofactors.ok ? "" : " " + cofactors.message));
  if (cofactors.reduced_parameters <= 4000) {
    builder.SetDenseInverseLimit(1 << 30);
    start = Clock::now();
    const calib::ObservationCofactors dense = builder.ComputeObservationCofactors(ids, false);
    state.counters["dense_cofactors_s"] = Seconds(start);
    builder.SetDenseInverseLimit(300);
    double worst = 0.0;
    for (const auto& [id, values] : cofactors.redundancy)
      for (size_t k = 0; k < values.size(); ++k)
        worst = std::max(worst, std::abs(values[k] - dense.redundancy.at(id)[k]));
    state.counters["max_abs_difference"] = worst;
  }
  state.counters["peak_rss_mb"] = PeakRssMb();
}
BENCHMARK(BM_Statistics)
    ->Arg(150)
    ->Arg(600)
    ->Arg(2400)
    ->Arg(10000)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace
}  // namespace aerocal::triangulation

BENCHMARK_MAIN();
