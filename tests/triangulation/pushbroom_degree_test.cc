// The degree test of the line camera's detector polynomials and the sigma of a selected table
// (triangulation/pushbroom/line_degree_choice.h): the polynomial's value and variance, the top-down
// Wald test in the reduced model (not in the full fit), and the coverage the selected table's
// sigma must give where the selected model's own sigma cannot (a Monte-Carlo of least-squares
// fits with a real cubic at its detection limit).
#include "calib/residuals/line_collinearity.h"
#include "triangulation/pushbroom/line_degree_choice.h"

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <vector>

namespace aerocal::triangulation {
namespace {

using calib::kLineMaxTerms;

TEST(LineDegreeTest, PolynomialValueAndVarianceOnOneAxis) {
  std::vector<double> a(2 * kLineMaxTerms, 0.0);
  a[0] = 1.0;  // x: 1 + 2u
  a[1] = 2.0;
  a[kLineMaxTerms + 2] = 3.0;  // y: 3u^2
  Eigen::MatrixXd q = Eigen::MatrixXd::Zero(2 * kLineMaxTerms, 2 * kLineMaxTerms);
  q(0, 0) = 0.04;
  q(1, 1) = 0.09;
  q(0, 1) = q(1, 0) = 0.01;
  q(kLineMaxTerms + 2, kLineMaxTerms + 2) = 0.25;
  const TableValue x = EvaluateDetectorPolynomial(a.data(), q, 0, 0.5);
  EXPECT_DOUBLE_EQ(x.value, 2.0);
  EXPECT_NEAR(x.variance, 0.04 + 0.25 * 0.09 + 2 * 0.5 * 0.01, 1e-15);  // g = (1, 0.5)
  const TableValue y = EvaluateDetectorPolynomial(a.data(), q, 1, -0.5);
  EXPECT_DOUBLE_EQ(y.value, 0.75);
  EXPECT_NEAR(y.variance, 0.0625 * 0.25, 1e-15);
  // No covariance: the value, variance 0.
  EXPECT_EQ(EvaluateDetectorPolynomial(a.data(), Eigen::MatrixXd(), 0, 0.5).variance, 0.0);
}

TEST(LineDegreeTest, DropsFromTheTopAndTestsEachTermInTheReducedModel) {
  std::vector<double> a(2 * kLineMaxTerms, 0.0);
  Eigen::MatrixXd q = Eigen::MatrixXd::Identity(2 * kLineMaxTerms, 2 * kLineMaxTerms);
  // Independent terms (unit sigmas): a_5 = 0.5, a_4 = -1.0 insignificant, a_3 = 2.5 is not.
  a[3] = 2.5;
  a[4] = -1.0;
  a[5] = 0.5;
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 0, 5, {}, 0.05), 3);
  // At alpha 0.01 (z = 2.576) a_3 goes too, and then a_2 = a_1 = a_0 = 0: nothing is kept.
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 0, 5, {}, 0.01), -1);
  // A held entry (fixed or the datum's) neither decides nor stops the test.
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 0, 5, {3}, 0.05), -1);
  // The y axis is tested on its own entries.
  a[kLineMaxTerms + 1] = 5.0;
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 1, 5, {}, 0.05), 1);

  // Correlated a_3, a_5 (rho 0.9): a_3 = 1.2 is insignificant in the full fit (z 1.2), but with
  // a_5 = -1 dropped its restricted estimate is 1.2 - 0.9 (-1) = 2.1 with variance 1 - 0.81:
  // z = 4.8, kept. Testing each term in the full fit would drop it (README "Degree test").
  std::fill(a.begin(), a.end(), 0.0);
  q = Eigen::MatrixXd::Identity(2 * kLineMaxTerms, 2 * kLineMaxTerms);
  q(3, 5) = q(5, 3) = 0.9;
  a[3] = 1.2;
  a[5] = -1.0;
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 0, 5, {}, 0.05), 3);
  // The start degree bounds the test.
  EXPECT_EQ(TopDownWaldDegree(a.data(), q, 0, 2, {}, 0.05), -1);
}

TEST(LineDegreeTest, SelectedSigmaIsAtLeastTheStartFitsAndGrowsWithTheShift) {
  // No reduction: the fit's own sigma.
  EXPECT_DOUBLE_EQ(SelectedTableSigma({1.0, 0.04}, {1.0, 0.04}), 0.2);
  // Reduced, table unmoved: the start fit's sigma (the dropped terms' share stays).
  EXPECT_DOUBLE_EQ(SelectedTableSigma({1.0, 0.04}, {1.0, 0.09}), 0.3);
  // Reduced and moved by d = 0.5 > sqrt(0.09 - 0.04): sqrt(0.04 + 0.25).
  EXPECT_DOUBLE_EQ(SelectedTableSigma({1.5, 0.04}, {1.0, 0.09}), std::sqrt(0.29));
}

