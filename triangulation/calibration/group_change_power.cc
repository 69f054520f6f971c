#include "triangulation/calibration/group_change_power.h"

#include <cmath>
#include <numeric>

namespace aerocal::triangulation {
namespace {

// Regularized upper incomplete gamma Q(a, x): the series of P for x < a + 1, else the continued
// fraction of Q (modified Lentz), both to double precision.
double UpperGammaQ(double a, double x) {
  if (x <= 0) return 1.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1) {
    double term = 1.0 / a, sum = term;
    for (int n = 1; n < 10000 && std::abs(term) > std::abs(sum) * 1e-16; ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return std::max(0.0, 1.0 - sum * std::exp(log_prefix));
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1 - a, c = 1 / kTiny, d = 1 / b, h = d;
  for (int n = 1; n < 10000; ++n) {
    const double an = -n * (n - a);
    b += 2;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1) < 1e-16) break;
  }
  return std::exp(log_prefix) * h;
}

// lambda per unit squared change of group j: w_j (1 - w_j / W).
double LambdaPerChange2(const std::vector<double>& sigmas, int group) {
  double total = 0;
  for (double s : sigmas) total += 1.0 / (s * s);
  const double w = 1.0 / (sigmas[group] * sigmas[group]);
  return w * (1.0 - w / total);
}

}  // namespace

double ChiSquareTail(double t, int dof) { return UpperGammaQ(0.5 * dof, 0.5 * t); }

double NonCentralChiSquareTail(double t, int dof, double lambda) {
  if (lambda <= 0) return ChiSquareTail(t, dof);
  // sum_k Poisson(k; lambda / 2) Q(dof / 2 + k, t / 2), summed outwards from the Poisson mode so
  // that large lambda does not underflow the first weights.
  const double h = 0.5 * lambda;
  const int mode = static_cast<int>(h);
  const auto weight = [&](int k) { return std::exp(k * std::log(h) - h - std::lgamma(k + 1.0)); };
  double sum = 0;
  for (int k = mode; k >= 0; --k) {
    const double p = weight(k);
    sum += p * UpperGammaQ(0.5 * dof + k, 0.5 * t);
    if (p < 1e-17 && k < mode) break;
  }
  for (int k = mode + 1;; ++k) {
    const double p = weight(k);
    sum += p * UpperGammaQ(0.5 * dof + k, 0.5 * t);
    if (p < 1e-17) break;
  }
  return std::min(1.0, sum);
}

double GroupChangePower(const std::vector<double>& sigmas,
                        int group,
                        double change,
                        double critical) {
  const int dof = static_cast<int>(sigmas.size()) - 1;
  return NonCentralChiSquareTail(critical, dof, change * change * LambdaPerChange2(sigmas, group));
}

double DetectableGroupChange(const std::vector<double>& sigmas,
                             int group,
                             double critical,
                             double power) {
  const int dof = static_cast<int>(sigmas.size()) - 1;
  // The tail grows monotonically with lambda: bisection to relative 1e-12.
  double lo = 0, hi = 1;
  while (NonCentralChiSquareTail(critical, dof, hi) < power) hi *= 2;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (NonCentralChiSquareTail(critical, dof, mid) < power ? lo : hi) = mid;
  }
  return std::sqrt(0.5 * (lo + hi) / LambdaPerChange2(sigmas, group));
}

}  // namespace aerocal::triangulation
