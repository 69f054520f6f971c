#include "calib/problem/normal_equations.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace aerocal::calib::internal {

namespace {

// Pseudo-inverse of a symmetric positive semi-definite matrix: eigenvalues below 1e-12 of the
// largest count as zero (the datum defect / an undetermined point direction).
Eigen::MatrixXd PseudoInverse(const Eigen::MatrixXd& m, bool* singular) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m);
  const double max_eig = eig.eigenvalues().size() ? eig.eigenvalues().cwiseAbs().maxCoeff() : 0.0;
  Eigen::VectorXd inv = eig.eigenvalues();
  bool any_zero = false;
  for (int i = 0; i < inv.size(); ++i) {
    const bool positive = inv(i) > 1e-12 * max_eig && max_eig > 0;
    any_zero = any_zero || !positive;
    inv(i) = positive ? 1.0 / inv(i) : 0.0;
  }
  if (singular) *singular = any_zero;
  return eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
}

// Position of `col` in the increasing `cols`.
int LocalIndex(const std::vector<int>& cols, int col) {
  return static_cast<int>(std::lower_bound(cols.begin(), cols.end(), col) - cols.begin());
}

}  // namespace

SchurComplement::SchurComplement(ceres::CRSMatrix jacobian, const ColumnBlocks& blocks)
    : jacobian_(std::move(jacobian)), blocks_(blocks) {
  IndexRows();
  AssembleS();
}

SchurComplement::SchurComplement(ceres::CRSMatrix jacobian,
                                 const ColumnBlocks& blocks,
                                 Eigen::SparseMatrix<double> s_lower)
    : jacobian_(std::move(jacobian)), blocks_(blocks), s_lower_(std::move(s_lower)) {
  IndexRows();
}

void SchurComplement::IndexRows() {
  const int n_blocks = static_cast<int>(blocks_.size.size());
  for (int b = 0; b < n_blocks; ++b)
    for (int k = 0; k < blocks_.size[b]; ++k) {
      col_block_.push_back(b);
      col_local_.push_back(k);
    }
  const int n_rows = jacobian_.num_rows;
  row_point_.assign(n_rows, -1);
  for (int r = 0; r < n_rows && eliminated_; ++r)
    for (int k = jacobian_.rows[r]; k < jacobian_.rows[r + 1]; ++k) {
      const int b = col_block_[jacobian_.cols[k]];
      if (!blocks_.eliminable[b]) continue;
      if (row_point_[r] >= 0 && row_point_[r] != b) {
        eliminated_ = false;  // a row observing two points: no block-diagonal A
        break;
      }
      row_point_[r] = b;
    }
  if (!eliminated_) row_point_.assign(n_rows, -1);
  reduced_offset_.assign(n_blocks, -1);
  point_index_.assign(n_blocks, -1);
  for (int b = 0; b < n_blocks; ++b) {
    if (eliminated_ && blocks_.eliminable[b]) {
      point_index_[b] = static_cast<int>(point_block_.size());
      point_block_.push_back(b);
    } else {
      reduced_offset_[b] = n_reduced_;
      n_reduced_ += blocks_.size[b];
    }
  }
  // Rows grouped by point (counting sort, rows in increasing order within a point).
  point_row_start_.assign(point_block_.size() + 1, 0);
  for (int r = 0; r < n_rows; ++r)
    if (row_point_[r] >= 0) ++point_row_start_[point_index_[row_point_[r]] + 1];
  for (size_t p = 0; p < point_block_.size(); ++p) point_row_start_[p + 1] += point_row_start_[p];
  point_rows_.resize(point_row_start_.back());
  std::vector<int> fill(point_row_start_.begin(), point_row_start_.end() - 1);
  for (int r = 0; r < n_rows; ++r)
    if (row_point_[r] >= 0) point_rows_[fill[point_index_[row_point_[r]]]++] = r;
}

