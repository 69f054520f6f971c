#include "calib/problem/residual_evaluator.h"

#include "calib/problem/block_kernels.h"
#include "calib/problem/parallel_for.h"

#include <Eigen/Core>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace aerocal::calib::internal {

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Triggs' correction of one residual block for a loss rho (Ceres' Corrector, corrector.cc): with
// s = |r|^2, the residual r' = r sqrt(rho') / (1 - alpha) and Jacobian
// J' = sqrt(rho') (I - alpha r r^T / s) J, alpha the root of 0.5 alpha^2 - alpha - rho'' s / rho' =
// 0 below 1, make 0.5 |r' + J' d|^2 the second-order model of 0.5 rho(|r + J d|^2).
struct Correction {
  double residual_scale = 1.0, sqrt_rho1 = 1.0, alpha_over_s = 0.0;
  Correction(double s, const double rho[3]) {
    sqrt_rho1 = std::sqrt(rho[1]);
    if (s == 0.0 || rho[2] <= 0.0) {
      residual_scale = sqrt_rho1;
      return;
    }
    const double d = 1.0 + 2.0 * s * rho[2] / rho[1];
    const double alpha = 1.0 - std::sqrt(d);
    residual_scale = sqrt_rho1 / (1.0 - alpha);
    alpha_over_s = alpha / s;
  }
  // J (rows x cols, row-major) with the uncorrected residual r.
  void Jacobian(const double* r, int rows, int cols, double* j) const {
    Eigen::Map<RowMatrix> m(j, rows, cols);
    if (alpha_over_s == 0.0) {
      m *= sqrt_rho1;
      return;
    }
    const Eigen::Map<const Eigen::VectorXd> v(r, rows);
    const Eigen::RowVectorXd rt_j = v.transpose() * m;
    for (int a = 0; a < rows; ++a) m.row(a) = sqrt_rho1 * (m.row(a) - alpha_over_s * v(a) * rt_j);
  }
};

}  // namespace

ResidualEvaluator::ResidualEvaluator(std::vector<FreeBlock> blocks,
                                     std::vector<ResidualTerm> residuals,
                                     int threads)
    : blocks_(std::move(blocks)), residuals_(std::move(residuals)), threads_(std::max(1, threads)) {
  ambient_offset_ = {0};
  tangent_offset_ = {0};
  plus_offset_ = {0};
  for (const FreeBlock& b : blocks_) {
    ambient_offset_.push_back(ambient_offset_.back() + b.size);
    tangent_offset_.push_back(tangent_offset_.back() + b.tangent);
    plus_offset_.push_back(plus_offset_.back() + (b.manifold ? b.size * b.tangent : 0));
  }
  plus_.assign(plus_offset_.back(), 0.0);
  r_offset_ = {0};
  slot_start_ = {0};
  long long j_size = 0;
  std::vector<double> cost(residuals_.size());
  for (size_t i = 0; i < residuals_.size(); ++i) {
    const ResidualTerm& t = residuals_[i];
    const int rows = t.cost->num_residuals();
    r_offset_.push_back(r_offset_.back() + rows);
    slot_start_.push_back(slot_start_.back() + static_cast<long long>(t.free.size()));
    cost[i] = 1.0;
    for (int b : t.free) {
      j_offset_.push_back(b < 0 ? -1 : j_size);
      if (b >= 0) {
        j_size += static_cast<long long>(rows) * blocks_[b].tangent;
        cost[i] += rows * blocks_[b].size;
      }
    }
  }
  r_.assign(r_offset_.back(), 0.0);
  r_trial_.assign(r_offset_.back(), 0.0);
  j_.assign(j_size, 0.0);
  costs_.assign(residuals_.size(), 0.0);
  bounds_ = BalancedBounds(cost, threads_);
}

std::vector<double> ResidualEvaluator::Gather() const {
  std::vector<double> x(ambient_offset_.back());
  for (size_t b = 0; b < blocks_.size(); ++b)
    std::copy(
        blocks_[b].values, blocks_[b].values + blocks_[b].size, x.data() + ambient_offset_[b]);
  return x;
}

void ResidualEvaluator::Scatter(const std::vector<double>& x) const {
  for (size_t b = 0; b < blocks_.size(); ++b)
    std::copy(x.data() + ambient_offset_[b], x.data() + ambient_offset_[b + 1], blocks_[b].values);
}

