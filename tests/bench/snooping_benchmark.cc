// Statistical acceptance of data snooping (issues 9 and 18), with the default options of
// `aerocal adjust` unless said otherwise. Not timed tests: figures to quote (triangulation/README).
//   BM_ConventionalSeeds      seeds 1-10, conventional: control rays rejected (must be 0), check
//                             RMSE / the --no-snooping run's, runs saying "model error suspected"
//   BM_FalseRejections        seeds 1-10, self-calibration all, clean data: runs with a rejection
//                             (the family-wise level is 5 %)
//   BM_SingleBlunder/<sigma>  RUNS runs (env AEROCAL_BENCH_RUNS, default 100) over seeds 1-10: one
//                             blunder of <sigma> sigmas in a random direction on a random
//                             observation with r >= 0.2 on both components; detected (it, or its
//                             correlated group, is rejected), the rate the test's power predicts
//                             (P(chi2(2, lambda) > T_crit), lambda = g^2 (r_x u_x^2 + r_y u_y^2),
//                             Q_ii's off-diagonal neglected), good observations named as THE
//                             gross error (group size 1, not the blunder)
//   BM_ManyBlunders/<percent> seeds 1-3: <percent> % of the observations corrupted by 20-50 sigma:
//                             found, good ones lost, check RMSE / the clean run's, camera offset
//                             from the clean run in sigmas (max over the 10 parameters)
//   BM_OdmUavBlock            the real UAV block (../shared/data/odm_br_uav_gcp_block), default
//                             options: the two known gross errors rejected, check RMSE, control
//                             rays lost
// Run: build with -DAEROCAL_BUILD_BENCHMARKS=ON, then build/tests/bench/bench_snooping.
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/nadir_start.h"
#include "triangulation/import/odm_gcp_import.h"
#include "triangulation/simulation/flight_simulator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <set>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

int Runs() {
  const char* env = std::getenv("AEROCAL_BENCH_RUNS");
  return env ? std::max(1, std::atoi(env)) : 100;
}

bool IsControl(const std::string& point) { return !point.empty() && point[0] == 'C'; }

AdjustOptions SelfCalibration() {
  AdjustOptions o;
  o.free_interior = ParseSelfCalibration("all");
  return o;
}

struct Seed {
  SimulatedFlight flight;
  Project project;
  AdjustmentResult clean;
};

const Seed& SeedData(int seed) {
  static std::map<int, std::unique_ptr<Seed>> cache;
  auto& s = cache[seed];
  if (!s) {
    s = std::make_unique<Seed>();
    FlightSimulationOptions options;
    options.seed = seed;
    s->flight = SimulateFlight(options);
    s->project = testing::ProjectFromFlight(s->flight);
    s->clean = Adjust(s->project, SelfCalibration());
  }
  return *s;
}

bool Rejected(const AdjustmentResult& r, const std::string& image, const std::string& point) {
  for (const auto& o : r.rejected)
    if (o.image == image && o.point == point) return true;
  return false;
}

void BM_ConventionalSeeds(benchmark::State& state) {
  for (auto _ : state) {
    int control_rejected = 0, model_error = 0;
    double worst_ratio = 1.0;
    for (int seed = 1; seed <= 10; ++seed) {
      const Seed& s = SeedData(seed);
      AdjustOptions none;
      none.data_snooping = false;
      const AdjustmentResult a = Adjust(s.project, AdjustOptions{});
      const AdjustmentResult b = Adjust(s.project, none);
      for (const auto& o : a.rejected) control_rejected += IsControl(o.point);
      model_error += a.snooping.model_error_suspected;
      const double ratio = a.check.spatial_rmse_m / b.check.spatial_rmse_m;
      if (std::abs(ratio - 1) > std::abs(worst_ratio - 1)) worst_ratio = ratio;
      std::printf("seed %2d conventional: check RMSE %.3f m (no snooping %.3f m), %zu rejected, "
                  "model error %s\n",
                  seed, a.check.spatial_rmse_m, b.check.spatial_rmse_m, a.rejected.size(),
                  a.snooping.model_error_suspected ? "suspected" : "no");
    }
    state.counters["control_rays_rejected"] = control_rejected;
    state.counters["worst_rmse_ratio"] = worst_ratio;
    state.counters["model_error_runs"] = model_error;
  }
}
BENCHMARK(BM_ConventionalSeeds)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_FalseRejections(benchmark::State& state) {
  for (auto _ : state) {
    int runs_with_rejection = 0, rejected = 0;
    for (int seed = 1; seed <= 10; ++seed) {
      const Seed& s = SeedData(seed);
      runs_with_rejection += !s.clean.rejected.empty();
      rejected += static_cast<int>(s.clean.rejected.size());
    }
    state.counters["runs"] = 10;
    state.counters["runs_with_rejection"] = runs_with_rejection;
    state.counters["rejected"] = rejected;
  }
}
BENCHMARK(BM_FalseRejections)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

