// Residuals and Jacobians of a problem's residual blocks, evaluated by aerocal rather than by
// ceres::Solve: the deterministic solver's evaluation (levenberg_marquardt.h). Internal to
// calib/problem.
//
// The same Ceres cost functions, loss functions and manifolds as the problem built; every residual
// block is evaluated by one thread of a fixed partition into its own storage, and the cost is
// summed afterwards in residual order: the values do not depend on the number of threads. Jacobians
// are kept in the tangent space of each free block (ambient Jacobian x the manifold's
// PlusJacobian), with Triggs' correction for a robust loss (as Ceres' Corrector: the loss-free
// Gauss-Newton model of rho(|r|^2)).
#pragma once

#include <ceres/cost_function.h>
#include <ceres/crs_matrix.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>

#include <vector>

namespace aerocal::calib::internal {

/// A free parameter block: `size` ambient doubles at `values`, `tangent` entries in the solver.
struct FreeBlock {
  double* values = nullptr;
  int size = 0, tangent = 0;
  const ceres::Manifold* manifold = nullptr;  // nullptr: the identity
  bool eliminable = false;                    // a point block (Schur elimination)
};

/// A residual block: per parameter of the cost function, its free block (index) or -1 and the
/// constant values.
struct ResidualTerm {
  const ceres::CostFunction* cost = nullptr;
  const ceres::LossFunction* loss = nullptr;
  std::vector<int> free;
  std::vector<const double*> constant;
};

class ResidualEvaluator {
 public:
  ResidualEvaluator(std::vector<FreeBlock> blocks,
                    std::vector<ResidualTerm> residuals,
                    int threads);

  /// The free blocks' ambient values, block after block (the state x).
  std::vector<double> Gather() const;
  void Scatter(const std::vector<double>& x) const;
  /// x_plus = Plus(x, delta) block by block (delta in the tangent, block after block).
  bool Plus(const std::vector<double>& x, const double* delta, std::vector<double>* x_plus) const;

  /// Cost 0.5 sum rho(|r_i|^2) at x; with `jacobians`, the corrected residuals and tangent
  /// Jacobians at x are kept (residual(), jacobian()). False when a cost function fails.
  bool Evaluate(const std::vector<double>& x, bool jacobians, double* cost);

  int num_blocks() const { return static_cast<int>(blocks_.size()); }
  int num_residuals() const { return static_cast<int>(residuals_.size()); }
  const FreeBlock& block(int b) const { return blocks_[b]; }
  const ResidualTerm& term(int i) const { return residuals_[i]; }
  int tangent_offset(int b) const { return tangent_offset_[b]; }
  int num_tangent() const { return tangent_offset_.back(); }
  // From the offsets (one array read in order) rather than the cost function (a heap object per
  // residual: a cache miss per call in the reduced system's loops over all residuals).
  int residual_size(int i) const { return static_cast<int>(r_offset_[i + 1] - r_offset_[i]); }
  /// Corrected residual i and its tangent Jacobian on parameter k (rows x tangent, row-major) of
  /// the last Evaluate with jacobians; nullptr for a constant parameter.
  const double* residual(int i) const { return r_.data() + r_offset_[i]; }
  const double* jacobian(int i, int k) const {
    const long long at = j_offset_[slot_start_[i] + k];
    return at < 0 ? nullptr : j_.data() + at;
  }
  int threads() const { return threads_; }
  /// The last Evaluate's tangent Jacobian as Ceres' Problem::Evaluate writes it (rows: the
  /// residuals in order; columns: the free blocks' tangents in order, each row's entries block by
  /// block in parameter order).
  ceres::CRSMatrix TangentJacobian() const;

 private:
  /// Residuals [begin, end) at x: cost per residual into costs_, residuals into `r`, and the
  /// tangent Jacobians with `jacobians`. False when one fails.
  bool EvaluateRange(const std::vector<double>& x, bool jacobians, int begin, int end, double* r);

  std::vector<FreeBlock> blocks_;
  std::vector<ResidualTerm> residuals_;
  int threads_ = 1;
  std::vector<int> ambient_offset_, tangent_offset_;
  std::vector<long long> r_offset_, slot_start_, j_offset_;
  std::vector<long long> plus_offset_;  // per block, into plus_
  std::vector<double> r_, r_trial_, j_, plus_, costs_;
  std::vector<int> bounds_;  // the fixed partition of the residuals
};

}  // namespace aerocal::calib::internal
