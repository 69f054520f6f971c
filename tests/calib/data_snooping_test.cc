// Data snooping (calib/problem/data_snooping.h) on problems whose cofactors are known in closed
// form: scalar "points" each observed directly n times with weights p_i. Then
//   r_i = 1 - p_i / P (P = sum of the weights), q_ik = -sqrt(p_i p_k) / P,
//   a blunder g (in sigmas) on observation i gives whitened v_i = g r_i, w_i = g sqrt(r_i).
// Two equal observations of one point correlate -1: no test can tell them apart.
#include "calib/problem/data_snooping.h"

#include "calib/residuals/prior.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

namespace aerocal::calib {
namespace {

// Points with value 0, observed as listed (sigmas), plus blunders (value in sigmas of that
// observation). Noise-free otherwise: sigma0 after cleaning is 0 and the test uses sigma 1.
struct Toy {
  ProblemBuilder builder;
  std::deque<double> values;
  std::vector<std::vector<ResidualId>> rays;  // per point
  std::vector<BlockId> blocks;

  void AddPoint(const std::vector<double>& sigmas,
                const std::vector<double>& blunders_sigma = {},
                const std::string& group = kGroupImage) {
    values.push_back(0.0);
    const int p = static_cast<int>(blocks.size());
    blocks.push_back(builder.AddBlock(
        "point P" + std::to_string(p), &values.back(), 1, BlockKind::kGroundPoint));
    rays.emplace_back();
    for (size_t i = 0; i < sigmas.size(); ++i) {
      const double blunder = i < blunders_sigma.size() ? blunders_sigma[i] * sigmas[i] : 0.0;
      rays.back().push_back(
          builder.AddResidual(group,
                              PriorCostFunction::Create({blunder}, {sigmas[i]}),
                              {blocks.back()},
                              "P" + std::to_string(p) + " obs " + std::to_string(i)));
    }
  }
};

// Ten four-ray points: the background of every case (critical value from 40+ components).
void AddBackground(Toy* toy) {
  for (int i = 0; i < 10; ++i) toy->AddPoint({1, 1, 1, 1});
}

TEST(DataSnooping, SingleBlunderOnAFourRayPointIsRejectedWithItsExactTestValues) {
  Toy toy;
  AddBackground(&toy);
  toy.AddPoint({1, 1, 1, 1}, {0, 20, 0, 0});
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, {});
  ASSERT_EQ(out.rejected.size(), 1u);
  const TestedObservation& x = out.rejected[0];
  EXPECT_EQ(x.id, toy.rays[10][1]);
  EXPECT_NEAR(x.redundancy[0], 0.75, 1e-9);  // 1 - 1/4
  // Pope: the reference sigma is sigma0 when above 1: v^T P v = 20^2 0.75, redundancy 44 - 11.
  const double s = std::sqrt(400 * 0.75 / 33);
  EXPECT_NEAR(x.w[0], 20 * std::sqrt(0.75) / s, 1e-6);
  EXPECT_EQ(x.group_size, 1);  // rho = -1/3 with the others
  EXPECT_NEAR(out.delta0, NonCentrality(out.critical_value, 0.8), 1e-12);
  EXPECT_NEAR(out.delta0 - out.critical_value, 0.8416, 1e-3);  // z(80 %)
  EXPECT_NEAR(x.mdb_sigma[0], out.delta0 * s / std::sqrt(0.75), 1e-9);
  EXPECT_FALSE(out.cap_reached);
  // The other rays of the point (w = 20/4 / sqrt(0.75) = 5.8, above the critical value before
  // the rejection) stay: the blunder was the largest of its point.
  for (int i : {0, 2, 3}) EXPECT_TRUE(toy.builder.IsActive(toy.rays[10][i]));
  // Critical value from alpha = 5 % over the 44 components: alpha0 = 0.05 / 44, at least 3.29.
  EXPECT_NEAR(out.alpha0, 0.05 / 44, 1e-12);
  EXPECT_NEAR(out.critical_value, std::max(3.29, NormalCriticalValue(0.05 / 44)), 1e-9);
}

TEST(DataSnooping, TwoRayBlunderIsReportedAsAGroupAndBothRaysGo) {
  Toy toy;
  AddBackground(&toy);
  toy.AddPoint({1, 1}, {20, 0});
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, {});
  ASSERT_EQ(out.rejected.size(), 2u);
  for (const auto& x : out.rejected) {
    EXPECT_EQ(x.group_size, 2);
    EXPECT_NEAR(x.redundancy[0], 0.5, 1e-9);
  }
  EXPECT_FALSE(toy.builder.IsActive(toy.rays[10][0]));
  EXPECT_FALSE(toy.builder.IsActive(toy.rays[10][1]));
  bool said = false;
  for (const auto& f : out.findings) said |= f.find("cannot be told apart") != std::string::npos;
  EXPECT_TRUE(said);
}

