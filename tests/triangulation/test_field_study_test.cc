// Monte-Carlo study of the simulated test field (issue 14 acceptance; label `long`, minutes):
// - 50 calibrations of independent test fields (3 groups of 24 images): how often the groups'
//   chi-square test (5 %) passes per parameter and for all parameters together; how often it
//   fails when one group's c is changed by 3 of that group's sigmas, and by the change the result
//   states as detectable with 80 % power: both flagged as often as the power of the test predicts
//   (group_change_power.h; a 3-sigma change of one of three groups has the non-centrality 6, ~58 %
//   for one 5 % test, less with the Bonferroni level over the free parameters);
// - the spread of c, x0, y0 over the runs against the sigmas the adjustment states (within 25 %);
// - 100 calibrations whose target coordinates carry survey errors: how often the expanded
//   uncertainty interval (k = 2 or from nu_eff) of c, x0, y0 covers the truth (>= 93 %).
// AEROCAL_STUDY_RUNS=N scales both run counts down (a quick look); the asserted counts are the
// issue's at 50 / 100 runs.
#include "triangulation/calibration/calibration.h"
#include "triangulation/calibration/group_change_power.h"
#include "triangulation/calibration/uncertainty_budget.h"
#include "triangulation/simulation/test_field_simulator.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

int Runs(int issue_count) {
  const char* env = std::getenv("AEROCAL_STUDY_RUNS");
  return env ? std::max(1, std::min(issue_count, std::atoi(env))) : issue_count;
}

CalibrationRun CalibrateField(const SimulatedTestField& f) {
  CalibrateOptions o;  // as tests/triangulation/test_field_test.cc
  o.adjust.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2,P1,P2");
  o.adjust.data_snooping = false;
  return Calibrate(TestFieldProject(f), o, f.group_of_image);
}

const StabilityRow* Row(const CalibrationRun& run, const std::string& name) {
  for (const auto& r : run.stability.rows)
    if (r.parameter == name) return &r;
  return nullptr;
}

TEST(TestFieldStudy, GroupChiSquareAndSigmasAgainstTheSpread) {
  const int runs = Runs(50);
  std::map<std::string, int> agree;
  int all_agree = 0, changed_flagged = 0, detectable_flagged = 0;
  double changed_expected = 0, changed_variance = 0;  // sum of the predicted powers, binomial
  const int params[3] = {Model::kC, Model::kX0, Model::kY0};
  double sum[3] = {}, sum2[3] = {}, sigma2[3] = {};
  for (int i = 0; i < runs; ++i) {
    TestFieldOptions o;
    o.seed = 1000 + i;
    const SimulatedTestField f = SimulateTestField(o);
    const CalibrationRun run = CalibrateField(f);
    ASSERT_TRUE(run.all.result.valid) << "seed " << o.seed;
    all_agree += run.stability.agree;
    for (const auto& row : run.stability.rows) agree[row.parameter] += row.agree;
    const CameraEstimate& c = run.all.result.cameras[0];
    for (int k = 0; k < 3; ++k) {
      const double e = c.estimated[params[k]] - f.truth.interior[params[k]];
      sum[k] += e;
      sum2[k] += e * e;
      sigma2[k] += c.sigma[params[k]] * c.sigma[params[k]];
    }
    // The same field with group B's c changed by 3 of its sigmas.
    const StabilityRow* row_c = Row(run, "c");
    ASSERT_NE(row_c, nullptr);
    TestFieldOptions changed = o;
    changed.changed_group = 1;
    changed.group_camera_change[Model::kC] = 3.0 * row_c->sigmas[1];
    const CalibrationRun run_changed = CalibrateField(SimulateTestField(changed));
    const StabilityRow* changed_c = Row(run_changed, "c");
    changed_flagged += changed_c && !changed_c->agree;
    const double power =
        GroupChangePower(row_c->sigmas, 1, 3.0 * row_c->sigmas[1], row_c->critical);
    changed_expected += power;
    changed_variance += power * (1 - power);
    // ... and by the change the stability table states as detectable with 80 % power.
    changed.group_camera_change[Model::kC] = row_c->detectable_change[1];
    const StabilityRow* detect_c = Row(CalibrateField(SimulateTestField(changed)), "c");
    detectable_flagged += detect_c && !detect_c->agree;
  }
  std::printf("%d runs: groups agree (all parameters) %d; per parameter:", runs, all_agree);
  for (const auto& [name, n] : agree) std::printf(" %s %d", name.c_str(), n);
  std::printf(
      "; c changed by 3 sigma in one group flagged %d (predicted %.1f); by the detectable "
      "change (80 %%) flagged %d\n",
      changed_flagged,
      changed_expected,
      detectable_flagged);
  for (int k = 0; k < 3; ++k) {
    const double mean = sum[k] / runs;
    const double spread = std::sqrt(std::max(0.0, sum2[k] / runs - mean * mean));
    const double sigma = std::sqrt(sigma2[k] / runs);
    std::printf(
        "%s: spread of the error %.3g mm, stated sigma (rms) %.3g mm, ratio %.3f, mean error "
        "%.3g\n",
        std::string(Model::kParams[params[k]].name).c_str(),
        spread,
        sigma,
        spread / sigma,
        mean);
    if (runs >= 50) {
      EXPECT_NEAR(spread / sigma, 1.0, 0.25) << Model::kParams[params[k]].name;
    }
  }
  if (runs >= 50) {
    // The test at its 5 % level, per parameter: passes in >= 90 % of the runs.
    for (const auto& [name, n] : agree) EXPECT_GE(n, 45) << name;
    // A 3-sigma change of one group of three: flagged as often as the test's power predicts
    // (within 3 binomial sigmas of the sum of the per-run powers), and the stated detectable
    // change in at least 80 % - 3 binomial sigmas of the runs.
    EXPECT_NEAR(changed_flagged, changed_expected, 3 * std::sqrt(changed_variance) + 1);
    EXPECT_GE(detectable_flagged, 0.8 * runs - 3 * std::sqrt(0.16 * runs));
  }
}

TEST(TestFieldStudy, ExpandedUncertaintyCoversTheTruth) {
  const int runs = Runs(100);
  int covered[3] = {}, valid = 0;
  const int params[3] = {Model::kC, Model::kX0, Model::kY0};
  const char* names[3] = {"c", "x0", "y0"};
  for (int i = 0; i < runs; ++i) {
    TestFieldOptions o;
    o.seed = 5000 + i;
    o.survey_sigma_m = 0.001;  // 1 mm survey errors in the target coordinates (and their sigma)
    const SimulatedTestField f = SimulateTestField(o);
    const CalibrationRun run = CalibrateField(f);
    if (!run.all.result.valid) continue;
    ++valid;
    const auto budget = UncertaintyBudget(run, run.project, {{5.0, 10.0}, 0.0, {}, {}});
    for (int k = 0; k < 3; ++k) {
      const auto q = std::find_if(budget.begin(), budget.end(), [&](const BudgetQuantity& b) {
        return b.name == names[k];
      });
      ASSERT_NE(q, budget.end()) << names[k];
      covered[k] += std::abs(q->value - f.truth.interior[params[k]]) <= q->expanded;
    }
  }
  std::printf("%d runs (%d valid): U (k from nu_eff) covers the truth: c %d, x0 %d, y0 %d\n",
              runs,
              valid,
              covered[0],
              covered[1],
              covered[2]);
  EXPECT_EQ(valid, runs);
  if (runs >= 100) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_GE(covered[k], 93) << names[k];
    }
  }
}

}  // namespace
}  // namespace aerocal::triangulation
