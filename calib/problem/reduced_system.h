// The damped normal equations of the deterministic solver (levenberg_marquardt.h) with the point
// blocks eliminated: the reduced camera system, assembled in parallel with a fixed summation order,
// factorised by Cholesky (dense LLT, or CHOLMOD's supernodal LLT when sparse), and the points
// back-substituted. Internal to calib/problem.
//
// With the tangent Jacobian J = [E F] (E: point columns, F: the others), g = J^T r and the
// Levenberg-Marquardt damping D^2 = diag(J^T J) / radius (diag clamped to [1e-6, 1e32], as Ceres):
//   V_e = E_e^T E_e + D_e^2 per point e,  W_e = E_e^T F,  U = F^T F + D_F^2,
//   S = U - sum_e W_e^T V_e^-1 W_e,   S dx_F = -g_F + sum_e W_e^T V_e^-1 g_e,
//   dx_e = -V_e^-1 (g_e + W_e dx_F).
// Determinism: the per-point terms are computed independently (any thread); S is stored by block
// rows of reduced blocks, and each block row is assembled by ONE thread (rows split by cost), its
// cells summed in a fixed order (the residuals by index, then the points by index). So S, its
// factor and the step are the same bits for every thread count.
#pragma once

#include "calib/problem/residual_evaluator.h"

#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <memory>
#include <vector>

namespace aerocal::calib::internal {

class ReducedSystem {
 public:
  /// nullptr when a residual sees two point blocks (no block-diagonal elimination) or there are no
  /// points or no reduced blocks. Up to `max_dense` reduced parameters the factorisation is dense.
  static std::unique_ptr<ReducedSystem> Create(const ResidualEvaluator& evaluator, int max_dense);
  ~ReducedSystem();

  /// The terms that do not depend on the damping, from the evaluator's current Jacobian.
  void Linearize(const ResidualEvaluator& evaluator);
  /// The step dx (tangent, evaluator's block order) for the damping 1 / radius; false when the
  /// factorisation fails.
  bool Solve(const ResidualEvaluator& evaluator, double radius, Eigen::VectorXd* dx);

  /// S at zero damping with the points' pseudo-inverses A_e^+ (the S of normal_equations.h for
  /// the same Jacobian), lower triangle, from the last Linearize: the statistics' reduced matrix at
  /// the solution without a second reduction. False when a point block is not finite. Overwrites
  /// the step's work arrays and hands the sparse pattern over: once, after the last Solve.
  bool UndampedLower(const ResidualEvaluator& evaluator, Eigen::SparseMatrix<double>* s_lower);

  /// Frees the factor of the last Solve (no Solve after this; UndampedLower still works).
  void ReleaseFactor();

  const Eigen::VectorXd& gradient() const { return g_; }  // J^T r (tangent)
  /// The damping D^2 of the last Solve (tangent).
  const Eigen::VectorXd& damping() const { return d2_; }
  bool dense() const { return dense_; }
  int num_reduced() const { return n_reduced_; }