TEST(DataSnooping, WeaklyControlledObservationIsReportedNeverRejected) {
  // Weights 1, 1, 400: r = 0.9975, 0.9975, 0.005. A 100-sigma blunder on the precise one gives
  // w = 100 sqrt(0.005) / s = 5.7 there (Pope: s = sigma0 = sqrt(100^2 0.005 / 32)) and
  // 100 * 20 / 402 / sqrt(0.9975) / s = 4.0 on the others: the point's largest w is weakly
  // controlled, so nothing of it is rejected.
  Toy toy;
  AddBackground(&toy);
  toy.AddPoint({1, 1, 0.05}, {0, 0, 100});
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, {});
  EXPECT_TRUE(out.rejected.empty());
  bool weak = false;
  for (const auto& x : out.tested)
    if (x.id == toy.rays[10][2]) {
      weak = x.verdict == SnoopingVerdict::kWeaklyControlled;
      EXPECT_NEAR(x.redundancy[0], 1 - 400.0 / 402.0, 1e-9);
      const double r = 1 - 400.0 / 402.0;
      EXPECT_NEAR(x.w[0], 100 * std::sqrt(r) / std::sqrt(100 * 100 * r / 32), 1e-5);  // solver tol.
    }
  EXPECT_TRUE(weak);
}

TEST(DataSnooping, VetoedAndReportOnlyCandidatesAreNamedNotRemoved) {
  Toy toy;
  AddBackground(&toy);
  toy.AddPoint({1, 1, 1, 1}, {0, 20, 0, 0});
  toy.AddPoint({1, 1, 1, 1}, {30, 0, 0, 0}, kGroupControl);  // a "survey" that disagrees
  SnoopingOptions options;
  options.report_only_groups = {kGroupControl};
  const ResidualId guarded = toy.rays[10][1];
  options.veto = [&](const std::vector<ResidualId>& ids) {
    for (ResidualId id : ids)
      if (id == guarded) return std::string("datum");
    return std::string();
  };
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, options);
  EXPECT_TRUE(out.rejected.empty());
  int vetoed = 0, held = 0;
  for (const auto& x : out.tested) {
    vetoed += x.verdict == SnoopingVerdict::kVetoed;
    held += x.verdict == SnoopingVerdict::kHeld && x.id == toy.rays[11][0];
  }
  EXPECT_EQ(vetoed, 1);
  EXPECT_EQ(held, 1);
  for (const auto& rays : toy.rays)
    for (ResidualId id : rays) EXPECT_TRUE(toy.builder.IsActive(id));
}

TEST(DataSnooping, RejectionCapStopsAndCountsWhatIsLeft) {
  Toy toy;
  AddBackground(&toy);
  for (int i = 0; i < 3; ++i) toy.AddPoint({1, 1, 1, 1}, {25.0 + i, 0, 0, 0});
  SnoopingOptions options;
  options.max_rejections = 1;
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, options);
  EXPECT_EQ(out.rejected.size(), 1u);
  EXPECT_EQ(out.rejected[0].id, toy.rays[12][0]);  // the largest first (27 sigma)
  EXPECT_TRUE(out.cap_reached);
  EXPECT_EQ(out.remaining_above_critical, 2);
}

TEST(DataSnooping, AllIndependentBlundersGoInOneRound) {
  Toy toy;
  AddBackground(&toy);
  for (int i = 0; i < 3; ++i) toy.AddPoint({1, 1, 1, 1}, {0, 0, 20, 0});
  const SnoopingOutcome out = SolveWithDataSnooping(toy.builder, {}, {});
  EXPECT_EQ(out.rejected.size(), 3u);
  for (const auto& x : out.rejected) EXPECT_EQ(x.round, 1);
  EXPECT_EQ(out.rounds, 2);  // the second finds nothing
}

