// Data snooping in the block adjustment (data_snooping.h through BlockAdjustment) on the
// simulated flight of seed 3: a conventional run keeps every control ray and says "model error
// suspected"; a planted 20-sigma blunder on a pinned-down observation is found; a blunder in a
// two-ray pair is reported and acted on as a group; a 20-sigma blunder on a control ray, which
// looks like a model error in the first test, is rejected and the check RMSE is the oracle's (the
// ray removed by hand); every observation carries r, w, MDB and its
// group size; with 5 % of the observations at 50 sigma the default run (robust start, snooping)
// recovers the clean camera, loses no good ray a method could keep and lists every blunder it
// keeps as one no test can judge.
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <set>

namespace aerocal::triangulation {
namespace {

using testing::ProjectFromFlight;

AdjustOptions SelfCalibration() {
  AdjustOptions o;
  o.free_interior = ParseSelfCalibration("all");
  return o;
}

bool IsControl(const std::string& point) { return !point.empty() && point[0] == 'C'; }

// The oracle: `p` without the observations in `drop` (removed by hand), adjusted without
// snooping or robust start.
AdjustmentResult Oracle(const Project& p,
                        const std::set<std::pair<std::string, std::string>>& drop) {
  Project without = p;
  without.observations.clear();
  for (const auto& o : p.observations)
    if (!drop.count({o.image, o.point})) without.observations.push_back(o);
  AdjustOptions by_hand = SelfCalibration();
  by_hand.data_snooping = false;
  by_hand.auto_robust_start = false;
  by_hand.estimate_covariance = false;
  return Adjust(without, by_hand);
}

class SnoopingOnTheSimulatedFlight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    FlightSimulationOptions options;
    options.seed = 3;
    flight_ = std::make_unique<SimulatedFlight>(SimulateFlight(options));
    project_ = std::make_unique<Project>(ProjectFromFlight(*flight_));
    clean_ = std::make_unique<AdjustmentResult>(Adjust(*project_, SelfCalibration()));
  }
  // The observation of the clean run (image, point) with group size `group` and both
  // components' r at least `min_r` on a tie or check point seen in >= `min_rays` images.
  static const ObservationResidual* Pick(int group, double min_r) {
    for (const auto& v : clean_->residuals)
      if (v.used && v.test.tested && v.test.group_size == group && !IsControl(v.point) &&
          v.test.redundancy.minCoeff() >= min_r)
        return &v;
    return nullptr;
  }
  // The project with `v`'s measurement moved by (dcol, drow) px.
  static Project Planted(const ObservationResidual& v, double dcol, double drow) {
    Project p = *project_;
    for (auto& o : p.observations)
      if (o.image == v.image && o.point == v.point) o.pixel += Eigen::Vector2d(dcol, drow);
    return p;
  }
  static std::unique_ptr<SimulatedFlight> flight_;
  static std::unique_ptr<Project> project_;
  static std::unique_ptr<AdjustmentResult> clean_;
};
std::unique_ptr<SimulatedFlight> SnoopingOnTheSimulatedFlight::flight_;
std::unique_ptr<Project> SnoopingOnTheSimulatedFlight::project_;
std::unique_ptr<AdjustmentResult> SnoopingOnTheSimulatedFlight::clean_;

TEST_F(SnoopingOnTheSimulatedFlight, ConventionalKeepsTheControlRaysAndSuspectsAModelError) {
  // Issue 9: the uncorrected camera error made snooping reject two rays of the centre control
  // point C5 (check Z RMSE 3.70 m against 0.71 m without snooping).
  AdjustOptions snooping;
  AdjustOptions none;
  none.data_snooping = false;
  const AdjustmentResult a = Adjust(*project_, snooping);
  const AdjustmentResult b = Adjust(*project_, none);
  std::printf("%s", FormatSummary(a).c_str());
  for (const auto& r : a.rejected) EXPECT_FALSE(IsControl(r.point)) << r.image << " " << r.point;
  EXPECT_NEAR(a.check.spatial_rmse_m / b.check.spatial_rmse_m, 1.0, 0.05)
      << a.check.spatial_rmse_m << " vs " << b.check.spatial_rmse_m;
  EXPECT_TRUE(a.snooping.model_error_suspected);
  EXPECT_NE(a.snooping.suggestion.find("self-calibration"), std::string::npos);
  EXPECT_TRUE(a.valid);
}