 private:
  ReducedSystem() = default;
  void BuildStructure(const ResidualEvaluator& ev);
  /// Index (into row_cols_ / cell_offset_) of the cell (row, col_block), col_block <= row.
  int CellIndex(int row, int col_block) const;
  /// Scalar size of reduced block j.
  int BlockSize(int j) const { return reduced_offset_[j + 1] - reduced_offset_[j]; }
  /// The cells of the products below (pair_cell_, u_cell_) and the assembly's pieces of work.
  void IndexCells(const ResidualEvaluator& ev);
  /// A piece of a block row of S: the cells [cell_begin, cell_end) (indices into row_cols_), all
  /// summed by one thread; the row's last piece owns the diagonal cell's damping and the row's
  /// right-hand side. Every cell is summed in the same order whatever the pieces: the pieces only
  /// decide which thread sums it.
  struct RowPart {
    int row, cell_begin, cell_end;
  };
  /// Cuts the rows into pieces of at most 1 / (2 threads) of the total cost (the interior's row
  /// alone receives a product from every point: about half of the work) and the pieces into one
  /// contiguous range per thread.
  void PartitionRows(const std::vector<double>& cell_cost, const std::vector<double>& row_cost);
  /// Per entry of point_res_: the point's slot in the residual and, per reduced parameter of the
  /// residual, its slot and its point entry (index into point_blk_): Linearize reads these in order
  /// instead of the residual terms scattered over the heap.
  void IndexPointTerms(const ResidualEvaluator& ev);
  /// V_e, g_e and W_e += the terms of residual point_res_[k] (kRows x kT fixed at compile time,
  /// 0: the runtime sizes).
  template <int kRows, int kT>
  void AddPointResidual(const ResidualEvaluator& ev, int k, int t, double* v, double* g);
  void AssembleRow(const ResidualEvaluator& ev, const RowPart& part);
  /// AssembleRow with the row's block size kSi fixed at compile time (3, 10; 0: BlockSize(row)).
  template <int kSi>
  void AssembleRowSized(const ResidualEvaluator& ev, const RowPart& part);
  /// sign W_e^T Q_a into the cells of a point's pairs (a0..entry) that lie in [c0, c1), with the
  /// point's tangent kT and the row's size kSi fixed at compile time (0: t, si).
  template <int kT, int kSi>
  void AddPointPairs(const double* wi,
                     const int* cells,
                     int a0,
                     int entry,
                     int t,
                     int si,
                     int c0,
                     int c1,
                     double sign);
  /// V_e^-1 (damped by d2_; pseudo-inverse with `pseudo`), Q_e, V_e^-1 g_e per point, then every
  /// row of S and the right-hand side. False when a point block is not finite.
  bool Reduce(const ResidualEvaluator& ev, bool pseudo);
  bool Factorize(Eigen::VectorXd* rhs);

  struct Sparse;  // CHOLMOD
  int threads_ = 1;
  bool dense_ = true;
  int n_reduced_ = 0;
  std::vector<int> point_of_block_, reduced_of_block_;  // per free block: index or -1
  std::vector<int> points_, reduced_;                   // free block of each point / reduced block
  std::vector<int> reduced_offset_;                     // scalar offset in S per reduced block
  std::vector<int> residual_point_;                     // per residual: point index or -1
  // per point: its residuals, its reduced blocks (sorted) and where W_e / Q_e of each start
  std::vector<int> point_res_start_, point_res_;
  std::vector<int> point_blk_start_, point_blk_;
  std::vector<long long> point_w_;  // per entry of point_blk_: offset in w_ / q_
  std::vector<int> entry_point_;    // per entry of point_blk_: its point
  // per reduced block: the residuals touching it (slot of the block in the residual), the points
  std::vector<int> red_res_start_, red_res_, red_res_slot_;
  std::vector<int> red_pt_start_, red_pt_entry_;  // entry: index into point_blk_
  // S by block rows: column blocks (sorted, <= row) and their cells (row-major s_i x s_j)
  std::vector<int> row_start_, row_cols_;
  std::vector<long long> cell_offset_;
  // The cells AssembleRow adds into, looked up once (IndexCells): per point entry, the cells of
  // its pairs with the point's blocks up to it; per entry of red_res_, the cell of each parameter
  // of the residual (-1: a point, constant, or a column block above the row).
  std::vector<int> point_res_slot_, point_res_w_slot_, point_res_w_entry_;
  std::vector<long long> point_res_w_start_;
  std::vector<long long> pair_cell_start_, u_cell_start_;
  std::vector<int> pair_cell_, u_cell_;
  std::vector<double> s_;
  std::vector<int> row_bounds_, point_bounds_;
  std::vector<RowPart> row_parts_;
  std::vector<int> part_bounds_;  // per thread, a range of row_parts_
  // per point: V (undamped), V^-1 (damped), g_e; W, Q = V^-1 W
  std::vector<long long> v_offset_;
  std::vector<double> v_, vinv_, w_, q_, qg_;
  Eigen::VectorXd g_, diag_, d2_, rhs_;
  Eigen::MatrixXd dense_s_;
  std::unique_ptr<Sparse> sparse_;
};

}  // namespace aerocal::calib::internal