TEST(DataSnooping, JointNonCentralityGivesThePowerOfTheTwoComponentTest) {
  // Oracle: the tail of the non-central chi-square(2, lambda) by integrating the Rice density of
  // R = sqrt(chi2): f(r) = r exp(-(r^2 + lambda) / 2) I0(r sqrt(lambda)), midpoint rule.
  for (double k : {3.29, 4.44, 5.5}) {
    const double delta = NonCentralityJoint(k, 0.8);
    const double t = -2.0 * std::log(std::erfc(k / std::sqrt(2.0)));
    const double lambda = delta * delta, r0 = std::sqrt(t);
    double tail = 0.0;
    const double step = 1e-4;
    for (double r = r0 + step / 2; r < delta + 12; r += step)
      tail += step * r * std::exp(-(r * r + lambda) / 2) * std::cyl_bessel_i(0.0, r * delta);
    EXPECT_NEAR(tail, 0.8, 1e-4) << "k " << k;
    EXPECT_GT(delta, NonCentrality(k, 0.8));  // two degrees of freedom need more
  }
  EXPECT_NEAR(NonCentralityJoint(4.44, 0.8), 5.565, 1e-3);
}

// A hundred four-ray points (sigma 1; points 0-99) and four more (100-103) that also carry a
// "survey" of sigma 0.16 (weight 39.06: r = 4 / 43.06 = 0.093, below min_redundancy, as the
// corner control of a block: a survey blunder there shows mostly on the rays), off by
// `blunders_m` (value units).
std::vector<ResidualId> AddSurveyedPoints(Toy* toy, const std::vector<double>& blunders_m) {
  for (int i = 0; i < 100; ++i) toy->AddPoint({1, 1, 1, 1});
  std::vector<ResidualId> surveys;
  for (int i = 0; i < 4; ++i) {
    toy->AddPoint({1, 1, 1, 1});
    const double blunder = i < static_cast<int>(blunders_m.size()) ? blunders_m[i] : 0.0;
    surveys.push_back(toy->builder.AddResidual(kGroupControl,
                                               PriorCostFunction::Create({blunder}, {0.16}),
                                               {toy->blocks.back()},
                                               "survey P" + std::to_string(100 + i)));
  }
  return surveys;
}

// Snooping with the control group report-only and tested first (leave_out_report_only).
SnoopingOutcome SnoopSurveysFirst(Toy* toy) {
  SnoopingOptions options;
  options.report_only_groups = {kGroupControl};
  options.leave_out_report_only = true;
  return SolveWithDataSnooping(toy->builder, {}, options);
}

TEST(DataSnooping, FailingSurveyIsLeftOutWhenTheOthersFitWithoutIt) {
  // 80 survey sigmas on P100: its residual 0.093 * 80 = 7.4 a-priori sigmas, 5.4 of s = sigma0
  // 1.37, is above the critical value (the block cannot bend to fit it), w = 80 sqrt(0.093) / s
  // = 17.8; the per-direction test called it
  // weakly controlled (r < 0.1). The survey test leaves it out and its rays stay.
  Toy toy;
  const std::vector<ResidualId> surveys = AddSurveyedPoints(&toy, {80 * 0.16});
  const SnoopingOutcome out = SnoopSurveysFirst(&toy);
  ASSERT_EQ(out.left_out.size(), 1u);
  EXPECT_EQ(out.left_out[0].id, surveys[0]);
  EXPECT_EQ(out.left_out[0].verdict, SnoopingVerdict::kLeftOut);
  const double r = 4 / (4 + 1 / (0.16 * 0.16));
  EXPECT_NEAR(out.left_out[0].redundancy[0], r, 1e-9);
  // Pope: s = sigma0 = sqrt(80^2 r / 316) (420 observations, 104 unknowns).
  EXPECT_NEAR(out.left_out[0].w_full, 80 * std::sqrt(r) / std::sqrt(6400 * r / 316), 1e-4);
  EXPECT_FALSE(toy.builder.IsActive(surveys[0]));
  for (int k = 1; k < 4; ++k) EXPECT_TRUE(toy.builder.IsActive(surveys[k]));
  for (const auto& rays : toy.rays)
    for (ResidualId id : rays) EXPECT_TRUE(toy.builder.IsActive(id));
  EXPECT_TRUE(out.rejected.empty());
  EXPECT_NEAR(toy.values[100], 0.0, 1e-9);  // where its rays say, not at the survey
}