TEST_F(SnoopingOnTheSimulatedFlight, EveryTestedObservationListsRWMdbAndGroupSize) {
  ASSERT_TRUE(clean_->snooping.run);
  EXPECT_FALSE(clean_->snooping.cofactor_method.empty());
  int tested = 0, groups = 0, joint_mdbs = 0;
  for (const auto& v : clean_->residuals) {
    if (!v.used) continue;
    ASSERT_TRUE(v.test.tested) << v.image << " " << v.point;
    ++tested;
    groups += v.test.group_size > 1;
    for (int k = 0; k < 2; ++k) {
      EXPECT_GE(v.test.redundancy(k), 0.0);
      EXPECT_LE(v.test.redundancy(k), 1.0 + 1e-9);
      // MDB = delta s / sqrt(r) sigma, in px with the observation's sigma: delta = delta0_joint
      // when both components are tested jointly (two controlled directions of Q_ii), delta0
      // when one direction is weakly controlled (a one-dimensional test).
      if (v.test.redundancy(k) > 1e-6) {
        const double unit =
            clean_->snooping.reference_sigma / std::sqrt(v.test.redundancy(k)) * v.sigma_px;
        const bool joint = std::abs(v.test.mdb_px(k) - clean_->snooping.delta0_joint * unit) < 1e-9;
        joint_mdbs += joint;
        if (!joint) {
          EXPECT_NEAR(v.test.mdb_px(k), clean_->snooping.delta0 * unit, 1e-9);
        }
      }
    }
  }
  EXPECT_GT(tested, 2000);
  EXPECT_GT(groups, 0) << "two-ray points form correlated pairs";
  // Clean data (Gaussian noise, self-calibration absorbs the camera error): at most the
  // family-wise level in false rejections (5 %: zero or one here).
  EXPECT_LE(clean_->rejected.size(), 1u);
  EXPECT_NEAR(clean_->snooping.delta0 - clean_->snooping.critical_value, 0.8416, 1e-3);
  EXPECT_NEAR(clean_->snooping.delta0_joint,
              calib::NonCentralityJoint(clean_->snooping.critical_value, 0.8),
              1e-12);
  EXPECT_GT(joint_mdbs, tested) << "most image observations are tested jointly in x and y";
}

