// The degree of a line camera's detector polynomials (module README "Degree test"), and the
// sigma of a table whose degree a test chose.
//
// One detector block holds both axes of a sub-camera's polynomial in the normalised index u in
// [-1, 1]: entries 0..5 are dx = a_0 + a_1 u + ... + a_5 u^5 (across track), 6..11 dy (along
// track), mm; q is their 12 x 12 covariance (sigma0^2 Q).
//
// Why the sigma of a selected table is not the selected model's own: the test is a pre-test. A
// real term below its threshold is dropped, and the reduced model's sigma does not show that
// bias; a noise term above it is kept, with an estimate inflated by the selection. Measured over
// 100 simulated flights (triangulation/pushbroom_study, true cubics at the detection limit): the
// reduced model's own sigmas put the table RMS error at 1.12 x its predicted sigma and left 49 of
// 100 flights within pointwise 3 sigma (degree 3 given: 89). SelectedTableSigma states at least
// what the start-degree fit knows and at least the distance the selection moved the table.
#pragma once

#include <Eigen/Core>

#include <set>

namespace aerocal::triangulation {

/// Value and variance at u of one axis (0: x, 1: y) of a detector polynomial: g'a and g'qg with
/// g = (1, u, ..., u^5) on that axis' entries.
struct TableValue {
  double value = 0.0, variance = 0.0;
};
TableValue EvaluateDetectorPolynomial(const double* coefficients,
                                      const Eigen::MatrixXd& q,
                                      int axis,
                                      double u);

/// Top-down Wald test of one axis: from `start_degree` down, drop the highest free coefficient
/// while it is insignificant at `alpha` (two-sided, one degree of freedom) in the model without
/// the terms already dropped. Entries in `held` (fixed, or held by the datum) neither count nor
/// stop the test. The reduced model's estimate and variance come from the start fit by restricted
/// least squares (b_e - Q_eB Q_BB^-1 b_B, Q_ee - Q_eB Q_BB^-1 Q_Be), so one solve serves every
/// step. Returns the highest kept degree; -1 when every free term was dropped.
int TopDownWaldDegree(const double* coefficients,
                      const Eigen::MatrixXd& q,
                      int axis,
                      int start_degree,
                      const std::set<int>& held,
                      double alpha);

/// Sigma of one table value after the degree test: sqrt(s_r^2 + max(d^2, s_0^2 - s_r^2)), with
/// s_r the selected (reduced) fit's sigma, s_0 the start-degree fit's and d the reduced minus the
/// start-degree value. So it is never below the start-degree fit's sigma (the dropped terms are
/// not assumed to be zero: their share s_0^2 - s_r^2 stays), and it grows with the shift d the
/// selection caused (a bias the reduced model cannot see). Without a reduction (d = 0,
/// s_0 = s_r) it is s_r. Measured against the alternatives (least-squares Monte-Carlo of
/// pushbroom_degree_test with a cubic of tau sigmas, coverage of the 95 % interval at the end of
/// the range; the flight study over true amplitudes 0, 0.5, 2 px, table RMS error / sigma):
/// - the reduced fit's own sigma: coverage 0.66 at tau = 2, flights 1.04 .. 1.22;
/// - s_r^2 + d^2 - (s_0^2 - s_r^2), unbiased for the mean squared error without the test: the
///   test keeps d small exactly where it dropped a real term (55 of 100 flights within 3 sigma);
/// - the GUM's uncorrected bias, s_0^2 + d^2: coverage 0.945 .. 0.98, but 0.58 on flights whose
///   corrections are all zero (the test drops every term: the table is zero, exact, d the noise);
/// - this: coverage 0.926 .. 0.98, flights 0.89 .. 0.92, and 0.65 with zero errors (conservative
///   there: the table is exact, its sigma stays s_0).
double SelectedTableSigma(const TableValue& reduced, const TableValue& start);

}  // namespace aerocal::triangulation
