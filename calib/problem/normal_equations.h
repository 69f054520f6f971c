// Sparse normal equations of a whitened least-squares problem with the point blocks eliminated
// (Schur complement), and the entries of the inverse of the reduced matrix on its sparsity pattern
// (selected inversion). Internal to calib/problem: ProblemBuilder uses it for redundancy numbers,
// observation cofactors and covariance; see calib/README.md ("Observation cofactors and
// covariance") for the method.
//
// With N = J^T J = [A B; B^T C] (A block-diagonal over the point blocks e, C over the other,
// "reduced" parameters) and S = C - sum_e B_e^T A_e^+ B_e:
//   N^- = [A^+ + A^+ B S^- B^T A^+, -A^+ B S^-; -S^- B^T A^+, S^-],
// a generalised inverse whenever range(B_e) lies in range(A_e) (always: both are spanned by the
// point parts of the rows of e). Every quantity the builder needs touches S^- only on pairs of
// reduced blocks that share a point or a row, i.e. on the pattern of S, which is contained in the
// pattern of the factor L of S: the selected inverse is exact there.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <ceres/crs_matrix.h>

#include <memory>
#include <string>
#include <vector>

namespace aerocal::calib::internal {

/// Parameter blocks in Jacobian column order (tangent space).
struct ColumnBlocks {
  std::vector<int> size;         // tangent size per block
  std::vector<bool> eliminable;  // a point block, eliminated by the Schur complement
};

/// Reduced normal equations S of a Jacobian. A row observing two point blocks makes the problem
/// ineligible for elimination: then every block is treated as reduced (S = N).
class SchurComplement {
 public:
  SchurComplement(ceres::CRSMatrix jacobian, const ColumnBlocks& blocks);
  /// The same with S given (the solver's reduced system at the solution, ReducedSystem::
  /// UndampedLower): only the row bookkeeping is built. The caller guarantees that `s_lower` is
  /// S of this Jacobian (eliminated as above; a row observing two points is not eliminable there).
  SchurComplement(ceres::CRSMatrix jacobian,
                  const ColumnBlocks& blocks,
                  Eigen::SparseMatrix<double> s_lower);

  /// Terms of one point block: the reduced blocks its rows touch, their scalar reduced columns
  /// (`cols`, in increasing order), A^+ (pseudo-inverse of the point's normal block) and B_e
  /// (point tangent x cols).
  struct PointTerms {
    std::vector<int> blocks;
    std::vector<int> cols;
    Eigen::MatrixXd a_pinv, b;
    bool singular = false;  // A_e rank deficient (a point with too few rays)
  };
  PointTerms Point(int block) const;

  int num_reduced() const { return n_reduced_; }
  bool eliminated() const { return eliminated_; }
  int reduced_offset(int block) const { return reduced_offset_[block]; }
  bool is_point(int block) const { return point_index_[block] >= 0; }
  /// Lower triangle of S (reduced scalar indexing).
  const Eigen::SparseMatrix<double>& s_lower() const { return s_lower_; }
  const ceres::CRSMatrix& jacobian() const { return jacobian_; }
  /// The point block a row observes, -1 for none.
  int RowPoint(int row) const { return row_point_[row]; }
  /// The reduced scalar columns of a row (increasing) and the row's values there.
  void RowReduced(int row, std::vector<int>* cols, std::vector<double>* values) const;
  /// The row's point part (tangent of its point), zero when it has none.
  Eigen::VectorXd RowPointPart(int row) const;
  /// Reduced columns of the listed blocks (increasing).
  std::vector<int> ReducedColumns(std::vector<int> blocks) const;

 private:
  void IndexRows();  // rows per point, reduced offsets
  void AssembleS();  // s_lower_ from the Jacobian
  ceres::CRSMatrix jacobian_;
  ColumnBlocks blocks_;
  bool eliminated_ = true;
  int n_reduced_ = 0;
  std::vector<int> col_block_, col_local_;
  std::vector<int> reduced_offset_;                // per block, -1 for a point
  std::vector<int> point_index_;                   // per block, -1 for a reduced block
  std::vector<int> row_point_;                     // per row
  std::vector<int> point_row_start_, point_rows_;  // rows of each point (CSR by point index)
  std::vector<int> point_block_;                   // block of each point index
  Eigen::SparseMatrix<double> s_lower_;
};

/// Entries of S^-1 (or S^+) for a symmetric positive semi-definite S.
/// Sparse path: LDL^T with an AMD ordering, then the Takahashi recurrences
///   Z = D^-1 L^-1 + (I - L^T) Z   evaluated only on the pattern of L,
/// which contains the pattern of S. Entries outside it come from solves with the factor.
/// Dense path (n <= dense_limit, or S singular and n <= max_dense): pseudo-inverse by an
/// eigen-decomposition (the minimum-norm generalised inverse on a rank defect).
class SelectedInverse {
 public:
  /// `s_lower`: lower triangle. Returns ok(); a singular S above max_dense is not ok.
  bool Compute(const Eigen::SparseMatrix<double>& s_lower, int dense_limit, int max_dense);
  bool ok() const { return ok_; }
  bool dense() const { return dense_; }
  bool singular() const { return singular_; }
  const std::string& message() const { return message_; }
  long long factor_nonzeros() const { return factor_nonzeros_; }
  int size() const { return n_; }
  /// S^-1(rows, cols).
  Eigen::MatrixXd Gather(const std::vector<int>& rows, const std::vector<int>& cols) const;

 private:
  /// Position of Z(i, j) (permuted indices, i > j) in zx_, -1 outside the pattern.
  long long Find(int i, int j) const;
  Eigen::VectorXd SolveColumn(int col) const;

  bool ok_ = false, dense_ = false, singular_ = false;
  std::string message_;
  int n_ = 0;
  long long factor_nonzeros_ = 0;
  Eigen::MatrixXd z_dense_;
  std::unique_ptr<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>> ldlt_;
  std::vector<int> perm_;  // new index of each original index
  std::vector<double> zx_, zd_;
};

}  // namespace aerocal::calib::internal