// Tail probability of the noncentral chi-square(2, lambda) above t, by simulation.
double PredictedPower(double lambda, double t_crit, std::mt19937_64* rng) {
  std::normal_distribution<double> n01;
  int hits = 0;
  const int draws = 20000;
  for (int i = 0; i < draws; ++i) {
    const double a = n01(*rng) + std::sqrt(lambda), b = n01(*rng);
    hits += a * a + b * b > t_crit;
  }
  return static_cast<double>(hits) / draws;
}

void BM_SingleBlunder(benchmark::State& state) {
  const double g = static_cast<double>(state.range(0));
  for (auto _ : state) {
    std::mt19937_64 rng(42 + static_cast<int>(g));
    const int runs = Runs();
    int detected = 0, wrong_named = 0;
    double predicted = 0.0;
    for (int run = 0; run < runs; ++run) {
      const Seed& s = SeedData(1 + run % 10);
      std::vector<const ObservationResidual*> eligible;
      for (const auto& v : s.clean.residuals)
        if (v.used && v.test.tested && v.test.redundancy.minCoeff() >= 0.2) eligible.push_back(&v);
      const ObservationResidual& v =
          *eligible[std::uniform_int_distribution<size_t>(0, eligible.size() - 1)(rng)];
      const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
      const Eigen::Vector2d u(std::cos(angle), std::sin(angle));
      Project p = s.project;
      for (auto& o : p.observations)
        if (o.image == v.image && o.point == v.point) o.pixel += g * v.sigma_px * u;
      const AdjustmentResult r = Adjust(p, SelfCalibration());
      detected += Rejected(r, v.image, v.point);
      for (const auto& o : r.rejected)
        wrong_named += o.test.group_size == 1 && !(o.image == v.image && o.point == v.point) &&
                       o.point == v.point;
      // Photo x = col, photo y = -row: the direction's components in the photo frame.
      const double lambda = g * g * (v.test.redundancy.x() * u.x() * u.x() +
                                     v.test.redundancy.y() * u.y() * u.y());
      const double p_k = std::erfc(r.snooping.critical_value / std::sqrt(2.0));
      predicted += PredictedPower(lambda, -2 * std::log(p_k), &rng);
    }
    state.counters["runs"] = runs;
    state.counters["detection_rate"] = static_cast<double>(detected) / runs;
    state.counters["predicted_power"] = predicted / runs;
    state.counters["good_named_as_the_error"] = wrong_named;
  }
}
BENCHMARK(BM_SingleBlunder)->Arg(20)->Arg(8)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_ManyBlunders(benchmark::State& state) {
  const double share = state.range(0) / 100.0;
  for (auto _ : state) {
    int planted = 0, found = 0, good_lost = 0, good = 0;
    double worst_rmse_ratio = 1.0, worst_camera_sigmas = 0.0;
    for (int seed = 1; seed <= 3; ++seed) {
      const Seed& s = SeedData(seed);
      std::mt19937_64 rng(seed);
      Project p = s.project;
      std::set<std::pair<std::string, std::string>> blunders;
      for (auto& o : p.observations) {
        if (std::uniform_real_distribution<double>(0, 1)(rng) >= share) continue;
        const double g = std::uniform_real_distribution<double>(20, 50)(rng);
        const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
        o.pixel += g * o.sigma_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        blunders.insert({o.image, o.point});
      }
      const AdjustmentResult r = Adjust(p, SelfCalibration());
      planted += static_cast<int>(blunders.size());
      for (const auto& [image, point] : blunders) found += Rejected(r, image, point);
      for (const auto& o : p.observations)
        if (!blunders.count({o.image, o.point})) {
          ++good;
          good_lost += Rejected(r, o.image, o.point);
        }
      const double ratio = r.check.spatial_rmse_m / s.clean.check.spatial_rmse_m;
      worst_rmse_ratio = std::max(worst_rmse_ratio, ratio);
      for (int k = 0; k < Model::kNumParams; ++k)
        if (s.clean.cameras[0].sigma[k] > 0)
          worst_camera_sigmas = std::max(
              worst_camera_sigmas, std::abs(r.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) /
                                       s.clean.cameras[0].sigma[k]);
      std::printf("seed %d, %.0f %% blunders: %zu planted, robust start %s (%d excluded, %d "
                  "re-admitted), %zu rejected, valid %s, check RMSE %.3f m (clean %.3f m)\n",
                  seed, 100 * share, blunders.size(), r.snooping.robust_start ? "yes" : "no",
                  r.snooping.robust_excluded, r.snooping.robust_readmitted, r.rejected.size(),
                  r.valid ? "yes" : "no", r.check.spatial_rmse_m, s.clean.check.spatial_rmse_m);
    }
    state.counters["planted"] = planted;
    state.counters["found_share"] = static_cast<double>(found) / std::max(1, planted);
    state.counters["good_lost_share"] = static_cast<double>(good_lost) / std::max(1, good);
    state.counters["worst_rmse_ratio"] = worst_rmse_ratio;
    state.counters["worst_camera_offset_sigmas"] = worst_camera_sigmas;
  }
}
BENCHMARK(BM_ManyBlunders)->Arg(1)->Arg(5)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