// Least squares of y = sum_k b_k u^k + e (sigma 1) at 60 equally spaced u in [-1, 1], start
// degree 3: b_0, b_1 ten of their sigmas, b_2 = 0, a cubic of tau of its sigma. The selected
// table's error at the end detector (u = 1) against the 95 % interval. Measured over 20000 fits
// (line_degree_choice.h): tau 2.5, the cubic dropped in 30 %: the reduced fit's own sigma covers
// 0.72, SelectedTableSigma 0.926; tau 0 (dropped in 95 %): 0.925 and 0.982.
struct Coverage {
  int reduced_runs = 0, covered_fit = 0, covered_selected = 0;
};
Coverage EndCoverage(double tau, int runs) {
  constexpr int kPoints = 60, kStart = 3;
  Eigen::MatrixXd design(kPoints, kStart + 1);
  for (int i = 0; i < kPoints; ++i) {
    const double u = -1.0 + 2.0 * i / (kPoints - 1);
    for (int k = 0; k <= kStart; ++k) design(i, k) = std::pow(u, k);
  }
  const Eigen::MatrixXd q_start = (design.transpose() * design).inverse();
  Eigen::VectorXd truth(kStart + 1);
  truth << 10 * std::sqrt(q_start(0, 0)), 10 * std::sqrt(q_start(1, 1)), 0.0,
      tau * std::sqrt(q_start(3, 3));
  const double truth_at_end = truth.sum();  // u = 1
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, 1.0);
  // A 12-entry detector block: the fitted x entries, the rest zero and held.
  auto block = [](const Eigen::VectorXd& b,
                  const Eigen::MatrixXd& qb,
                  std::vector<double>* a,
                  Eigen::MatrixXd* q) {
    a->assign(2 * kLineMaxTerms, 0.0);
    *q = Eigen::MatrixXd::Zero(2 * kLineMaxTerms, 2 * kLineMaxTerms);
    for (int k = 0; k < b.size(); ++k) {
      (*a)[k] = b[k];
      for (int m = 0; m < b.size(); ++m) (*q)(k, m) = qb(k, m);
    }
  };
  std::set<int> held;
  for (int e = kStart + 1; e < 2 * kLineMaxTerms; ++e) held.insert(e);
  Coverage out;
  for (int run = 0; run < runs; ++run) {
    Eigen::VectorXd y = design * truth;
    for (int i = 0; i < kPoints; ++i) y[i] += noise(rng);
    std::vector<double> a;
    Eigen::MatrixXd q;
    block(q_start * design.transpose() * y, q_start, &a, &q);
    const int degree = TopDownWaldDegree(a.data(), q, 0, kStart, held, 0.05);
    const TableValue start = EvaluateDetectorPolynomial(a.data(), q, 0, 1.0);
    // The reduced fit: least squares on the kept columns (as the adjustment solves again).
    const Eigen::MatrixXd kept = design.leftCols(degree + 1);
    const Eigen::MatrixXd q_reduced = (kept.transpose() * kept).inverse();
    block(q_reduced * kept.transpose() * y, q_reduced, &a, &q);
    const TableValue reduced = EvaluateDetectorPolynomial(a.data(), q, 0, 1.0);
    out.reduced_runs += degree < kStart;
    const double error = std::abs(reduced.value - truth_at_end);
    out.covered_fit += error < 1.96 * std::sqrt(reduced.variance);
    out.covered_selected += error < 1.96 * SelectedTableSigma(reduced, start);
  }
  return out;
}

TEST(LineDegreeTest, SelectedSigmaCoversTheTruthWhereTheReducedFitsDoesNot) {
  constexpr int kRuns = 4000;  // binomial spread of a coverage near 0.93: 0.004
  // A real cubic at the detection limit: dropped in P(|N(2.5, 1)| < 1.96) = 0.29 of the fits.
  const Coverage limit = EndCoverage(2.5, kRuns);
  EXPECT_NEAR(limit.reduced_runs, 0.29 * kRuns, 0.03 * kRuns);
  EXPECT_LT(limit.covered_fit, 0.80 * kRuns);
  EXPECT_GT(limit.covered_selected, 0.91 * kRuns);
  // No cubic, no quadratic: both dropped in most fits; the selected sigma is then conservative.
  const Coverage none = EndCoverage(0.0, kRuns);
  EXPECT_GT(none.reduced_runs, 0.9 * kRuns);
  EXPECT_GT(none.covered_selected, 0.96 * kRuns);
  std::printf(
      "95 %% coverage at the end: cubic 2.5 sigma (dropped in %d of %d): fit sigma %.3f, "
      "selected %.3f; no cubic: %.3f, %.3f\n",
      limit.reduced_runs,
      kRuns,
      double(limit.covered_fit) / kRuns,
      double(limit.covered_selected) / kRuns,
      double(none.covered_fit) / kRuns,
      double(none.covered_selected) / kRuns);
}

}  // namespace
}  // namespace aerocal::triangulation
