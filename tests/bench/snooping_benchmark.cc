// Statistical acceptance of data snooping (issues 9 and 18), with the default options of
// `aerocal adjust` unless said otherwise. Not timed tests: figures to quote (triangulation/README).
//   BM_ConventionalSeeds      seeds 1-10, conventional: control rays rejected (must be 0), check
//                             RMSE / the --no-snooping run's, runs saying "model error suspected"
//   BM_FalseRejections        RUNS clean flights (seeds 1..RUNS), self-calibration all: runs with
//                             a rejection (the family-wise level is 5 %), Clopper-Pearson 95 %
//                             interval
//   BM_SingleBlunder/<sigma>  RUNS runs (env AEROCAL_BENCH_RUNS, default 100) over seeds 1-10: one
//                             blunder of <sigma> sigmas in a random direction on a random
//                             observation with r >= 0.2 on both components; detected (it, or its
//                             correlated group, is rejected), the rate the test's power predicts
//                             (P(chi2(2, lambda) > T_crit s^2), lambda = nabla^T R_ii nabla from
//                             the linear response, s Pope's factor; see the function), blunders
//                             in correlated groups and those reported as a group, good
//                             observations named as THE gross error (group size 1, not the
//                             blunder), rejections on other points, the detection rate's
//                             Clopper-Pearson 95 % interval
//   BM_ManyBlunders/<percent> seeds 1..AEROCAL_BENCH_MANY_SEEDS (default 3): <percent> % of the
//                             observations corrupted by 20-50 sigma: found, good ones lost (not
//                             used at the end) by cause, check RMSE / the clean run's over all
//                             check points and over the controlled ones (check_controlled),
//                             camera offset from the clean run in sigmas (max over the 10);
//                             beside them the oracles: the blunders removed by hand (no snooping),
//                             also with the good rays the run lost removed (the camera offset
//                             split into lost information, good rays lost, blunders kept), the
//                             oracle's offset in its expected spread sqrt(q_oracle^2 - q_clean^2)
//                             (z), the check RMSE over the check points none of whose rays held a
//                             blunder, and (/1/1 only) oracles with only the blunders on check
//                             (K), control (C) or tie (T) rays removed. AEROCAL_BENCH_DEBUG_SIGMA
//                             set: every camera parameter of the clean run, oracle and run
//   BM_OdmUavBlock            the real UAV block (../shared/data/odm_br_uav_gcp_block), default
//                             options: the two known gross errors rejected, check RMSE, control
//                             rays lost
// Run: build with -DAEROCAL_BUILD_BENCHMARKS=ON, then build/tests/bench/bench_snooping.
#include "tests/support/odm_uav_block.h"
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <random>
#include <set>
#include <tuple>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

int Runs() {
  const char* env = std::getenv("AEROCAL_BENCH_RUNS");
  return env ? std::max(1, std::atoi(env)) : 100;
}

