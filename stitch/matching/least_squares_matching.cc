#include "stitch/matching/least_squares_matching.h"

#include "calib/core/error.h"

#include <Eigen/Dense>

#include <cmath>
#include <vector>

namespace aerocal::stitch {
namespace {

// Keys cubic convolution (a = -0.5) weights of the 4 taps at -1, 0, 1, 2 for fraction t in [0, 1),
// and their derivatives with respect to t.
void KeysWeights(double t, double w[4], double dw[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = 0.5 * (-t + 2 * t2 - t3);
  w[1] = 0.5 * (2 - 5 * t2 + 3 * t3);
  w[2] = 0.5 * (t + 4 * t2 - 3 * t3);
  w[3] = 0.5 * (-t2 + t3);
  dw[0] = 0.5 * (-1 + 4 * t - 3 * t2);
  dw[1] = 0.5 * (-10 * t + 9 * t2);
  dw[2] = 0.5 * (1 + 8 * t - 9 * t2);
  dw[3] = 0.5 * (-2 * t + 3 * t2);
}

// Bicubic value and gradient (d/dcol, d/drow) at (col, row); false when the 4x4 support leaves b.
bool Sample(const GrayImage& b, double col, double row, double* value, double* gc, double* gr) {
  const double fc = std::floor(col), fr = std::floor(row);
  const int c0 = static_cast<int>(fc) - 1, r0 = static_cast<int>(fr) - 1;
  if (c0 < 0 || r0 < 0 || c0 + 3 >= b.cols() || r0 + 3 >= b.rows()) return false;
  double wc[4], dwc[4], wr[4], dwr[4];
  KeysWeights(col - fc, wc, dwc);
  KeysWeights(row - fr, wr, dwr);
  double v = 0, dc = 0, dr = 0;
  for (int i = 0; i < 4; ++i) {
    double row_v = 0, row_dc = 0;
    for (int j = 0; j < 4; ++j) {
      const double g = b(r0 + i, c0 + j);
      row_v += wc[j] * g;
      row_dc += dwc[j] * g;
    }
    v += wr[i] * row_v;
    dc += wr[i] * row_dc;
    dr += dwr[i] * row_v;
  }
  *value = v;
  *gc = dc;
  *gr = dr;
  return true;
}

using Vector8d = Eigen::Matrix<double, 8, 1>;
using Matrix8d = Eigen::Matrix<double, 8, 8>;

// The template: the (2h + 1)^2 grey values of a round p_a, row by row.
std::vector<double> TemplateAround(const GrayImage& a, const Eigen::Vector2i& p_a, int h) {
  const int side = 2 * h + 1;
  std::vector<double> tmpl(side * side);
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) tmpl[i * side + j] = a(p_a.y() - h + i, p_a.x() - h + j);
  return tmpl;
}

// One linearisation of the model a(x, y) = r0 + r1 b(t + A (x, y)) over the template: the normal
// equations (lower triangle mirrored), v^T v and the resampled patch; false when a pixel's
// bicubic support leaves b. Parameters: t_col, t_row, A00, A01, A10, A11, r0, r1.
bool Linearise(const GrayImage& b,
               const std::vector<double>& tmpl,
               int h,
               const Eigen::Vector2d& t,
               const Eigen::Matrix2d& affine,
               double r0,
               double r1,
               Matrix8d* normal,
               Vector8d* rhs,
               double* vtv,
               std::vector<double>* fitted) {
  const int side = 2 * h + 1;
  normal->setZero();
  *rhs = Vector8d::Zero();
  *vtv = 0;
  for (int i = 0; i < side; ++i) {
    for (int j = 0; j < side; ++j) {
      const double x = j - h, y = i - h;
      const Eigen::Vector2d q = t + affine * Eigen::Vector2d(x, y);
      double g, gc, gr;
      if (!Sample(b, q.x(), q.y(), &g, &gc, &gr)) return false;
      Vector8d jac;
      jac << r1 * gc, r1 * gr, r1 * gc * x, r1 * gc * y, r1 * gr * x, r1 * gr * y, 1.0, g;
      const double v = tmpl[i * side + j] - (r0 + r1 * g);
      normal->selfadjointView<Eigen::Lower>().rankUpdate(jac);
      *rhs += jac * v;
      *vtv += v * v;
      (*fitted)[i * side + j] = g;
    }
  }
  normal->triangularView<Eigen::StrictlyUpper>() = normal->transpose();
  return true;
}

// Correlation coefficient of the template with the resampled patch (0 where one is flat).
double PatchCorrelation(const std::vector<double>& tmpl, const std::vector<double>& fitted) {
  const int n = static_cast<int>(tmpl.size());
  double ma = 0, mb = 0;
  for (int k = 0; k < n; ++k) {
    ma += tmpl[k];
    mb += fitted[k];
  }
  ma /= n;
  mb /= n;
  double sab = 0, saa = 0, sbb = 0;
  for (int k = 0; k < n; ++k) {
    sab += (tmpl[k] - ma) * (fitted[k] - mb);
    saa += (tmpl[k] - ma) * (tmpl[k] - ma);
    sbb += (fitted[k] - mb) * (fitted[k] - mb);
  }
  return saa > 0 && sbb > 0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

void LsmOptions::Validate() const {
  if (half_size_px < 3) throw ConfigError("lsm.half_size_px must be >= 3");
  if (max_iterations < 1) throw ConfigError("lsm.max_iterations must be >= 1");
  if (!(convergence_px > 0)) throw ConfigError("lsm.convergence_px must be > 0");
  if (!(max_shift_px > 0)) throw ConfigError("lsm.max_shift_px must be > 0");
  if (!(max_sigma_px > 0)) throw ConfigError("lsm.max_sigma_px must be > 0");
  if (!(min_correlation >= -1 && min_correlation <= 1))
    throw ConfigError("lsm.min_correlation must be in -1..1");
}

double LsmResult::SigmaMaxPx() const {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov_px2);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

LsmResult MatchLeastSquares(const GrayImage& a,
                            const Eigen::Vector2i& p_a,
                            const GrayImage& b,
                            const Eigen::Vector2d& t0,
                            const Eigen::Matrix2d& a0,
                            const LsmOptions& options) {
  const int h = options.half_size_px;
  AEROCAL_CHECK(p_a.x() - h >= 0 && p_a.y() - h >= 0 && p_a.x() + h < a.cols() &&
                p_a.y() + h < a.rows())
      << "template leaves image a at " << p_a.transpose();
  const std::vector<double> tmpl = TemplateAround(a, p_a, h);
  const int n = static_cast<int>(tmpl.size());

  // Parameters: t_col, t_row, A00, A01, A10, A11, r0, r1.
  Eigen::Vector2d t = t0;
  Eigen::Matrix2d affine = a0;
  double r0 = 0, r1 = 1;
  LsmResult result;
  Matrix8d normal;
  Vector8d rhs;
  double vtv = 0;
  std::vector<double> fitted(n);
  bool converged = false;
  for (int iteration = 1; iteration <= options.max_iterations && !converged; ++iteration) {
    if (!Linearise(b, tmpl, h, t, affine, r0, r1, &normal, &rhs, &vtv, &fitted)) {
      result.status = LsmStatus::kOutside;
      return result;
    }
    const Eigen::LDLT<Matrix8d> ldlt(normal);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return result;  // flat patch
    const Vector8d step = ldlt.solve(rhs);
    if (!step.allFinite()) return result;
    t += step.head<2>();
    affine(0, 0) += step(2);
    affine(0, 1) += step(3);
    affine(1, 0) += step(4);
    affine(1, 1) += step(5);
    r0 += step(6);
    r1 += step(7);
    result.iterations = iteration;
    converged = step.head<2>().norm() < options.convergence_px;
    if ((t - t0).norm() > options.max_shift_px) return result;  // drifted away: not converged
    if (converged) {
      // Precision from the last linearisation (the step is negligible there).
      const double sigma0_sq = vtv / (n - 8);
      const Matrix8d q_xx = ldlt.solve(Matrix8d::Identity());
      result.cov_px2 = sigma0_sq * q_xx.topLeftCorner<2, 2>();
      result.sigma0_dn = std::sqrt(sigma0_sq);
    }
  }
  result.position_in_b = t;
  result.gain = r1;
  result.offset = r0;
  if (!converged) return result;
  // Correlation of the template with the resampled patch at the solution's last linearisation.
  result.correlation = PatchCorrelation(tmpl, fitted);
  if (result.correlation < options.min_correlation) {
    result.status = LsmStatus::kLowCorrelation;
  } else if (result.SigmaMaxPx() > options.max_sigma_px) {
    result.status = LsmStatus::kPoorPrecision;
  } else {
    result.status = LsmStatus::kConverged;
  }
  return result;
}

}  // namespace aerocal::stitch