void SchurComplement::AssembleS() {
  const int n_blocks = static_cast<int>(blocks_.size.size());
  const int n_rows = jacobian_.num_rows;
  // S, accumulated per pair of reduced blocks (lower: block i >= block j), each a dense
  // size_i x size_j column-major cell in `values`.
  std::unordered_map<long long, size_t> cell;
  std::vector<double> values;
  std::vector<std::pair<int, int>> cell_blocks;
  auto add_dense = [&](const std::vector<int>& set, const Eigen::MatrixXd& m) {
    std::vector<int> start(set.size() + 1, 0);
    for (size_t k = 0; k < set.size(); ++k) start[k + 1] = start[k] + blocks_.size[set[k]];
    for (size_t j = 0; j < set.size(); ++j)
      for (size_t i = j; i < set.size(); ++i) {
        const int bi = set[i], bj = set[j];
        const long long key = static_cast<long long>(bi) * n_blocks + bj;
        auto [it, added] = cell.try_emplace(key, values.size());
        const int si = blocks_.size[bi], sj = blocks_.size[bj];
        if (added) {
          values.resize(values.size() + si * sj, 0.0);
          cell_blocks.emplace_back(bi, bj);
        }
        double* v = values.data() + it->second;
        for (int c = 0; c < sj; ++c)
          for (int r = 0; r < si; ++r) v[c * si + r] += m(start[i] + r, start[j] + c);
      }
  };
  std::vector<int> cols;
  std::vector<double> vals;
  for (int r = 0; r < n_rows; ++r) {
    if (row_point_[r] >= 0) continue;
    RowReduced(r, &cols, &vals);
    if (cols.empty()) continue;
    std::vector<int> set;
    for (int k = jacobian_.rows[r]; k < jacobian_.rows[r + 1]; ++k)
      set.push_back(col_block_[jacobian_.cols[k]]);
    std::sort(set.begin(), set.end());
    set.erase(std::unique(set.begin(), set.end()), set.end());
    const std::vector<int> set_cols = ReducedColumns(set);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(set_cols.size());
    for (size_t k = 0; k < cols.size(); ++k) f(LocalIndex(set_cols, cols[k])) = vals[k];
    add_dense(set, f * f.transpose());
  }
  for (int b : point_block_) {
    const PointTerms t = Point(b);
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(t.cols.size(), t.cols.size());
    const int p = point_index_[b];
    for (int k = point_row_start_[p]; k < point_row_start_[p + 1]; ++k) {
      RowReduced(point_rows_[k], &cols, &vals);
      Eigen::VectorXd f = Eigen::VectorXd::Zero(t.cols.size());
      for (size_t q = 0; q < cols.size(); ++q) f(LocalIndex(t.cols, cols[q])) = vals[q];
      m.selfadjointView<Eigen::Lower>().rankUpdate(f);
    }
    Eigen::MatrixXd full = m.selfadjointView<Eigen::Lower>();
    full.noalias() -= t.b.transpose() * t.a_pinv * t.b;
    if (!t.blocks.empty()) add_dense(t.blocks, full);
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(values.size());
  for (const auto& [bi, bj] : cell_blocks) {
    const double* v = values.data() + cell.at(static_cast<long long>(bi) * n_blocks + bj);
    const int si = blocks_.size[bi], sj = blocks_.size[bj];
    const int oi = reduced_offset_[bi], oj = reduced_offset_[bj];
    for (int c = 0; c < sj; ++c)
      for (int r = 0; r < si; ++r)
        if (bi != bj || r >= c) triplets.emplace_back(oi + r, oj + c, v[c * si + r]);
  }
  s_lower_.resize(n_reduced_, n_reduced_);
  s_lower_.setFromTriplets(triplets.begin(), triplets.end());
}

void SchurComplement::RowReduced(int row,
                                 std::vector<int>* cols,
                                 std::vector<double>* values) const {
  cols->clear();
  values->clear();
  for (int k = jacobian_.rows[row]; k < jacobian_.rows[row + 1]; ++k) {
    const int b = col_block_[jacobian_.cols[k]];
    if (reduced_offset_[b] < 0) continue;
    cols->push_back(reduced_offset_[b] + col_local_[jacobian_.cols[k]]);
    values->push_back(jacobian_.values[k]);
  }
  // Ceres writes a row's entries block by block in parameter order; sort to be independent of it.
  std::vector<int> order(cols->size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = static_cast<int>(i);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return (*cols)[a] < (*cols)[b]; });
  std::vector<int> c(cols->size());
  std::vector<double> v(cols->size());
  for (size_t i = 0; i < order.size(); ++i) {
    c[i] = (*cols)[order[i]];
    v[i] = (*values)[order[i]];
  }
  *cols = std::move(c);
  *values = std::move(v);
}