TEST_F(SnoopingOnTheSimulatedFlight, ObservationsNoTestCanJudgeAreListedWithTheirReason) {
  // Each used observation with a component r < min_redundancy is listed once, with its r, MDB
  // and why; a two-ray point has one ray equation more than its three unknowns need in y only,
  // so the along-base component of both rays has r = 0: every two-ray check point is listed
  // apart from the controlled check statistics, which are those of the other check points.
  const SnoopingSummary& s = clean_->snooping;
  int weak = 0;
  std::map<std::string, int> rays;
  for (const auto& v : clean_->residuals) rays[v.point] += v.used;
  for (const auto& v : clean_->residuals)
    weak += v.used && v.test.redundancy.minCoeff() < s.min_redundancy;
  ASSERT_EQ(static_cast<int>(s.uncontrolled.size()), weak);
  ASSERT_GT(weak, 0);
  int two_ray = 0;
  for (const auto& u : s.uncontrolled) {
    EXPECT_LT(u.redundancy.minCoeff(), s.min_redundancy) << u.image << " " << u.point;
    EXPECT_EQ(u.rays, rays[u.point]);
    EXPECT_EQ(u.untestable, u.redundancy.minCoeff() < 1e-6);
    if (u.untestable && u.rays == 2) {
      ++two_ray;
      EXPECT_NE(u.reason.find("two-ray point"), std::string::npos) << u.reason;
    }
    if (!u.untestable) {
      EXPECT_NE(u.reason.find("weakly controlled"), std::string::npos) << u.reason;
    }
  }
  EXPECT_GT(two_ray, 0);
  ASSERT_TRUE(clean_->check_controlled.has_value());
  std::vector<PointDifference> controlled;
  int two_ray_checks = 0;
  for (const auto& d : clean_->check_points) {
    if (d.rays == 2) {
      ++two_ray_checks;
      EXPECT_FALSE(d.uncontrolled.empty()) << d.point << " has two rays: r = 0 along the base";
    }
    if (d.uncontrolled.empty()) controlled.push_back(d);
  }
  EXPECT_GT(two_ray_checks, 0);
  EXPECT_EQ(clean_->check_controlled->n, static_cast<int>(controlled.size()));
  EXPECT_LT(clean_->check_controlled->n, clean_->check.n);
  EXPECT_NEAR(clean_->check_controlled->spatial_rmse_m,
              ComputePointStatistics(controlled).spatial_rmse_m,
              1e-12);
  // Listed in the JSON and the terminal summary, beside the unchanged check statistics.
  const nlohmann::json j = AdjustmentToJson(*clean_);
  EXPECT_EQ(j["snooping"]["uncontrolled"].size(), s.uncontrolled.size());
  EXPECT_TRUE(j["snooping"]["uncontrolled"][0]["r"].is_array());
  EXPECT_EQ(j["check_controlled"]["n"].get<int>(), clean_->check_controlled->n);
  EXPECT_EQ(j["check_controlled"]["uncontrolled_points"].size(),
            static_cast<size_t>(clean_->check.n - clean_->check_controlled->n));
  EXPECT_DOUBLE_EQ(j["check"]["spatial_rmse_m"].get<double>(), clean_->check.spatial_rmse_m);
  const std::string summary = FormatSummary(*clean_);
  EXPECT_NE(summary.find("uncontrolled: " + std::to_string(weak) + " observation(s)"),
            std::string::npos);
  EXPECT_NE(summary.find("check*"), std::string::npos);
}

TEST_F(SnoopingOnTheSimulatedFlight, PlantedTwentySigmaBlunderOnAPinnedObservationIsFound) {
  const ObservationResidual* v = Pick(1, 0.3);
  ASSERT_NE(v, nullptr);
  // 20 sigma (0.2 px) in both directions.
  const AdjustmentResult r =
      Adjust(Planted(*v, 4.0 / std::sqrt(2.0), 4.0 / std::sqrt(2.0)), SelfCalibration());
  bool found = false;
  for (const auto& o : r.rejected)
    if (o.image == v->image && o.point == v->point) {
      found = true;
      EXPECT_EQ(o.test.group_size, 1);
      EXPECT_GT(o.w, r.snooping.critical_value);
    }
  EXPECT_TRUE(found) << v->image << " " << v->point;
  EXPECT_LE(r.rejected.size(), 2u);
}