bool ResidualEvaluator::Plus(const std::vector<double>& x,
                             const double* delta,
                             std::vector<double>* x_plus) const {
  x_plus->resize(x.size());
  for (size_t b = 0; b < blocks_.size(); ++b) {
    const double* xb = x.data() + ambient_offset_[b];
    const double* db = delta + tangent_offset_[b];
    double* out = x_plus->data() + ambient_offset_[b];
    if (blocks_[b].manifold == nullptr) {
      for (int k = 0; k < blocks_[b].size; ++k) out[k] = xb[k] + db[k];
    } else if (!blocks_[b].manifold->Plus(xb, db, out)) {
      return false;
    }
  }
  return true;
}

bool ResidualEvaluator::Evaluate(const std::vector<double>& x, bool jacobians, double* cost) {
  std::atomic<bool> ok{true};
  if (jacobians)  // the manifolds' Jacobians at x, one block per thread of a fixed split
    ParallelRanges(EvenBounds(num_blocks(), threads_), [&](int begin, int end, int) {
      for (int b = begin; b < end; ++b)
        if (blocks_[b].manifold != nullptr &&
            !blocks_[b].manifold->PlusJacobian(x.data() + ambient_offset_[b],
                                               plus_.data() + plus_offset_[b]))
          ok = false;
    });
  if (!ok) return false;
  double* r = jacobians ? r_.data() : r_trial_.data();
  ParallelRanges(bounds_, [&](int begin, int end, int) {
    if (!EvaluateRange(x, jacobians, begin, end, r)) ok = false;
  });
  if (!ok) return false;
  double sum = 0.0;  // in residual order, whatever the threads
  for (double c : costs_) sum += c;
  *cost = sum;
  return std::isfinite(sum);
}

ceres::CRSMatrix ResidualEvaluator::TangentJacobian() const {
  ceres::CRSMatrix crs;
  crs.num_rows = static_cast<int>(r_offset_.back());
  crs.num_cols = num_tangent();
  crs.rows.reserve(crs.num_rows + 1);
  crs.rows.push_back(0);
  for (int i = 0; i < num_residuals(); ++i) {
    const ResidualTerm& t = residuals_[i];
    for (int row = 0; row < residual_size(i); ++row) {
      for (size_t k = 0; k < t.free.size(); ++k) {
        if (t.free[k] < 0) continue;
        const int tangent = blocks_[t.free[k]].tangent;
        const double* j = jacobian(i, static_cast<int>(k)) + row * tangent;
        for (int c = 0; c < tangent; ++c) {
          crs.cols.push_back(tangent_offset_[t.free[k]] + c);
          crs.values.push_back(j[c]);
        }
      }
      crs.rows.push_back(static_cast<int>(crs.cols.size()));
    }
  }
  return crs;
}

bool ResidualEvaluator::EvaluateRange(
    const std::vector<double>& x, bool jacobians, int begin, int end, double* r_all) {
  std::vector<const double*> params;
  std::vector<double*> jac_ptrs;
  std::vector<std::vector<double>> ambient;
  for (int i = begin; i < end; ++i) {
    const ResidualTerm& t = residuals_[i];
    const int rows = t.cost->num_residuals();
    const size_t n = t.free.size();
    params.resize(n);
    jac_ptrs.assign(n, nullptr);
    if (ambient.size() < n) ambient.resize(n);
    for (size_t k = 0; k < n; ++k) {
      const int b = t.free[k];
      params[k] = b < 0 ? t.constant[k] : x.data() + ambient_offset_[b];
      if (jacobians && b >= 0) {
        ambient[k].resize(static_cast<size_t>(rows) * blocks_[b].size);
        jac_ptrs[k] = ambient[k].data();
      }
    }
    double* r = r_all + r_offset_[i];
    if (!t.cost->Evaluate(params.data(), r, jacobians ? jac_ptrs.data() : nullptr)) return false;
    const double s = Eigen::Map<const Eigen::VectorXd>(r, rows).squaredNorm();
    double rho[3] = {s, 1.0, 0.0};
    if (t.loss != nullptr) t.loss->Evaluate(s, rho);
    costs_[i] = 0.5 * rho[0];
    const Correction correction(s, rho);
    for (size_t k = 0; jacobians && k < n; ++k) {
      const int b = t.free[k];
      if (b < 0) continue;
      double* out = j_.data() + j_offset_[slot_start_[i] + k];
      const FreeBlock& fb = blocks_[b];
      if (fb.manifold == nullptr)
        std::copy_n(ambient[k].data(), rows * fb.size, out);
      else
        MultiplyInto(
            ambient[k].data(), plus_.data() + plus_offset_[b], rows, fb.size, fb.tangent, out);
      if (t.loss != nullptr) correction.Jacobian(r, rows, fb.tangent, out);
    }
    if (t.loss != nullptr)
      for (int a = 0; a < rows; ++a) r[a] *= correction.residual_scale;
  }
  return true;
}

}  // namespace aerocal::calib::internal
