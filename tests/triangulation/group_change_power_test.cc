// The sensitivity of the group-stability test (group_change_power.h): the chi-square tails against
// closed forms, the non-central tail against the normal form for 1 degree of freedom and against
// data snooping's independent chi-square(2) computation, the power against a Monte-Carlo run of
// the test itself (unequal group sigmas), and the detectable change as the power's inverse.
#include "triangulation/calibration/group_change_power.h"

#include "calib/problem/data_snooping.h"
#include "triangulation/calibration/calibration.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace aerocal::triangulation {
namespace {

double UpperNormal(double z) { return 0.5 * std::erfc(z / std::sqrt(2.0)); }

TEST(GroupChangePower, CentralTailsEqualTheClosedForms) {
  for (double t : {0.01, 0.5, 2.0, 5.99, 13.8, 40.0}) {
    EXPECT_NEAR(ChiSquareTail(t, 1), std::erfc(std::sqrt(t / 2)), 1e-13) << t;
    EXPECT_NEAR(ChiSquareTail(t, 2), std::exp(-t / 2), 1e-13) << t;
    EXPECT_NEAR(ChiSquareTail(t, 4), std::exp(-t / 2) * (1 + t / 2), 1e-13) << t;
  }
  // The quantile of calibration.h is the tail's inverse.
  for (int dof : {1, 2, 3, 6})
    EXPECT_NEAR(ChiSquareTail(ChiSquareQuantile(0.95, dof), dof), 0.05, 1e-6);
}

TEST(GroupChangePower, NonCentralTailForOneDegreeIsTheShiftedNormal) {
  // chi^2(1, lambda) = (Z + sqrt lambda)^2.
  for (double lambda : {0.0, 0.3, 6.0, 25.0, 400.0})
    for (double t : {1.0, 3.84, 9.0, 30.0}) {
      const double expected = UpperNormal(std::sqrt(t) - std::sqrt(lambda)) +
                              UpperNormal(std::sqrt(t) + std::sqrt(lambda));
      EXPECT_NEAR(NonCentralChiSquareTail(t, 1, lambda), expected, 1e-11) << lambda << " " << t;
    }
}

TEST(GroupChangePower, NonCentralTailForTwoDegreesAgreesWithDataSnooping) {
  // NonCentralityJoint: sqrt(lambda) for which chi^2(2, lambda) exceeds the chi^2(2) value of the
  // two-sided normal tail of k with probability `power` (its own series).
  for (double k : {3.29, 4.44}) {
    const double t = -2 * std::log(std::erfc(k / std::sqrt(2.0)));
    const double delta = calib::NonCentralityJoint(k, 0.8);
    EXPECT_NEAR(NonCentralChiSquareTail(t, 2, delta * delta), 0.8, 1e-8) << k;
  }
}

TEST(GroupChangePower, PowerMatchesAMonteCarloOfTheTest) {
  const std::vector<double> sigmas = {0.002, 0.003, 0.0025, 0.004};  // unequal groups
  const double critical = ChiSquareQuantile(1 - 0.05 / 7, 3);        // Bonferroni over 7 parameters
  const int changed = 1;
  const double change = 3 * sigmas[changed];
  const double predicted = GroupChangePower(sigmas, changed, change, critical);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const int runs = 200000;
  int flagged = 0;
  for (int i = 0; i < runs; ++i) {
    double sw = 0, swv = 0;
    std::vector<double> v(sigmas.size());
    for (size_t g = 0; g < sigmas.size(); ++g) {
      v[g] = sigmas[g] * normal(rng) + (static_cast<int>(g) == changed ? change : 0.0);
      sw += 1 / (sigmas[g] * sigmas[g]);
      swv += v[g] / (sigmas[g] * sigmas[g]);
    }
    double chi2 = 0;
    for (size_t g = 0; g < sigmas.size(); ++g) chi2 += std::pow((v[g] - swv / sw) / sigmas[g], 2);
    flagged += chi2 > critical;
  }
  const double measured = static_cast<double>(flagged) / runs;
  const double binomial_sigma = std::sqrt(predicted * (1 - predicted) / runs);
  EXPECT_NEAR(measured, predicted, 4 * binomial_sigma) << "predicted " << predicted;
  EXPECT_GT(predicted, 0.1);
  EXPECT_LT(predicted, 0.9);
}

TEST(GroupChangePower, ThreeEqualGroupsAtThreeSigmaHaveTheTextbookNonCentrality) {
  // lambda = 9 * (1 - 1/3) = 6: one 5 % test with 2 dof flags ~58 %.
  const std::vector<double> sigmas(3, 1.0);
  const double critical = ChiSquareQuantile(0.95, 2);
  EXPECT_NEAR(
      GroupChangePower(sigmas, 0, 3.0, critical), NonCentralChiSquareTail(critical, 2, 6.0), 1e-14);
  EXPECT_NEAR(GroupChangePower(sigmas, 0, 3.0, critical), 0.58, 0.01);
}

TEST(GroupChangePower, DetectableChangeIsThePowersInverse) {
  const std::vector<double> sigmas = {0.5, 1.0, 2.0};
  const double critical = ChiSquareQuantile(1 - 0.05 / 4, 2);
  for (int g = 0; g < 3; ++g) {
    const double d = DetectableGroupChange(sigmas, g, critical, 0.8);
    EXPECT_NEAR(GroupChangePower(sigmas, g, d, critical), 0.8, 1e-9) << g;
    EXPECT_GT(d, 2 * sigmas[g]);  // more than twice the group's own sigma at 80 %
  }
  // The least precise group needs the largest change.
  EXPECT_LT(DetectableGroupChange(sigmas, 0, critical, 0.8),
            DetectableGroupChange(sigmas, 2, critical, 0.8));
}

}  // namespace
}  // namespace aerocal::triangulation
