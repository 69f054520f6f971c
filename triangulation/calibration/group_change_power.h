// How large a change of ONE group's camera the group-stability test detects (issue 14): the
// analogue of the marginal detectable blunder for the chi-square test of calibration.h.
//
// Per parameter, groups g with estimates v_g and sigmas s_g (weights w_g = 1 / s_g^2, W = sum w_g)
// are tested by chi2 = sum w_g (v_g - m)^2 against chi^2(G - 1). When group j alone is off by a
// change d, chi2 follows the non-central chi^2(G - 1, lambda) with
//   lambda = d^2 w_j (1 - w_j / W)
// (the quadratic form sum w_g (e_g - m_e)^2 of the shift vector e = d at j, 0 elsewhere). The
// power of the test is P(chi^2(G - 1, lambda) > critical); the detectable change at a power beta
// is d = sqrt(lambda0 / (w_j (1 - w_j / W))) with P(chi^2(G - 1, lambda0) > critical) = beta.
// Three equal groups and a 3-sigma change: lambda = 9 * 2/3 = 6, power ~0.58 at 5 % (one test),
// lower with the Bonferroni critical value the stability test uses over several parameters.
#pragma once

#include <vector>

namespace aerocal::triangulation {

/// P(X > t) for X ~ chi^2(dof), dof >= 1, t >= 0 (regularized upper incomplete gamma).
double ChiSquareTail(double t, int dof);

/// P(X > t) for X ~ chi^2(dof, lambda), the non-central chi-square (Poisson mixture of central
/// chi-squares; exact to ~1e-12 for lambda up to ~1e4).
double NonCentralChiSquareTail(double t, int dof, double lambda);

/// Power of the group-stability test (critical value `critical`, G - 1 = sigmas.size() - 1 degrees
/// of freedom) against a change `change` of group `group` alone. Sigmas > 0.
double GroupChangePower(const std::vector<double>& sigmas,
                        int group,
                        double change,
                        double critical);

/// The change of group `group` alone that the test detects with probability `power` (0 < power
/// < 1). Sigmas > 0; two groups or more.
double DetectableGroupChange(const std::vector<double>& sigmas,
                             int group,
                             double critical,
                             double power);

}  // namespace aerocal::triangulation