// BM_ManyBlunders runs over seeds FIRST..AEROCAL_BENCH_MANY_SEEDS (default 3), FIRST from
// AEROCAL_BENCH_MANY_FIRST_SEED (default 1): 100 seeds in pieces that each fit the CPU lock.
int ManyBlundersSeeds() {
  const char* env = std::getenv("AEROCAL_BENCH_MANY_SEEDS");
  return env ? std::max(1, std::atoi(env)) : 3;
}
int ManyBlundersFirstSeed() {
  const char* env = std::getenv("AEROCAL_BENCH_MANY_FIRST_SEED");
  return env ? std::max(1, std::atoi(env)) : 1;
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

// Whether image/point took part in the final adjustment (not rejected, its point not left out).
bool Used(const AdjustmentResult& r, const std::string& image, const std::string& point) {
  for (const auto& o : r.residuals)
    if (o.image == image && o.point == point) return o.used;
  return false;
}

// Check RMSE (sqrt of the mean squared 3D difference, as PointStatistics::spatial_rmse_m) over the
// check points of r whose id is in `only`, or over all when `only` is null.
double CheckRmse(const AdjustmentResult& r, const std::set<std::string>* only) {
  double sum = 0.0;
  int n = 0;
  for (const auto& c : r.check_points)
    if (!only || only->count(c.point)) {
      sum += c.difference_m.squaredNorm();
      ++n;
    }
  return n > 0 ? std::sqrt(sum / n) : 0.0;
}

// The block of `project` without the observations in `drop`, adjusted without snooping (an
// oracle: the observations removed by hand).
AdjustmentResult AdjustWithout(const Project& project,
                               const std::set<std::pair<std::string, std::string>>& drop) {
  Project without = project;
  without.observations.clear();
  for (const auto& o : project.observations)
    if (!drop.count({o.image, o.point})) without.observations.push_back(o);
  AdjustOptions options = SelfCalibration();
  options.data_snooping = false;
  options.auto_robust_start = false;
  return Adjust(without, options);
}

// The sigma of oracle - clean for camera parameter k, in the clean run's sigmas: least squares
// on nested observation sets, so the difference has the cofactor Q_oracle - Q_clean; the
// cofactors are the sigmas over each run's sigma0 (the covariance is scaled by sigma0^2).
double OracleSpread(const AdjustmentResult& clean, const AdjustmentResult& oracle, int k) {
  const double qc = clean.cameras[0].sigma[k] / clean.sigma0;
  const double qo = oracle.cameras[0].sigma[k] / oracle.sigma0;
  return std::sqrt(std::max(1e-6, qo * qo / (qc * qc) - 1.0));
}

// Clopper-Pearson 95 % interval of a binomial proportion k / n (by bisection on the binomial
// tails, exact enough for n <= a few hundred).
double BinomialTail(int k, int n, double p, bool upper) {  // P(X >= k) or P(X <= k)
  double sum = 0.0;
  for (int i = upper ? k : 0; i <= (upper ? n : k); ++i)
    sum += std::exp(std::lgamma(n + 1.0) - std::lgamma(i + 1.0) - std::lgamma(n - i + 1.0) +
                    (i > 0 ? i * std::log(p) : 0.0) + (n - i > 0 ? (n - i) * std::log1p(-p) : 0.0));
  return sum;
}
std::pair<double, double> ClopperPearson95(int k, int n) {
  const auto solve = [&](bool lower) {
    double a = 0.0, b = 1.0;
    for (int i = 0; i < 60; ++i) {
      const double m = 0.5 * (a + b);
      // lower bound: P(X >= k | p) = 0.025; upper: P(X <= k | p) = 0.025
      const double tail = lower ? BinomialTail(k, n, m, true) : BinomialTail(k, n, m, false);
      if (lower == (tail < 0.025))
        a = m;
      else
        b = m;
    }
    return 0.5 * (a + b);
  };
  return {k == 0 ? 0.0 : solve(true), k == n ? 1.0 : solve(false)};
}

std::string RejectedBy(const AdjustmentResult& r,
                       const std::string& image,
                       const std::string& point) {
  for (const auto& o : r.rejected)
    if (o.image == image && o.point == point) return o.by;
  return "";
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
      std::printf(
          "seed %2d conventional: check RMSE %.3f m (no snooping %.3f m), %zu rejected, "
          "model error %s\n",
          seed,
          a.check.spatial_rmse_m,
          b.check.spatial_rmse_m,
          a.rejected.size(),
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
    const int runs = Runs();
    int runs_with_rejection = 0, rejected = 0;
    for (int seed = 1; seed <= runs; ++seed) {
      FlightSimulationOptions options;
      options.seed = seed;
      const AdjustmentResult r =
          Adjust(testing::ProjectFromFlight(SimulateFlight(options)), SelfCalibration());
      runs_with_rejection += !r.rejected.empty();
      rejected += static_cast<int>(r.rejected.size());
      if (!r.rejected.empty())
        std::printf("clean seed %d: %zu rejected (first w %.2f, group %d)\n",
                    seed,
                    r.rejected.size(),
                    r.rejected[0].w,
                    r.rejected[0].test.group_size);
    }
    state.counters["runs"] = runs;
    state.counters["runs_with_rejection"] = runs_with_rejection;
    state.counters["false_rejection_rate"] = static_cast<double>(runs_with_rejection) / runs;
    state.counters["rejected"] = rejected;
    const auto ci = ClopperPearson95(runs_with_rejection, runs);
    state.counters["false_rejection_ci95_high"] = ci.second;
    std::printf(
        "clean flights: %d of %d runs with a rejection (%.3f, 95 %% interval %.3f-%.3f) "
        "against the family-wise alpha 0.05; %d observations rejected\n",
        runs_with_rejection,
        runs,
        static_cast<double>(runs_with_rejection) / runs,
        ci.first,
        ci.second,
        rejected);
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

AdjustOptions WithoutSnooping() {
  AdjustOptions o = SelfCalibration();
  o.data_snooping = false;
  o.estimate_covariance = false;
  o.auto_robust_start = false;
  return o;
}

// Whitened residual (col, row) of image/point in r; zero when absent.
Eigen::Vector2d Whitened(const AdjustmentResult& r,
                         const std::string& image,
                         const std::string& point) {
  for (const auto& o : r.residuals)
    if (o.image == image && o.point == point && o.used) return o.residual_px / o.sigma_px;
  return Eigen::Vector2d::Zero();
}

// The prediction: the joint test of the blundered observation is chi-square(2) with the
// non-centrality lambda = nabla^T R_ii nabla (R = Q_vv P, whitened; nabla = g u). R_ii's
// off-diagonal matters (lambda = g^2 (r_x u_x^2 + r_y u_y^2) was 5 % optimistic), so lambda is
// taken from the linear response itself: R_ii nabla = v(with blunder) - v(without), both without
// snooping, on the same noise. The critical value applies to w = |v| / (s sqrt r) with Pope's
// s = max(sigma0, 1) of the first solve (the blunder inflates it): T_crit s^2 on the T scale.
void BM_SingleBlunder(benchmark::State& state) {
  const double g = static_cast<double>(state.range(0));
  for (auto _ : state) {
    std::mt19937_64 rng(42 + static_cast<int>(g));
    const int runs = Runs();
    int detected = 0, wrong_named = 0, other_rejections = 0, in_group = 0, group_reported = 0;
    double predicted = 0.0, predicted_diagonal = 0.0;
    std::map<int, AdjustmentResult> unsnooped;  // per seed: the clean run without snooping
    for (int run = 0; run < runs; ++run) {
      const int seed = 1 + run % 10;
      const Seed& s = SeedData(seed);
      if (!unsnooped.count(seed)) unsnooped[seed] = Adjust(s.project, WithoutSnooping());
      std::vector<const ObservationResidual*> eligible;
      for (const auto& v : s.clean.residuals)
        if (v.used && v.test.tested && v.test.redundancy.minCoeff() >= 0.2) eligible.push_back(&v);
      const ObservationResidual& v =
          *eligible[std::uniform_int_distribution<size_t>(0, eligible.size() - 1)(rng)];
      const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
      const Eigen::Vector2d u(std::cos(angle), std::sin(angle));  // (col, row)
      Project p = s.project;
      for (auto& o : p.observations)
        if (o.image == v.image && o.point == v.point) o.pixel += g * v.sigma_px * u;
      const AdjustmentResult r = Adjust(p, SelfCalibration());
      const AdjustmentResult plain = Adjust(p, WithoutSnooping());
      const bool found = Rejected(r, v.image, v.point);
      detected += found;
      const bool grouped = v.test.group_size > 1;
      in_group += grouped;
      for (const auto& o : r.rejected) {
        const bool blunder = o.image == v.image && o.point == v.point;
        group_reported += grouped && blunder && o.test.group_size > 1;
        wrong_named += !blunder && o.test.group_size == 1 && o.point == v.point;
        other_rejections += !blunder && o.point != v.point;
      }
      const Eigen::Vector2d response =
          Whitened(plain, v.image, v.point) - Whitened(unsnooped[seed], v.image, v.point);
      const double lambda = g * u.dot(response);
      const double t_crit = -2 * std::log(std::erfc(r.snooping.critical_value / std::sqrt(2.0)));
      const double s0 = std::max(1.0, plain.sigma0);
      const double power = PredictedPower(lambda, t_crit * s0 * s0, &rng);
      predicted += power;
      // The former prediction (diagonal of R_ii, s = 1), for the record.
      const double lambda_diagonal =
          g * g * (v.test.redundancy.x() * u.x() * u.x() + v.test.redundancy.y() * u.y() * u.y());
      predicted_diagonal += PredictedPower(lambda_diagonal, t_crit, &rng);
      if (!found)
        std::printf(
            "missed: seed %d %s/%s r (%.2f, %.2f) group %d lambda %.1f (diagonal %.1f) "
            "s %.3f predicted power %.2f, %zu rejected\n",
            seed,
            v.image.c_str(),
            v.point.c_str(),
            v.test.redundancy.x(),
            v.test.redundancy.y(),
            v.test.group_size,
            lambda,
            lambda_diagonal,
            s0,
            power,
            r.rejected.size());
    }
    state.counters["runs"] = runs;
    state.counters["detection_rate"] = static_cast<double>(detected) / runs;
    const auto ci = ClopperPearson95(detected, runs);
    state.counters["detection_ci95_low"] = ci.first;
    state.counters["detection_ci95_high"] = ci.second;
    std::printf(
        "%.0f sigma: found %d of %d (%.3f, 95 %% interval %.3f-%.3f), predicted power "
        "%.3f (%s the interval)\n",
        g,
        detected,
        runs,
        static_cast<double>(detected) / runs,
        ci.first,
        ci.second,
        predicted / runs,
        predicted / runs >= ci.first && predicted / runs <= ci.second ? "inside" : "OUTSIDE");
    state.counters["predicted_power"] = predicted / runs;
    state.counters["predicted_power_diagonal"] = predicted_diagonal / runs;
    state.counters["blunders_in_groups"] = in_group;
    state.counters["groups_reported"] = group_reported;
    state.counters["good_named_as_the_error"] = wrong_named;
    state.counters["rejections_elsewhere"] = other_rejections;
  }
}
BENCHMARK(BM_SingleBlunder)
    ->Arg(20)
    ->Arg(8)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

void BM_ManyBlunders(benchmark::State& state) {
  const double share = state.range(0) / 100.0;
  const bool controlled_only = state.range(1) != 0;
  for (auto _ : state) {
    int planted = 0, found = 0, good_lost = 0, good = 0;
    int good_lost_undetermined = 0, good_lost_in_group = 0, good_lost_other = 0;
    int by_class[4] = {0, 0, 0, 0}, found_by_class[4] = {0, 0, 0, 0};
    double worst_rmse_ratio = 1.0, worst_rmse_ratio_controlled = 1.0, worst_camera_sigmas = 0.0;
    int invalid_runs = 0;
    double worst_oracle_ratio = 1.0, worst_ratio_to_oracle = 1.0, worst_oracle_camera_sigmas = 0.0;
    std::map<std::string, int> invalid_by_reason;  // by the reason's words before its numbers
    double worst_oracle_lost_camera_sigmas = 0.0, worst_kept_camera_sigmas = 0.0;
    double worst_oracle_z = 0.0, worst_run_vs_oracle = 0.0;
    double worst_ratio_untouched = 0.0, worst_oracle_untouched = 0.0, sum_ratio = 0.0;
    double sum_oracle_ratio = 0.0, sum_kind_ratio[3] = {0, 0, 0}, worst_kind_ratio[3] = {1, 1, 1};
    int runs_within_2_clean = 0, runs_within_2_oracle = 0, runs_within_2_untouched = 0;
    int seeds_run = 0, planted_by_kind[3] = {0, 0, 0};
    for (int seed = ManyBlundersFirstSeed(); seed <= ManyBlundersSeeds(); ++seed) {
      const Seed& s = SeedData(seed);
      std::mt19937_64 rng(seed);
      Project p = s.project;
      std::set<std::pair<std::string, std::string>> blunders;
      std::map<std::pair<std::string, std::string>, const ObservationResidual*> clean_test;
      for (const auto& v : s.clean.residuals) clean_test[{v.image, v.point}] = &v;
      for (auto& o : p.observations) {
        if (std::uniform_real_distribution<double>(0, 1)(rng) >= share) continue;
        if (controlled_only) {  // issue 9: on observations with r >= 0.2 (both components)
          const auto it = clean_test.find({o.image, o.point});
          if (it == clean_test.end() || !it->second->test.tested ||
              it->second->test.redundancy.minCoeff() < 0.2)
            continue;
        }
        const double g = std::uniform_real_distribution<double>(20, 50)(rng);
        const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
        o.pixel += g * o.sigma_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
        blunders.insert({o.image, o.point});
      }
      const AdjustmentResult r = Adjust(p, SelfCalibration());
      planted += static_cast<int>(blunders.size());
      for (const auto& [image, point] : blunders) found += Rejected(r, image, point);
      // Each blunder classed by the clean run's test of its observation: weakly controlled (a
      // component with r < min_redundancy), in a correlated group, or controlled.
      for (const auto& key : blunders) {
        const ObservationResidual* v = clean_test.count(key) ? clean_test.at(key) : nullptr;
        const int k = !v || !v->test.tested                                             ? 3
                      : v->test.redundancy.minCoeff() < s.clean.snooping.min_redundancy ? 0
                      : v->test.group_size > 1                                          ? 1
                                                                                        : 2;
        ++by_class[k];
        const bool hit = Rejected(r, key.first, key.second);
        found_by_class[k] += hit;
        if (!hit && k > 0)
          for (const auto& f : r.residuals)
            if (f.image == key.first && f.point == key.second)
              std::printf(
                  "  kept %s/%s (%s, r (%.2f, %.2f) group %d): final w (%.2f, %.2f) "
                  "r (%.2f, %.2f) %s %s\n",
                  key.first.c_str(),
                  key.second.c_str(),
                  k == 1 ? "grouped" : "controlled",
                  v->test.redundancy.x(),
                  v->test.redundancy.y(),
                  v->test.group_size,
                  f.test.w.x(),
                  f.test.w.y(),
                  f.test.redundancy.x(),
                  f.test.redundancy.y(),
                  f.test.verdict.c_str(),
                  f.test.reason.c_str());
      }
      // The check points the blunders moved: which of their rays held a blunder and why it stayed.
      for (const auto& c : r.check_points)
        for (const auto& c0 : s.clean.check_points)
          if (c.point == c0.point && (c.difference_m - c0.difference_m).norm() > 0.3) {
            std::printf("  check %s moved %.2f m (%d rays):",
                        c.point.c_str(),
                        (c.difference_m - c0.difference_m).norm(),
                        c.rays);
            for (const auto& [image, point] : blunders)
              if (point == c.point) {
                const auto* v =
                    clean_test.count({image, point}) ? clean_test.at({image, point}) : nullptr;
                std::printf(" blunder %s r (%.2f, %.2f) group %d %s;",
                            image.c_str(),
                            v ? v->test.redundancy.x() : -1,
                            v ? v->test.redundancy.y() : -1,
                            v ? v->test.group_size : 0,
                            Rejected(r, image, point) ? "rejected" : "kept");
              }
            std::printf("\n");
          }
      // Good observations lost, by cause: on a point left with fewer than two good rays (no
      // method can keep them: without the blunder the point is undetermined), in the blunder's
      // correlated group of the clean run (no test can tell them from it), and the others.
      std::map<std::string, int> good_rays;
      std::map<std::pair<std::string, std::string>, int> group_of;
      for (const auto& o : p.observations)
        good_rays[o.point] += !blunders.count({o.image, o.point});
      for (const auto& o : p.observations)
        if (!blunders.count({o.image, o.point})) {
          ++good;
          if (Used(r, o.image, o.point)) continue;
          ++good_lost;
          const ObservationResidual* v =
              clean_test.count({o.image, o.point}) ? clean_test.at({o.image, o.point}) : nullptr;
          // In the blunder's correlated group: in the clean run, or rejected with it as a group
          // the test could not separate (the group of the rejection holds a blundered image).
          bool beside_grouped_blunder = false;
          for (const auto& [image, point] : blunders)
            if (point == o.point && clean_test.count({image, point}) &&
                clean_test.at({image, point})->test.group_size > 1 && v && v->test.group_size > 1)
              beside_grouped_blunder = true;
          for (const auto& x : r.rejected)
            if (x.image == o.image && x.point == o.point && x.group.size() > 1)
              for (const auto& member : x.group)
                beside_grouped_blunder |= blunders.count({member, o.point}) > 0;
          if (good_rays[o.point] < 2) {
            ++good_lost_undetermined;
          } else if (beside_grouped_blunder) {
            ++good_lost_in_group;
          } else {
            ++good_lost_other;
            std::printf("  good lost %s/%s (%d good rays of %s, by %s)\n",
                        o.image.c_str(),
                        o.point.c_str(),
                        good_rays[o.point],
                        o.point.c_str(),
                        Rejected(r, o.image, o.point) ? RejectedBy(r, o.image, o.point).c_str()
                                                      : "left out");
          }
        }
      const double ratio = r.check.spatial_rmse_m / s.clean.check.spatial_rmse_m;
      worst_rmse_ratio = std::max(worst_rmse_ratio, ratio);
      // The oracle: the blundered observations removed by hand, no snooping (what no method can
      // beat: their information is gone). Its check RMSE over the clean run's says how much of
      // the ratio above is the lost information, not a fault of the detection.
      const AdjustmentResult oracle = AdjustWithout(p, blunders);
      worst_oracle_ratio =
          std::max(worst_oracle_ratio, oracle.check.spatial_rmse_m / s.clean.check.spatial_rmse_m);
      worst_ratio_to_oracle =
          std::max(worst_ratio_to_oracle,
                   ratio * s.clean.check.spatial_rmse_m / oracle.check.spatial_rmse_m);
      std::printf("seed %d: check RMSE of the oracle (blunders removed by hand) %.3f m\n",
                  seed,
                  oracle.check.spatial_rmse_m);
      // The check points whose rays are all controlled, in this run and in the clean one.
      const double ratio_controlled =
          r.check_controlled && s.clean.check_controlled
              ? r.check_controlled->spatial_rmse_m / s.clean.check_controlled->spatial_rmse_m
              : 0.0;
      worst_rmse_ratio_controlled = std::max(worst_rmse_ratio_controlled, ratio_controlled);
      double camera_sigmas = 0.0, oracle_camera_sigmas = 0.0;
      int camera_worst = 0;
      for (int k = 0; k < Model::kNumParams; ++k)
        if (s.clean.cameras[0].sigma[k] > 0) {
          const double d = std::abs(r.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) /
                           s.clean.cameras[0].sigma[k];
          if (d > camera_sigmas) std::tie(camera_sigmas, camera_worst) = std::make_tuple(d, k);
          oracle_camera_sigmas =
              std::max(oracle_camera_sigmas,
                       std::abs(oracle.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) /
                           s.clean.cameras[0].sigma[k]);
        }
      worst_camera_sigmas = std::max(worst_camera_sigmas, camera_sigmas);
      // Why the camera moved: the oracle with the good rays this run lost removed too. The run
      // against it is the effect of the blunders the run kept (its final set is that one plus
      // them); it against the oracle the effect of the good rays lost; the oracle against the
      // clean run the information of the blundered observations, which no method gets back.
      std::set<std::pair<std::string, std::string>> used_final, drop_lost = blunders;
      for (const auto& o : r.residuals)
        if (o.used) used_final.insert({o.image, o.point});
      int kept = 0;
      for (const auto& o : p.observations) {
        const std::pair<std::string, std::string> key{o.image, o.point};
        if (!blunders.count(key) && !used_final.count(key)) drop_lost.insert(key);
        kept += blunders.count(key) && used_final.count(key);
      }
      const AdjustmentResult oracle_lost = AdjustWithout(p, drop_lost);
      double lost_sigmas = 0.0, kept_sigmas = 0.0;
      for (int k = 0; k < Model::kNumParams; ++k)
        if (s.clean.cameras[0].sigma[k] > 0) {
          const double sigma = s.clean.cameras[0].sigma[k];
          lost_sigmas = std::max(
              lost_sigmas,
              std::abs(oracle_lost.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) /
                  sigma);
          kept_sigmas = std::max(
              kept_sigmas,
              std::abs(r.cameras[0].estimated[k] - oracle_lost.cameras[0].estimated[k]) / sigma);
        }
      // The oracle's own spread: nested least squares, so oracle - clean has the covariance
      // Q_oracle - Q_clean; per parameter its sigma is sqrt(sigma_oracle^2 - sigma_clean^2).
      // z = (oracle - clean) / that: what the lost information alone predicts (|z| <= 3 but for
      // chance). And this run against the oracle: the method's own share.
      double oracle_z = 0.0, run_vs_oracle = 0.0, worst_spread = 0.0;
      for (int k = 0; k < Model::kNumParams; ++k)
        if (s.clean.cameras[0].sigma[k] > 0) {
          const double sc = s.clean.cameras[0].sigma[k], so = oracle.cameras[0].sigma[k];
          const double spread = sc * OracleSpread(s.clean, oracle, k);
          oracle_z = std::max(
              oracle_z,
              std::abs(oracle.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) / spread);
          worst_spread = std::max(worst_spread, spread / sc);
          if (std::getenv("AEROCAL_BENCH_DEBUG_SIGMA"))
            std::printf("  %s: clean %.6g +- %.4g, oracle %.6g +- %.4g, run %.6g +- %.4g\n",
                        std::string(Model::kParams[k].name).c_str(),
                        s.clean.cameras[0].estimated[k],
                        sc,
                        oracle.cameras[0].estimated[k],
                        so,
                        r.cameras[0].estimated[k],
                        r.cameras[0].sigma[k]);
          run_vs_oracle =
              std::max(run_vs_oracle,
                       std::abs(r.cameras[0].estimated[k] - oracle.cameras[0].estimated[k]) / sc);
        }
      worst_oracle_z = std::max(worst_oracle_z, oracle_z);
      worst_run_vs_oracle = std::max(worst_run_vs_oracle, run_vs_oracle);
      {
        const int k = camera_worst;
        const double sc = s.clean.cameras[0].sigma[k], so = oracle.cameras[0].sigma[k];
        const double spread = OracleSpread(s.clean, oracle, k);
        std::printf(
            "seed %d: camera %s: sigma clean %.4g, oracle %.4g, this run %.4g; the oracle's "
            "expected spread about the clean camera sqrt(so^2 - sc^2) = %.2f clean sigmas, "
            "its offset %.2f of them; over all parameters: oracle |z| max %.2f, spread max "
            "%.2f clean sigmas, this run against the oracle max %.2f clean sigmas\n",
            seed,
            std::string(Model::kParams[k].name).c_str(),
            sc,
            so,
            r.cameras[0].sigma[k],
            spread,
            (oracle.cameras[0].estimated[k] - s.clean.cameras[0].estimated[k]) / (sc * spread),
            oracle_z,
            worst_spread,
            run_vs_oracle);
      }
      worst_oracle_lost_camera_sigmas = std::max(worst_oracle_lost_camera_sigmas, lost_sigmas);
      worst_kept_camera_sigmas = std::max(worst_kept_camera_sigmas, kept_sigmas);
      {
        const int k = camera_worst;
        const double sigma = s.clean.cameras[0].sigma[k], clean_k = s.clean.cameras[0].estimated[k];
        std::printf(
            "seed %d: camera %s from the clean run, signed, in sigmas: this run %+.2f, the "
            "oracle %+.2f, the oracle without the %zu good rays lost too %+.2f; this run "
            "against the latter (the %d blunders kept) %+.2f; over all parameters: "
            "oracle+lost %.2f, kept blunders %.2f\n",
            seed,
            std::string(Model::kParams[k].name).c_str(),
            (r.cameras[0].estimated[k] - clean_k) / sigma,
            (oracle.cameras[0].estimated[k] - clean_k) / sigma,
            drop_lost.size() - blunders.size(),
            (oracle_lost.cameras[0].estimated[k] - clean_k) / sigma,
            kept,
            (r.cameras[0].estimated[k] - oracle_lost.cameras[0].estimated[k]) / sigma,
            lost_sigmas,
            kept_sigmas);
      }
      // Issue 9's check RMSE within 2 % of the clean run: by where the blunders fell. The check
      // points none of whose rays held a blunder keep their intersection whole; a check point
      // that lost a ray is intersected from fewer rays in every method (the oracle too).
      std::set<std::string> touched, untouched;
      for (const auto& key : blunders)
        if (!key.second.empty() && key.second[0] == 'K') touched.insert(key.second);
      for (const auto& c : s.clean.check_points)
        if (!touched.count(c.point)) untouched.insert(c.point);
      const double clean_untouched = CheckRmse(s.clean, &untouched);
      const double ratio_untouched = CheckRmse(r, &untouched) / clean_untouched;
      const double oracle_untouched = CheckRmse(oracle, &untouched) / clean_untouched;
      worst_ratio_untouched = std::max(worst_ratio_untouched, ratio_untouched);
      worst_oracle_untouched = std::max(worst_oracle_untouched, oracle_untouched);
      const double to_oracle = r.check.spatial_rmse_m / oracle.check.spatial_rmse_m;
      runs_within_2_clean += ratio <= 1.02;
      runs_within_2_oracle += to_oracle <= 1.02;
      runs_within_2_untouched += ratio_untouched <= 1.02;
      sum_ratio += ratio;
      sum_oracle_ratio += oracle.check.spatial_rmse_m / s.clean.check.spatial_rmse_m;
      ++seeds_run;
      std::printf(
          "seed %d: check RMSE / clean run %.3f (the acceptance's figure), / the oracle %.3f, "
          "oracle / clean %.3f; over the %zu check points whose rays held no blunder (%zu "
          "touched): this run / clean %.3f, oracle / clean %.3f\n",
          seed,
          ratio,
          to_oracle,
          oracle.check.spatial_rmse_m / s.clean.check.spatial_rmse_m,
          untouched.size(),
          touched.size(),
          ratio_untouched,
          oracle_untouched);
      if (controlled_only) {  // partial oracles: only the blunders of one kind removed
        const char kinds[3] = {'K', 'C', 'T'};
        std::printf("seed %d: oracle / clean with only the blunders on", seed);
        for (int k = 0; k < 3; ++k) {
          std::set<std::pair<std::string, std::string>> of_kind;
          for (const auto& key : blunders)
            if (!key.second.empty() && key.second[0] == kinds[k]) of_kind.insert(key);
          planted_by_kind[k] += static_cast<int>(of_kind.size());
          const double kind_ratio = of_kind.empty()
                                        ? 1.0
                                        : AdjustWithout(s.project, of_kind).check.spatial_rmse_m /
                                              s.clean.check.spatial_rmse_m;
          sum_kind_ratio[k] += kind_ratio;
          worst_kind_ratio[k] = std::max(worst_kind_ratio[k], kind_ratio);
          std::printf(" %c rays (%zu) removed %.3f;", kinds[k], of_kind.size(), kind_ratio);
        }
        std::printf("\n");
      }
      worst_oracle_camera_sigmas = std::max(worst_oracle_camera_sigmas, oracle_camera_sigmas);
      std::printf("seed %d: camera %.2f sigma from the clean run (%s); the oracle's %.2f\n",
                  seed,
                  camera_sigmas,
                  std::string(Model::kParams[camera_worst].name).c_str(),
                  oracle_camera_sigmas);
      std::printf(
          "seed %d, %.0f %% blunders: %zu planted, robust start %s (%d excluded, %d "
          "re-admitted, %d re-tested), %zu rejected, valid %s, check RMSE %.3f m (clean %.3f m), "
          "controlled check points %d: %.3f m (clean %d: %.3f m)\n",
          seed,
          100 * share,
          blunders.size(),
          r.snooping.robust_start ? "yes" : "no",
          r.snooping.robust_excluded,
          r.snooping.robust_readmitted,
          r.snooping.robust_retested,
          r.rejected.size(),
          r.valid ? "yes" : "no",
          r.check.spatial_rmse_m,
          s.clean.check.spatial_rmse_m,
          r.check_controlled ? r.check_controlled->n : 0,
          r.check_controlled ? r.check_controlled->spatial_rmse_m : 0.0,
          s.clean.check_controlled ? s.clean.check_controlled->n : 0,
          s.clean.check_controlled ? s.clean.check_controlled->spatial_rmse_m : 0.0);
      for (const auto& why : r.invalid_reasons) {  // issue 9 (c): why a run ends invalid
        std::printf("  seed %d invalid: %s\n", seed, why.c_str());
        ++invalid_by_reason[why.substr(0, why.find_first_of("(0123456789:"))];
      }
      invalid_runs += !r.valid;
    }
    state.counters["invalid_runs"] = invalid_runs;
    state.counters["worst_oracle_lost_camera_offset_sigmas"] = worst_oracle_lost_camera_sigmas;
    state.counters["worst_kept_blunders_camera_sigmas"] = worst_kept_camera_sigmas;
    state.counters["worst_oracle_camera_z"] = worst_oracle_z;
    state.counters["worst_camera_against_oracle_sigmas"] = worst_run_vs_oracle;
    state.counters["worst_rmse_ratio_untouched"] = worst_ratio_untouched;
    state.counters["worst_oracle_rmse_ratio_untouched"] = worst_oracle_untouched;
    state.counters["runs_within_2pct_of_clean"] = runs_within_2_clean;
    state.counters["runs_within_2pct_of_oracle"] = runs_within_2_oracle;
    state.counters["runs_within_2pct_of_clean_untouched"] = runs_within_2_untouched;
    std::printf(
        "over %d seeds: check RMSE / clean run mean %.3f, worst %.3f, within 2 %% in %d; "
        "/ the oracle worst %.3f, within 2 %% in %d; oracle / clean mean %.3f, worst %.3f; "
        "over the check points whose rays held no blunder: this run / clean worst %.3f, "
        "within 2 %% in %d, oracle / clean worst %.3f\n",
        seeds_run,
        sum_ratio / std::max(1, seeds_run),
        worst_rmse_ratio,
        runs_within_2_clean,
        worst_ratio_to_oracle,
        runs_within_2_oracle,
        sum_oracle_ratio / std::max(1, seeds_run),
        worst_oracle_ratio,
        worst_ratio_untouched,
        runs_within_2_untouched,
        worst_oracle_untouched);
    if (controlled_only)
      for (int k = 0; k < 3; ++k) {
        const char kinds[3] = {'K', 'C', 'T'};
        std::printf(
            "blunders on %c rays: %d planted; oracle / clean with only them removed: mean "
            "%.3f, worst %.3f\n",
            kinds[k],
            planted_by_kind[k],
            sum_kind_ratio[k] / std::max(1, seeds_run),
            worst_kind_ratio[k]);
        state.counters[std::string("oracle_ratio_only_") + kinds[k]] = worst_kind_ratio[k];
      }
    std::printf(
        "camera: this run worst %.2f sigma from the clean run; the oracle %.2f; the oracle "
        "without the good rays lost too %.2f; this run against the latter (kept blunders) "
        "%.2f; this run against the oracle %.2f; the oracle's offset in its expected spread (z) "
        "%.2f\n",
        worst_camera_sigmas,
        worst_oracle_camera_sigmas,
        worst_oracle_lost_camera_sigmas,
        worst_kept_camera_sigmas,
        worst_run_vs_oracle,
        worst_oracle_z);
    state.counters["worst_oracle_rmse_ratio"] = worst_oracle_ratio;        // oracle / clean
    state.counters["worst_rmse_ratio_to_oracle"] = worst_ratio_to_oracle;  // this run / oracle
    state.counters["worst_oracle_camera_offset_sigmas"] = worst_oracle_camera_sigmas;
    for (const auto& [why, n] : invalid_by_reason)
      std::printf("invalid %d run(s): %s\n", n, why.c_str());
    state.counters["planted"] = planted;
    state.counters["found_share"] = static_cast<double>(found) / std::max(1, planted);
    state.counters["good_lost_share"] = static_cast<double>(good_lost) / std::max(1, good);
    state.counters["good_lost_share_undetermined"] =
        static_cast<double>(good_lost_undetermined) / std::max(1, good);
    state.counters["good_lost_share_in_group"] =
        static_cast<double>(good_lost_in_group) / std::max(1, good);
    state.counters["good_lost_share_other"] =
        static_cast<double>(good_lost_other) / std::max(1, good);
    // Issue 18's "good observations lost", both ways: every good observation not used at the end,
    // and the avoidable ones. Not avoidable: the single good ray of a point whose other rays are
    // all blunders (one ray of an unknown point has no redundancy: it determines nothing else,
    // with or without it the other parameters are the same), and the good members of a group
    // with a blunder whose standardised residuals no test can separate (keeping them keeps the
    // blunder). A point with 2 good rays and 1 blunder is NOT in the first class.
    state.counters["good_lost_share_avoidable"] = state.counters["good_lost_share_other"];
    std::printf(
        "good observations lost: all %.2f %% (%d of %d), avoidable %.2f %% (%d); on points "
        "left with < 2 good rays %.2f %%, in an inseparable group with a blunder %.2f %%\n",
        100.0 * good_lost / std::max(1, good),
        good_lost,
        good,
        100.0 * good_lost_other / std::max(1, good),
        good_lost_other,
        100.0 * good_lost_undetermined / std::max(1, good),
        100.0 * good_lost_in_group / std::max(1, good));
    state.counters["worst_rmse_ratio"] = worst_rmse_ratio;
    state.counters["worst_rmse_ratio_controlled"] = worst_rmse_ratio_controlled;
    state.counters["worst_camera_offset_sigmas"] = worst_camera_sigmas;
    const char* names[4] = {"weak", "grouped", "controlled", "untested"};
    for (int k = 0; k < 4; ++k) {
      state.counters[std::string("planted_") + names[k]] = by_class[k];
      state.counters[std::string("found_") + names[k]] = found_by_class[k];
    }
  }
}
BENCHMARK(BM_ManyBlunders)
    ->Args({1, 1})
    ->Args({1, 0})
    ->Args({5, 0})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

void BM_OdmUavBlock(benchmark::State& state) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) {
    state.SkipWithError("../shared/data/odm_br_uav_gcp_block is absent");
    return;
  }
  for (auto _ : state) {
    std::set<std::string> control_ids;
    const Project project = testing::ImportOdmUavBlock(dir, &control_ids);
    const AdjustmentResult r = Adjust(project, AdjustOptions{});
    std::printf("%s", FormatSummary(r).c_str());
    int control_lost = 0;
    for (const auto& o : r.rejected) control_lost += control_ids.count(o.point) > 0;
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