Eigen::VectorXd SchurComplement::RowPointPart(int row) const {
  const int b = row_point_[row];
  if (b < 0) return Eigen::VectorXd();
  Eigen::VectorXd a = Eigen::VectorXd::Zero(blocks_.size[b]);
  for (int k = jacobian_.rows[row]; k < jacobian_.rows[row + 1]; ++k)
    if (col_block_[jacobian_.cols[k]] == b) a(col_local_[jacobian_.cols[k]]) = jacobian_.values[k];
  return a;
}

std::vector<int> SchurComplement::ReducedColumns(std::vector<int> blocks) const {
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  std::vector<int> cols;
  for (int b : blocks)
    for (int k = 0; k < blocks_.size[b]; ++k) cols.push_back(reduced_offset_[b] + k);
  return cols;
}

SchurComplement::PointTerms SchurComplement::Point(int block) const {
  PointTerms t;
  const int p = point_index_[block];
  const int ne = blocks_.size[block];
  for (int k = point_row_start_[p]; k < point_row_start_[p + 1]; ++k) {
    const int row = point_rows_[k];
    for (int q = jacobian_.rows[row]; q < jacobian_.rows[row + 1]; ++q) {
      const int b = col_block_[jacobian_.cols[q]];
      if (reduced_offset_[b] >= 0) t.blocks.push_back(b);
    }
  }
  std::sort(t.blocks.begin(), t.blocks.end());
  t.blocks.erase(std::unique(t.blocks.begin(), t.blocks.end()), t.blocks.end());
  t.cols = ReducedColumns(t.blocks);
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(ne, ne);
  t.b = Eigen::MatrixXd::Zero(ne, t.cols.size());
  std::vector<int> cols;
  std::vector<double> vals;
  for (int k = point_row_start_[p]; k < point_row_start_[p + 1]; ++k) {
    const int row = point_rows_[k];
    const Eigen::VectorXd ar = RowPointPart(row);
    a.noalias() += ar * ar.transpose();
    RowReduced(row, &cols, &vals);
    for (size_t q = 0; q < cols.size(); ++q) t.b.col(LocalIndex(t.cols, cols[q])) += ar * vals[q];
  }
  t.a_pinv = PseudoInverse(a, &t.singular);
  return t;
}