TEST_F(SnoopingOnTheSimulatedFlight, BlunderInATwoRayPairIsReportedAsTheGroup) {
  const ObservationResidual* v = Pick(2, 0.0);
  ASSERT_NE(v, nullptr);
  const AdjustmentResult r = Adjust(Planted(*v, 4.0, 4.0), SelfCalibration());
  std::printf("%s", FormatSummary(r).c_str());
  int of_point = 0;
  for (const auto& o : r.rejected)
    if (o.point == v->point) {
      ++of_point;
      EXPECT_EQ(o.test.group_size, 2);
      EXPECT_EQ(o.group.size(), 2u);
    }
  // Never one arbitrary member named as the gross error: both rays go, as a group.
  EXPECT_EQ(of_point, 2);
  bool said = false;
  for (const auto& f : r.snooping.findings)
    said |= f.find("point " + v->point) != std::string::npos &&
            f.find("cannot be told apart") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST_F(SnoopingOnTheSimulatedFlight, BlunderOnAControlRayGoesAndTheCheckRmseIsTheOracles) {
  // Issue 9's "check RMSE within 2 % of the clean solution": a blunder on a control ray takes that
  // ray's information with it (5 control points, one ray fewer weakens the datum), so the target
  // is the oracle, the ray removed by hand; the clean run's figure is printed beside it.
  const ObservationResidual* v = nullptr;
  std::map<std::string, int> rays;
  for (const auto& o : clean_->residuals) rays[o.point] += o.used;
  for (const auto& o : clean_->residuals)
    if (!v && o.used && o.test.tested && o.test.group_size == 1 && IsControl(o.point) &&
        rays[o.point] >= 3 && o.test.redundancy.minCoeff() >= 0.2)
      v = &o;
  ASSERT_NE(v, nullptr);
  const double g = 20 * v->sigma_px / std::sqrt(2.0);  // 20 sigma, diagonal
  const AdjustmentResult r = Adjust(Planted(*v, g, g), SelfCalibration());
  bool found = false;
  for (const auto& o : r.rejected) found |= o.image == v->image && o.point == v->point;
  EXPECT_TRUE(found) << v->image << " " << v->point;
  // It looked like a model error (the largest w on one control point's rays); without the ray
  // every control ray passes, so the suspicion is withdrawn and no other ray is rejected.
  EXPECT_FALSE(r.snooping.model_error_suspected);
  EXPECT_EQ(r.rejected.size(), 1u);
  for (const auto& f : r.snooping.findings) std::printf("finding: %s\n", f.c_str());
  EXPECT_TRUE(r.valid);
  const AdjustmentResult oracle = Oracle(*project_, {{v->image, v->point}});
  // 2 %: the figure, now against the oracle (bench: within 1.8 % in 40 of 40 seeds).
  constexpr double kCheckRmseTolerance = 0.02;
  EXPECT_NEAR(r.check.spatial_rmse_m / oracle.check.spatial_rmse_m, 1.0, kCheckRmseTolerance);
  std::printf(
      "control ray %s/%s (r %.2f, %.2f): check RMSE %.4f m, the oracle %.4f m, the clean "
      "run %.4f m (/ clean %.3f)\n",
      v->image.c_str(),
      v->point.c_str(),
      v->test.redundancy.x(),
      v->test.redundancy.y(),
      r.check.spatial_rmse_m,
      oracle.check.spatial_rmse_m,
      clean_->check.spatial_rmse_m,
      r.check.spatial_rmse_m / clean_->check.spatial_rmse_m);
}

TEST_F(SnoopingOnTheSimulatedFlight, FivePercentOfFiftySigmaBlundersRecoverTheCleanCamera) {
  // Issue 18: 5 % of the observations moved by 50 sigma in a random direction (seeded).
  Project p = *project_;
  std::mt19937_64 rng(18);
  std::set<std::pair<std::string, std::string>> blunders;
  for (auto& o : p.observations) {
    if (std::uniform_real_distribution<double>(0, 1)(rng) >= 0.05) continue;
    const double angle = std::uniform_real_distribution<double>(0, 2 * M_PI)(rng);
    o.pixel += 50 * o.sigma_px * Eigen::Vector2d(std::cos(angle), std::sin(angle));
    blunders.insert({o.image, o.point});
  }
  ASSERT_GT(blunders.size(), 100u);
  const AdjustmentResult r = Adjust(p, SelfCalibration());
  EXPECT_TRUE(r.snooping.robust_start);  // called for by the first solve's residuals
  // The automatic cap (10 % of the tested observations, at least 100) is not reached.
  EXPECT_GE(r.snooping.max_rejections, 100);
  EXPECT_FALSE(r.snooping.cap_reached);
  EXPECT_TRUE(r.valid) << (r.invalid_reasons.empty() ? "" : r.invalid_reasons.front());
  // The oracle: the blundered observations removed by hand, no snooping. Its camera differs from
  // the clean one by the information of the blundered observations, which no method gets back
  // (over seeds 1-30 of tests/bench/snooping_benchmark.cc it is itself up to 1.55 clean sigmas
  // off); the method's own share is this run against the oracle.
  const AdjustmentResult oracle = Oracle(p, blunders);
  // The method's share (blunders kept on r ~ 0 components, good rays lost): over seeds 1-30 of
  // the benchmark's 5 % case this run was at most 0.44 clean sigmas from the oracle in any
  // parameter (0.23 here); 0.5 is that with a margin, half of the 1 sigma.
  constexpr double kMethodShareSigmas = 0.5;
  // The clean camera within 1 of its sigmas, every free parameter.
  for (int k = 0; k < calib::BrownFraser10Model::kNumParams; ++k) {
    const double sigma = clean_->cameras[0].sigma[k];
    if (!(sigma > 0)) continue;
    EXPECT_LE(std::abs(r.cameras[0].estimated[k] - clean_->cameras[0].estimated[k]), sigma)
        << calib::BrownFraser10Model::kParams[k].name;
    EXPECT_LE(std::abs(r.cameras[0].estimated[k] - oracle.cameras[0].estimated[k]),
              kMethodShareSigmas * sigma)
        << calib::BrownFraser10Model::kParams[k].name;
    std::printf("%s: this run %+.2f, the oracle %+.2f clean sigmas from the clean camera\n",
                std::string(calib::BrownFraser10Model::kParams[k].name).c_str(),
                (r.cameras[0].estimated[k] - clean_->cameras[0].estimated[k]) / sigma,
                (oracle.cameras[0].estimated[k] - clean_->cameras[0].estimated[k]) / sigma);
  }
  // Good rays lost: only on points left with fewer than two good rays (no method can use them)
  // or rejected in a group with a blunder the test could not separate from them. The robust
  // start loses none on a point of three or more good rays (judged there by the point's own fit).
  std::map<std::string, int> good_rays;
  for (const auto& o : p.observations) good_rays[o.point] += !blunders.count({o.image, o.point});
  int good = 0, lost = 0, lost_avoidable = 0;
  for (const auto& v : r.residuals) {
    if (blunders.count({v.image, v.point})) continue;
    ++good;
    if (v.used) continue;
    ++lost;
    bool beside_blunder = good_rays[v.point] < 2;
    for (const auto& x : r.rejected)
      if (x.image == v.image && x.point == v.point) {
        EXPECT_FALSE(x.by == "robust start" && good_rays[v.point] >= 3)
            << v.image << " " << v.point;
        for (const auto& member : x.group)
          beside_blunder |= member != v.image && blunders.count({member, v.point}) > 0;
      }
    lost_avoidable += !beside_blunder;
  }
  std::printf("%zu blunders; good rays lost %d of %d, %d avoidable\n",
              blunders.size(),
              lost,
              good,
              lost_avoidable);
  EXPECT_LE(lost_avoidable, good / 500);  // 0.2 %
  // Every blunder still used is listed as one no test can judge (r below min_redundancy).
  std::set<std::pair<std::string, std::string>> uncontrolled;
  for (const auto& u : r.snooping.uncontrolled) uncontrolled.insert({u.image, u.point});
  for (const auto& v : r.residuals) {
    if (v.used && blunders.count({v.image, v.point})) {
      EXPECT_TRUE(uncontrolled.count({v.image, v.point})) << v.image << " " << v.point;
    }
  }
}

}  // namespace
}  // namespace aerocal::triangulation