void BM_OdmUavBlock(benchmark::State& state) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) {
    state.SkipWithError("../shared/data/odm_br_uav_gcp_block is absent");
    return;
  }
  for (auto _ : state) {
    OdmImportOptions in;
    in.gcp_list = dir + "/odm_gcp_br/gcp_list_floatxy_raw.txt";
    in.camera.name = "Canon PowerShot SX260 HS";
    in.camera.width_px = 4000;
    in.camera.height_px = 3000;
    in.camera.pixel_size_mm = 4.5 / 2904.0;
    in.camera.interior[Model::kC] = 4.5;
    OdmImportOptions subset = in;
    subset.gcp_list = dir + "/odm_gcp_br/gcp_list_raw.txt";
    for (const auto& p : ImportOdmGcpList(subset).points) in.control_ids.insert(p.id);
    Project project = ImportOdmGcpList(in);
    project.exposures = NadirStartFromControl(project, "cam1");
    const AdjustmentResult r = Adjust(project, AdjustOptions{});
    std::printf("%s", FormatSummary(r).c_str());
    int control_lost = 0;
    for (const auto& o : r.rejected) control_lost += in.control_ids.count(o.point) > 0;
    state.counters["known_blunders_rejected"] =
        Rejected(r, "IMG_5352", "HV11") + Rejected(r, "IMG_5358", "HV14");
    state.counters["check_rmse_m"] = r.check.spatial_rmse_m;
    state.counters["rejected"] = static_cast<double>(r.rejected.size());
    state.counters["control_rays_rejected"] = control_lost;
    state.counters["robust_start"] = r.snooping.robust_start;
    state.counters["valid"] = r.valid;
  }
}
BENCHMARK(BM_OdmUavBlock)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace aerocal::triangulation

BENCHMARK_MAIN();
