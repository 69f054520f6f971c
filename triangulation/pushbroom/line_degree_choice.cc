#include "triangulation/pushbroom/line_degree_choice.h"

#include "calib/camera/line_camera.h"
#include "calib/problem/problem_builder.h"
#include "calib/residuals/line_collinearity.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aerocal::triangulation {

using calib::kLineMaxTerms;

TableValue EvaluateDetectorPolynomial(const double* coefficients,
                                      const Eigen::MatrixXd& q,
                                      int axis,
                                      double u) {
  const int base = axis * kLineMaxTerms;
  TableValue out;
  out.value = calib::EvaluatePolynomial(coefficients + base, kLineMaxTerms, u);
  if (q.rows() < 2 * kLineMaxTerms) return out;
  Eigen::VectorXd g = Eigen::VectorXd::Zero(2 * kLineMaxTerms);
  double power = 1.0;
  for (int k = 0; k < kLineMaxTerms; ++k, power *= u) g[base + k] = power;
  out.variance = std::max(0.0, g.dot(q * g));
  return out;
}

int TopDownWaldDegree(const double* coefficients,
                      const Eigen::MatrixXd& q,
                      int axis,
                      int start_degree,
                      const std::set<int>& held,
                      double alpha) {
  const int base = axis * kLineMaxTerms;
  const double z = calib::NormalCriticalValue(alpha);
  std::vector<int> dropped;
  int chosen = start_degree;
  for (; chosen >= 0; --chosen) {
    const int e = base + chosen;
    if (held.count(e)) continue;  // fixed or held by the datum: does not decide
    double beta = coefficients[e], var = q(e, e);
    if (!dropped.empty()) {
      const int nb = int(dropped.size());
      Eigen::MatrixXd qbb(nb, nb);
      Eigen::VectorXd qeb(nb), bb(nb);
      for (int k = 0; k < nb; ++k) {
        qeb[k] = q(e, dropped[k]);
        bb[k] = coefficients[dropped[k]];
        for (int m = 0; m < nb; ++m) qbb(k, m) = q(dropped[k], dropped[m]);
      }
      const Eigen::LDLT<Eigen::MatrixXd> ldlt(qbb);
      beta -= qeb.dot(ldlt.solve(bb));
      var -= qeb.dot(ldlt.solve(qeb));
    }
    if (!(var > 0) || !(beta * beta / var < z * z)) break;
    dropped.push_back(e);
  }
  return chosen;
}

double SelectedTableSigma(const TableValue& reduced, const TableValue& start) {
  const double d = reduced.value - start.value;
  const double dropped_share = std::max(0.0, start.variance - reduced.variance);
  return std::sqrt(std::max(0.0, reduced.variance) + std::max(d * d, dropped_share));
}

}  // namespace aerocal::triangulation