TEST(DataSnooping, SurveysThatDoNotFitWithoutTheWorstAreAllRestored) {
  // Two surveys off (as a model error moves several): leaving out the worst (at most one of
  // four, the default third) leaves the other failing, so both are put back, named, and the
  // rays of their points are not rejected.
  Toy toy;
  const std::vector<ResidualId> surveys = AddSurveyedPoints(&toy, {100 * 0.16, -60 * 0.16});
  const SnoopingOutcome out = SnoopSurveysFirst(&toy);
  EXPECT_TRUE(out.left_out.empty());
  for (ResidualId id : surveys) EXPECT_TRUE(toy.builder.IsActive(id));
  for (const auto& rays : toy.rays)
    for (ResidualId id : rays) EXPECT_TRUE(toy.builder.IsActive(id));
  bool said = false;
  for (const auto& f : out.findings)
    said |= f.find("leaving out survey P100") != std::string::npos &&
            f.find("every survey kept") != std::string::npos;
  EXPECT_TRUE(said);
  // Both are named as unresolved: P100 left out first, then P101 at the cap of one.
  ASSERT_EQ(out.unresolved.size(), 2u);
  EXPECT_EQ(out.unresolved[0].id, surveys[0]);
  EXPECT_EQ(out.unresolved[1].id, surveys[1]);
  // Restored: the solution with every survey (P100 pulled to 16 * 39.06 / 43.06).
  const double p = 1 / (0.16 * 0.16);
  EXPECT_NEAR(toy.values[100], 16.0 * p / (4 + p), 1e-6);
}

// Two surveys of one point that has no rays (a height only the surveys hold): their residuals
// correlate -1 (r = 0.5 each), so a blunder on either gives both the same w.
std::vector<ResidualId> AddSurveyPair(Toy* toy, double blunder_sigma) {
  toy->AddPoint({});
  std::vector<ResidualId> pair;
  for (int i = 0; i < 2; ++i)
    pair.push_back(toy->builder.AddResidual(
        kGroupControl,
        PriorCostFunction::Create({i == 0 ? blunder_sigma * 0.16 : 0.0}, {0.16}),
        {toy->blocks.back()},
        "survey Q" + std::to_string(i)));
  return pair;
}

TEST(DataSnooping, SurveysTheTestCannotTellApartAreNamedUnresolvedAndKept) {
  // 40 sigmas on Q0: v = -20, +20 sigmas, w equal on both (the test cannot say which is off).
  // Neither is left out, neither's point loses anything, and both are named as unresolved.
  Toy toy;
  AddSurveyedPoints(&toy, {});
  const std::vector<ResidualId> pair = AddSurveyPair(&toy, 40);
  const SnoopingOutcome out = SnoopSurveysFirst(&toy);
  EXPECT_TRUE(out.left_out.empty());
  ASSERT_EQ(out.unresolved.size(), 2u);
  for (const auto& x : out.unresolved) {
    EXPECT_TRUE(x.id == pair[0] || x.id == pair[1]);
    EXPECT_NEAR(x.redundancy[0], 0.5, 1e-9);
    EXPECT_NEAR(std::abs(x.v[0]), 20.0, 1e-6);
  }
  EXPECT_NEAR(out.unresolved[0].w_full, out.unresolved[1].w_full, 1e-6);
  EXPECT_NE(out.unresolved_reason.find("cannot tell them apart"), std::string::npos);
  for (ResidualId id : pair) EXPECT_TRUE(toy.builder.IsActive(id));
  EXPECT_TRUE(out.rejected.empty());
}

TEST(DataSnooping, SurveySingledOutStaysOutBesideAnUnresolvedPair) {
  // P100 off by 80 survey sigmas fails alone (the largest statistic) and is left out; the pair
  // (20 sigmas on Q0) then fails as a pair: named unresolved and kept, and P100 stays out (putting
  // it back would bend the block by its blunder as well).
  Toy toy;
  const std::vector<ResidualId> surveys = AddSurveyedPoints(&toy, {80 * 0.16});
  const std::vector<ResidualId> pair = AddSurveyPair(&toy, 20);
  const SnoopingOutcome out = SnoopSurveysFirst(&toy);
  ASSERT_EQ(out.left_out.size(), 1u);
  EXPECT_EQ(out.left_out[0].id, surveys[0]);
  EXPECT_FALSE(toy.builder.IsActive(surveys[0]));
  EXPECT_NEAR(toy.values[100], 0.0, 1e-6);  // where its rays say (solver tolerance)
  ASSERT_EQ(out.unresolved.size(), 2u);
  for (ResidualId id : pair) EXPECT_TRUE(toy.builder.IsActive(id));
  EXPECT_NEAR(toy.values[104], 10 * 0.16, 1e-6);  // the mean of the pair's two surveys
}

}  // namespace
}  // namespace aerocal::calib