bool SelectedInverse::Compute(const Eigen::SparseMatrix<double>& s_lower,
                              int dense_limit,
                              int max_dense) {
  n_ = static_cast<int>(s_lower.rows());
  ok_ = true;
  if (n_ == 0) return true;
  auto dense_path = [&] {
    Eigen::MatrixXd s = Eigen::MatrixXd(s_lower);
    s = s.selfadjointView<Eigen::Lower>();
    bool singular = false;
    z_dense_ = PseudoInverse(s, &singular);
    singular_ = singular_ || singular;
    dense_ = true;
    ldlt_.reset();
    return true;
  };
  if (n_ <= dense_limit) return dense_path();
  ldlt_ = std::make_unique<Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower>>();
  ldlt_->compute(s_lower);
  const Eigen::VectorXd d = ldlt_->vectorD();
  perm_.assign(ldlt_->permutationP().indices().data(), ldlt_->permutationP().indices().data() + n_);
  // A pivot that lost all but 1e-12 of its diagonal is a (numerical) rank defect.
  Eigen::VectorXd diagonal = Eigen::VectorXd::Zero(n_);
  for (int j = 0; j < n_; ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(s_lower, j); it; ++it)
      if (it.row() == j) diagonal(perm_[j]) = it.value();
  bool singular = ldlt_->info() != Eigen::Success;
  for (int k = 0; k < n_ && !singular; ++k)
    singular = !(d(k) > 1e-12 * diagonal(k)) || !std::isfinite(d(k));
  if (singular) {
    singular_ = true;
    if (n_ <= max_dense) return dense_path();
    ok_ = false;
    ldlt_.reset();
    message_ = "the reduced normal matrix (" + std::to_string(n_) +
               " parameters) is singular: the problem has a datum defect or undetermined "
               "parameters, and its generalised inverse is computed densely only up to " +
               std::to_string(max_dense) + " parameters";
    return false;
  }
  // Takahashi: Z = L^-T D^-1 L^-1 on the pattern of L, columns right to left:
  //   Z_ij = -sum_{k in S_j} Z_ik L_kj (i in S_j),  Z_jj = 1 / D_j - sum_{k in S_j} Z_kj L_kj.
  const Eigen::SparseMatrix<double>& l = ldlt_->matrixL().nestedExpression();
  const int* lp = l.outerIndexPtr();
  const int* li = l.innerIndexPtr();
  const double* lx = l.valuePtr();
  factor_nonzeros_ = lp[n_];
  zx_.assign(lp[n_], 0.0);
  zd_.assign(n_, 0.0);
  std::vector<int> pos(n_, -1);
  std::vector<double> y;
  for (int j = n_ - 1; j >= 0; --j) {
    const int p0 = lp[j], m = lp[j + 1] - p0;
    for (int q = 0; q < m; ++q) pos[li[p0 + q]] = q;
    y.assign(m, 0.0);
    for (int q = 0; q < m; ++q) {
      const int k = li[p0 + q];
      const double lk = lx[p0 + q];
      double yq = zd_[k] * lk;
      for (int s = lp[k]; s < lp[k + 1]; ++s) {
        const int qi = pos[li[s]];
        if (qi < 0) continue;
        y[qi] += zx_[s] * lk;
        yq += zx_[s] * lx[p0 + qi];
      }
      y[q] += yq;
    }
    double zjj = 1.0 / d(j);
    for (int q = 0; q < m; ++q) {
      zx_[p0 + q] = -y[q];
      zjj += y[q] * lx[p0 + q];
    }
    zd_[j] = zjj;
    for (int q = 0; q < m; ++q) pos[li[p0 + q]] = -1;
  }
  return true;
}

long long SelectedInverse::Find(int i, int j) const {
  const Eigen::SparseMatrix<double>& l = ldlt_->matrixL().nestedExpression();
  const int* li = l.innerIndexPtr();
  const int* begin = li + l.outerIndexPtr()[j];
  const int* end = li + l.outerIndexPtr()[j + 1];
  const int* it = std::lower_bound(begin, end, i);
  return it != end && *it == i ? it - li : -1;
}

Eigen::VectorXd SelectedInverse::SolveColumn(int col) const {
  Eigen::VectorXd e = Eigen::VectorXd::Zero(n_);
  e(col) = 1.0;
  return ldlt_->solve(e);
}

Eigen::MatrixXd SelectedInverse::Gather(const std::vector<int>& rows,
                                        const std::vector<int>& cols) const {
  Eigen::MatrixXd out(rows.size(), cols.size());
  if (dense_) {
    for (size_t c = 0; c < cols.size(); ++c)
      for (size_t r = 0; r < rows.size(); ++r) out(r, c) = z_dense_(rows[r], cols[c]);
    return out;
  }
  for (size_t c = 0; c < cols.size(); ++c) {
    const int pc = perm_[cols[c]];
    bool complete = true;
    for (size_t r = 0; r < rows.size() && complete; ++r) {
      const int pr = perm_[rows[r]];
      if (pr == pc) {
        out(r, c) = zd_[pr];
        continue;
      }
      const long long at = pr > pc ? Find(pr, pc) : Find(pc, pr);
      if (at < 0)
        complete = false;
      else
        out(r, c) = zx_[at];
    }
    if (complete) continue;
    const Eigen::VectorXd column = SolveColumn(cols[c]);  // outside the pattern of L
    for (size_t r = 0; r < rows.size(); ++r) out(r, c) = column(rows[r]);
  }
  return out;
}

}  // namespace aerocal::calib::internal
