// F distribution for the variance-ratio test between nested least-squares models.
// With v^T P v and redundancy r of a simpler model (s) and a richer one (c) on the same
// observations,
//   F = ((vtpv_s - vtpv_c) / (r_s - r_c)) / (vtpv_c / r_c)  ~  F(r_s - r_c, r_c)
// when the extra parameters of the richer model are zero (Koch, Parameter Estimation and
// Hypothesis Testing in Linear Models, section 4.2). The CDF is the regularized incomplete beta
// function I_x(d1/2, d2/2) with x = d1 F / (d1 F + d2), by Lentz's continued fraction.
#pragma once

namespace aerocal::stitch {

/// P(X <= f) for X ~ F(d1, d2); d1, d2 > 0, f >= 0.
double FDistributionCdf(double f, double d1, double d2);

/// Quantile: f with P(X <= f) = p, 0 < p < 1 (bisection on the CDF, relative 1e-10).
double FDistributionQuantile(double p, double d1, double d2);

}  // namespace aerocal::stitch
