#include "calib/problem/reduced_system.h"

#include "calib/problem/block_kernels.h"
#include "calib/problem/parallel_for.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <cmath>

namespace aerocal::calib::internal {

namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using ConstMap = Eigen::Map<const RowMatrix>;
using Map = Eigen::Map<RowMatrix>;

constexpr double kMinDiagonal = 1e-6, kMaxDiagonal = 1e32;  // Ceres' LM defaults
// The cost of one small product in multiply-adds beyond its own (the call, the size dispatch, the
// cell's address). With the multiply-adds alone the exposures' 3 x 3 products were undercounted
// against the interior's 10-wide ones: a perf profile of two threads put 61 % of the assembly's
// samples on one thread; with this weight 54 % (docs/measurements/triangulation.md).
constexpr double kProductOverhead = 30.0;

// Slot of free block `b` among the parameters of residual term `t`.
int SlotOf(const ResidualTerm& t, int b) {
  return static_cast<int>(std::find(t.free.begin(), t.free.end(), b) - t.free.begin());
}

// CSR-like grouping: items of each of n groups, in increasing item order.
void Group(int n,
           const std::vector<std::pair<int, int>>& group_item,
           std::vector<int>* start,
           std::vector<int>* items) {
  start->assign(n + 1, 0);
  for (const auto& [g, i] : group_item) ++(*start)[g + 1];
  for (int g = 0; g < n; ++g) (*start)[g + 1] += (*start)[g];
  items->resize(group_item.size());
  std::vector<int> fill(start->begin(), start->end() - 1);
  for (const auto& [g, i] : group_item) (*items)[fill[g]++] = i;
}

// (V + diag(d2))^-1 of a point (t x t, row-major), symmetrised; the pseudo-inverse (eigenvalues
// below 1e-12 of the largest dropped, as Ceres and normal_equations.h) for a point its rays do not
// determine (one ray), or always with `pseudo` (the statistics' A_e^+). kSize: t at compile time
// (3, the ground points) or Eigen::Dynamic. False when not finite.
template <int kSize>
bool InvertDamped(const double* v_undamped, const double* d2, int t, bool pseudo, double* out) {
  using Matrix = Eigen::Matrix<double, kSize, kSize, Eigen::RowMajor>;
  Matrix v = Eigen::Map<const Matrix>(v_undamped, t, t);
  for (int k = 0; k < t; ++k) v(k, k) += d2[k];
  Eigen::Map<Matrix> vinv(out, t, t);
  const Eigen::LLT<Matrix> llt(v);
  if (!pseudo && llt.info() == Eigen::Success) {
    vinv = llt.solve(Matrix::Identity(t, t));
  } else {
    const Eigen::SelfAdjointEigenSolver<Matrix> eig(v);
    const double max = eig.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::Matrix<double, kSize, 1> inverse = eig.eigenvalues();
    for (int k = 0; k < t; ++k)
      inverse(k) = inverse(k) > 1e-12 * max && max > 0 ? 1.0 / inverse(k) : 0.0;
    vinv = eig.eigenvectors() * inverse.asDiagonal() * eig.eigenvectors().transpose();
  }
  const Matrix symmetric = 0.5 * (vinv + vinv.transpose());
  vinv = symmetric;
  return vinv.allFinite();
}

}  // namespace

struct ReducedSystem::Sparse {
  Eigen::SparseMatrix<double> s;  // lower triangle, the pattern fixed at Create
  std::vector<long long> source;  // per stored value: its index in s_
  // The factor, freed by ReleaseFactor (the pattern s stays for UndampedLower).
  std::unique_ptr<Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>> llt;
};

ReducedSystem::~ReducedSystem() = default;

std::unique_ptr<ReducedSystem> ReducedSystem::Create(const ResidualEvaluator& ev, int max_dense) {
  std::unique_ptr<ReducedSystem> sys(new ReducedSystem());
  ReducedSystem& s = *sys;
  s.threads_ = ev.threads();
  const int n_blocks = ev.num_blocks();
  s.point_of_block_.assign(n_blocks, -1);
  s.reduced_of_block_.assign(n_blocks, -1);
  s.reduced_offset_ = {0};
  for (int b = 0; b < n_blocks; ++b) {
    if (ev.block(b).eliminable) {
      s.point_of_block_[b] = static_cast<int>(s.points_.size());
      s.points_.push_back(b);
    } else {
      s.reduced_of_block_[b] = static_cast<int>(s.reduced_.size());
      s.reduced_.push_back(b);
      s.reduced_offset_.push_back(s.reduced_offset_.back() + ev.block(b).tangent);
    }
  }
  s.n_reduced_ = s.reduced_offset_.back();
  if (s.points_.empty() || s.reduced_.empty()) return nullptr;
  s.residual_point_.assign(ev.num_residuals(), -1);
  for (int i = 0; i < ev.num_residuals(); ++i)
    for (int b : ev.term(i).free) {
      if (b < 0 || s.point_of_block_[b] < 0) continue;
      if (s.residual_point_[i] >= 0) return nullptr;  // two points in one residual
      s.residual_point_[i] = s.point_of_block_[b];
    }
  s.BuildStructure(ev);
  s.IndexPointTerms(ev);
  s.dense_ = s.n_reduced_ <= max_dense;
  if (s.dense_) {
    s.dense_s_.setZero(s.n_reduced_, s.n_reduced_);  // cells outside the pattern stay 0
  } else {
    s.sparse_ = std::make_unique<Sparse>();
    std::vector<Eigen::Triplet<double>> triplets;
    const int n_red = static_cast<int>(s.reduced_.size());
    for (int i = 0; i < n_red; ++i)
      for (int c = s.row_start_[i]; c < s.row_start_[i + 1]; ++c) {
        const int j = s.row_cols_[c];
        const int si = ev.block(s.reduced_[i]).tangent, sj = ev.block(s.reduced_[j]).tangent;
        for (int a = 0; a < si; ++a)
          for (int b = 0; b < sj && (i != j || b <= a); ++b)
            triplets.emplace_back(s.reduced_offset_[i] + a,
                                  s.reduced_offset_[j] + b,
                                  static_cast<double>(s.cell_offset_[c] + a * sj + b));
      }
    s.sparse_->s.resize(s.n_reduced_, s.n_reduced_);
    s.sparse_->s.setFromTriplets(triplets.begin(), triplets.end());
    const auto& m = s.sparse_->s;
    s.sparse_->source.resize(m.nonZeros());
    for (long long k = 0; k < m.nonZeros(); ++k)
      s.sparse_->source[k] = std::llround(m.valuePtr()[k]);
    s.sparse_->llt =
        std::make_unique<Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower>>();
    s.sparse_->llt->analyzePattern(s.sparse_->s);
  }
  return sys;
}

void ReducedSystem::BuildStructure(const ResidualEvaluator& ev) {
  const int n_pts = static_cast<int>(points_.size()), n_red = static_cast<int>(reduced_.size());
  std::vector<std::pair<int, int>> pr, rr;  // (point, residual), (reduced block, residual)
  for (int i = 0; i < ev.num_residuals(); ++i) {
    if (residual_point_[i] >= 0) pr.emplace_back(residual_point_[i], i);
    for (int b : ev.term(i).free)
      if (b >= 0 && reduced_of_block_[b] >= 0) rr.emplace_back(reduced_of_block_[b], i);
  }
  Group(n_pts, pr, &point_res_start_, &point_res_);
  Group(n_red, rr, &red_res_start_, &red_res_);
  red_res_slot_.resize(red_res_.size());
  for (int j = 0; j < n_red; ++j)
    for (int k = red_res_start_[j]; k < red_res_start_[j + 1]; ++k)
      red_res_slot_[k] = SlotOf(ev.term(red_res_[k]), reduced_[j]);
  // Per point: its reduced blocks, where its W and Q blocks live; per row, its column blocks.
  point_blk_start_ = {0};
  std::vector<std::vector<int>> cols(n_red);
  std::vector<std::pair<int, int>> rp;  // (reduced block, entry)
  long long w_size = 0, v_size = 0;
  v_offset_.clear();
  for (int e = 0; e < n_pts; ++e) {
    std::vector<int> blk;
    for (int k = point_res_start_[e]; k < point_res_start_[e + 1]; ++k)
      for (int b : ev.term(point_res_[k]).free)
        if (b >= 0 && reduced_of_block_[b] >= 0) blk.push_back(reduced_of_block_[b]);
    std::sort(blk.begin(), blk.end());
    blk.erase(std::unique(blk.begin(), blk.end()), blk.end());
    const int t = ev.block(points_[e]).tangent;
    v_offset_.push_back(v_size);
    v_size += t * t;
    for (size_t a = 0; a < blk.size(); ++a) {
      rp.emplace_back(blk[a], static_cast<int>(point_blk_.size()));
      point_blk_.push_back(blk[a]);
      entry_point_.push_back(e);
      point_w_.push_back(w_size);
      w_size += static_cast<long long>(t) * ev.block(reduced_[blk[a]]).tangent;
      for (size_t b = 0; b <= a; ++b) cols[blk[a]].push_back(blk[b]);
    }
    point_blk_start_.push_back(static_cast<int>(point_blk_.size()));
  }
  Group(n_red, rp, &red_pt_start_, &red_pt_entry_);
  for (int i = 0; i < ev.num_residuals(); ++i) {
    std::vector<int> blk;
    for (int b : ev.term(i).free)
      if (b >= 0 && reduced_of_block_[b] >= 0) blk.push_back(reduced_of_block_[b]);
    for (int a : blk)
      for (int b : blk)
        if (b <= a) cols[a].push_back(b);
  }
  row_start_ = {0};
  long long s_size = 0;
  std::vector<double> row_cost(n_red), point_cost(n_pts);
  for (int i = 0; i < n_red; ++i) {
    std::sort(cols[i].begin(), cols[i].end());
    cols[i].erase(std::unique(cols[i].begin(), cols[i].end()), cols[i].end());
    const int si = ev.block(reduced_[i]).tangent;
    for (int j : cols[i]) {
      row_cols_.push_back(j);
      cell_offset_.push_back(s_size);
      s_size += static_cast<long long>(si) * ev.block(reduced_[j]).tangent;
    }
    row_start_.push_back(static_cast<int>(row_cols_.size()));
    row_cost[i] = 2.0 * (red_res_start_[i + 1] - red_res_start_[i]) + cols[i].size();
    for (int k = red_pt_start_[i]; k < red_pt_start_[i + 1]; ++k) {
      const int entry = red_pt_entry_[k];
      row_cost[i] += 1.0 + entry - point_blk_start_[entry_point_[entry]];
    }
  }
  for (int e = 0; e < n_pts; ++e)
    point_cost[e] = 1.0 + (point_res_start_[e + 1] - point_res_start_[e]) *
                              (point_blk_start_[e + 1] - point_blk_start_[e]);
  s_.assign(s_size, 0.0);
  v_.assign(v_size, 0.0);
  vinv_.assign(v_size, 0.0);
  w_.assign(w_size, 0.0);
  q_.assign(w_size, 0.0);
  qg_.assign(ev.num_tangent(), 0.0);
  row_bounds_ = BalancedBounds(row_cost, threads_);
  point_bounds_ = BalancedBounds(point_cost, threads_);
  IndexCells(ev);
}

int ReducedSystem::CellIndex(int row, int col_block) const {
  const int* begin = row_cols_.data() + row_start_[row];
  const int* end = row_cols_.data() + row_start_[row + 1];
  return static_cast<int>(std::lower_bound(begin, end, col_block) - row_cols_.data());
}

void ReducedSystem::IndexCells(const ResidualEvaluator& ev) {
  // The cell of every product AssembleRow adds, looked up once, with its multiply-adds (the
  // cost that splits the work between threads): per point entry (row block point_blk_[entry])
  // the cells of its pairs with the point's earlier blocks ...
  std::vector<double> cell_cost(row_cols_.size(), 0.0), row_cost(reduced_.size(), 0.0);
  pair_cell_start_ = {0};
  pair_cell_.clear();
  for (size_t entry = 0; entry < point_blk_.size(); ++entry) {
    const int e = entry_point_[entry], row = point_blk_[entry];
    const int t = ev.block(points_[e]).tangent;
    for (size_t a = point_blk_start_[e]; a <= entry; ++a) {
      pair_cell_.push_back(CellIndex(row, point_blk_[a]));
      cell_cost[pair_cell_.back()] +=
          kProductOverhead + t * BlockSize(row) * BlockSize(point_blk_[a]);
    }
    pair_cell_start_.push_back(static_cast<long long>(pair_cell_.size()));
    row_cost[row] += 8.0;  // a piece's loop visits every point of its row
  }
  // ... and per residual of a block row, the cell of each of its parameters (-1: none).
  u_cell_start_ = {0};
  u_cell_.clear();
  for (size_t j = 0; j + 1 < red_res_start_.size(); ++j)
    for (int k = red_res_start_[j]; k < red_res_start_[j + 1]; ++k) {
      const int rows = ev.residual_size(red_res_[k]);
      for (int b : ev.term(red_res_[k]).free) {
        const int col = b < 0 ? -1 : reduced_of_block_[b];
        u_cell_.push_back(
            col < 0 || col > static_cast<int>(j) ? -1 : CellIndex(static_cast<int>(j), col));
        if (u_cell_.back() >= 0)
          cell_cost[u_cell_.back()] +=
              kProductOverhead + rows * BlockSize(static_cast<int>(j)) * BlockSize(col);
      }
      u_cell_start_.push_back(static_cast<long long>(u_cell_.size()));
      row_cost[j] += 8.0;
    }
  PartitionRows(cell_cost, row_cost);
}

void ReducedSystem::IndexPointTerms(const ResidualEvaluator& ev) {
  point_res_slot_.resize(point_res_.size());
  point_res_w_start_ = {0};
  point_res_w_slot_.clear();
  point_res_w_entry_.clear();
  for (size_t e = 0; e < points_.size(); ++e) {
    const int b0 = point_blk_start_[e], b1 = point_blk_start_[e + 1];
    for (int k = point_res_start_[e]; k < point_res_start_[e + 1]; ++k) {
      const ResidualTerm& term = ev.term(point_res_[k]);
      point_res_slot_[k] = SlotOf(term, points_[e]);
      for (size_t q = 0; q < term.free.size(); ++q) {
        const int b = term.free[q];
        if (b < 0 || reduced_of_block_[b] < 0) continue;
        point_res_w_slot_.push_back(static_cast<int>(q));
        point_res_w_entry_.push_back(static_cast<int>(std::lower_bound(point_blk_.begin() + b0,
                                                                       point_blk_.begin() + b1,
                                                                       reduced_of_block_[b]) -
                                                      point_blk_.begin()));
      }
      point_res_w_start_.push_back(static_cast<long long>(point_res_w_slot_.size()));
    }
  }
}

template <int kRows, int kT>
void ReducedSystem::AddPointResidual(
    const ResidualEvaluator& ev, int k, int t, double* v, double* g) {
  const int i = point_res_[k], rows = ev.residual_size(i);
  const double* ej = ev.jacobian(i, point_res_slot_[k]);
  AddTransposedProductOf<kRows, kT>(ej, ej, rows, t, t, 1.0, v);
  AddTransposedProductOf<kRows, kT>(ej, ev.residual(i), rows, t, 1, 1.0, g);
  for (long long p = point_res_w_start_[k]; p < point_res_w_start_[k + 1]; ++p) {
    const int a = point_res_w_entry_[p];
    AddTransposedProductOf<kRows, kT>(ej,
                                      ev.jacobian(i, point_res_w_slot_[p]),
                                      rows,
                                      t,
                                      BlockSize(point_blk_[a]),
                                      1.0,
                                      w_.data() + point_w_[a]);
  }
}

void ReducedSystem::PartitionRows(const std::vector<double>& cell_cost,
                                  const std::vector<double>& row_cost) {
  double total = 0.0;
  for (double c : cell_cost) total += c;
  for (double c : row_cost) total += c;
  const double max_piece = total / (2.0 * threads_);
  row_parts_.clear();
  std::vector<double> part_cost;
  for (int i = 0; i < static_cast<int>(reduced_.size()); ++i) {
    const int c0 = row_start_[i], c1 = row_start_[i + 1];
    double cells = 0.0;
    for (int c = c0; c < c1; ++c) cells += cell_cost[c];
    // One thread: whole rows. Else a row above the piece size is cut where its cells' cost
    // passes k / pieces of the row's.
    const int pieces =
        threads_ == 1 ? 1
                      : std::max(1, static_cast<int>(std::ceil((row_cost[i] + cells) / max_piece)));
    double sum = 0.0, piece = 0.0;
    int begin = c0, cut = 1;
    for (int c = c0; c < c1; ++c) {
      sum += cell_cost[c];
      piece += cell_cost[c];
      if (c + 1 < c1 && sum < cells * cut / pieces) continue;
      row_parts_.push_back({i, begin, c + 1});
      part_cost.push_back(row_cost[i] + piece);
      begin = c + 1;
      piece = 0.0;
      while (cut < pieces && sum >= cells * cut / pieces) ++cut;  // a heavy cell spans cuts
    }
  }
  part_bounds_ = BalancedBounds(part_cost, threads_);
}

void ReducedSystem::Linearize(const ResidualEvaluator& ev) {
  g_.setZero(ev.num_tangent());
  diag_.setZero(ev.num_tangent());
  // Per point: V_e = E^T E, g_e = E^T r, W_e = E^T F (each point by one thread).
  ParallelRanges(point_bounds_, [&](int begin, int end, int) {
    for (int e = begin; e < end; ++e) {
      const int pb = points_[e], t = ev.block(pb).tangent, to = ev.tangent_offset(pb);
      double* v = v_.data() + v_offset_[e];
      std::fill_n(v, t * t, 0.0);
      const int b0 = point_blk_start_[e], b1 = point_blk_start_[e + 1];
      if (b0 < b1)  // the point's W blocks lie one after the other
        std::fill(w_.data() + point_w_[b0],
                  b1 < static_cast<int>(point_w_.size()) ? w_.data() + point_w_[b1]
                                                         : w_.data() + w_.size(),
                  0.0);
      for (int k = point_res_start_[e]; k < point_res_start_[e + 1]; ++k) {
        if (t == 3 && ev.residual_size(point_res_[k]) == 2)  // a ray of a ground point
          AddPointResidual<2, 3>(ev, k, t, v, g_.data() + to);
        else
          AddPointResidual<0, 0>(ev, k, t, v, g_.data() + to);
      }
      for (int a = 0; a < t; ++a) diag_(to + a) = v[a * t + a];
    }
  });
  // Per reduced block: g_j = F_j^T r and diag(F_j^T F_j), residuals in index order.
  ParallelRanges(row_bounds_, [&](int begin, int end, int) {
    for (int j = begin; j < end; ++j) {
      const int b = reduced_[j], sj = ev.block(b).tangent, to = ev.tangent_offset(b);
      for (int k = red_res_start_[j]; k < red_res_start_[j + 1]; ++k) {
        const int i = red_res_[k], rows = ev.residual_size(i);
        const double* f = ev.jacobian(i, red_res_slot_[k]);
        AddTransposedProduct(f, ev.residual(i), rows, sj, 1, 1.0, g_.data() + to);
        for (int a = 0; a < sj; ++a) {
          double norm2 = 0.0;
          for (int row = 0; row < rows; ++row) norm2 += f[row * sj + a] * f[row * sj + a];
          diag_(to + a) += norm2;
        }
      }
    }
  });
}

void ReducedSystem::AssembleRow(const ResidualEvaluator& ev, const RowPart& part) {
  switch (BlockSize(part.row)) {  // an exposure's rotation or centre, the interior
    case 3:
      return AssembleRowSized<3>(ev, part);
    case 10:
      return AssembleRowSized<10>(ev, part);
    default:
      return AssembleRowSized<0>(ev, part);
  }
}

// The row's products by the kernel of their shape (block_kernels.h): the residual's rows 2 (a ray)
// and the point's tangent 3 with the row's size kSi are fixed once for the row piece; any other
// shape takes the generic dispatch. The same operations in the same order either way.
template <int kSi>
void ReducedSystem::AssembleRowSized(const ResidualEvaluator& ev, const RowPart& part) {
  const int i = part.row, bi = reduced_[i], oi = reduced_offset_[i];
  const int si = kSi > 0 ? kSi : BlockSize(i);
  const int c0 = part.cell_begin, c1 = part.cell_end;
  const bool last = c1 == row_start_[i + 1];  // the diagonal cell is the row's last
  for (int c = c0; c < c1; ++c)
    std::fill_n(s_.data() + cell_offset_[c], si * BlockSize(row_cols_[c]), 0.0);
  // U = F^T F, the residuals by index (the cells and sizes from the index arrays read in order,
  // not from the residual terms: those are scattered over the heap).
  for (int k = red_res_start_[i]; k < red_res_start_[i + 1]; ++k) {
    const int r = red_res_[k], rows = ev.residual_size(r);
    const double* fi = ev.jacobian(r, red_res_slot_[k]);
    const int* cells = u_cell_.data() + u_cell_start_[k];
    const int slots = static_cast<int>(u_cell_start_[k + 1] - u_cell_start_[k]);
    for (int q = 0; q < slots; ++q) {
      const int c = cells[q];  // -1 (no cell) is below c0 too
      if (c < c0 || c >= c1) continue;
      const int sj = BlockSize(row_cols_[c]);
      double* cell = s_.data() + cell_offset_[c];
      if (rows == 2)
        AddTransposedProductOf<2, kSi>(fi, ev.jacobian(r, q), rows, si, sj, 1.0, cell);
      else
        AddTransposedProduct(fi, ev.jacobian(r, q), rows, si, sj, 1.0, cell);
    }
  }
  const int ti = ev.tangent_offset(bi);
  if (last) {
    double* diagonal = s_.data() + cell_offset_[CellIndex(i, i)];
    for (int a = 0; a < si; ++a) diagonal[a * si + a] += d2_(ti + a);
    rhs_.segment(oi, si) = -g_.segment(ti, si);
  }
  // - W_e^T V_e^-1 W_e, the points by index; a point's cells ascend with its blocks.
  for (int k = red_pt_start_[i]; k < red_pt_start_[i + 1]; ++k) {
    const int entry = red_pt_entry_[k];
    const int e = entry_point_[entry], a0 = point_blk_start_[e];
    const int t = ev.block(points_[e]).tangent;
    const double* wi = w_.data() + point_w_[entry];
    const double* qg = qg_.data() + ev.tangent_offset(points_[e]);
    const int* cells = pair_cell_.data() + pair_cell_start_[entry];
    if (t == 3) {
      AddPointPairs<3, kSi>(wi, cells, a0, entry, t, si, c0, c1, -1.0);
      if (last) AddTransposedProductOf<3, kSi>(wi, qg, t, si, 1, 1.0, rhs_.data() + oi);
    } else {
      AddPointPairs<0, kSi>(wi, cells, a0, entry, t, si, c0, c1, -1.0);
      if (last) AddTransposedProduct(wi, qg, t, si, 1, 1.0, rhs_.data() + oi);
    }
  }
}

template <int kT, int kSi>
void ReducedSystem::AddPointPairs(const double* wi,
                                  const int* cells,
                                  int a0,
                                  int entry,
                                  int t,
                                  int si,
                                  int c0,
                                  int c1,
                                  double sign) {
  for (int a = a0; a <= entry; ++a) {
    const int c = cells[a - a0];
    if (c < c0) continue;
    if (c >= c1) break;
    AddTransposedProductOf<kT, kSi>(wi,
                                    q_.data() + point_w_[a],
                                    t,
                                    si,
                                    BlockSize(point_blk_[a]),
                                    sign,
                                    s_.data() + cell_offset_[c]);
  }
}

bool ReducedSystem::Factorize(Eigen::VectorXd* rhs) {
  const int n_red = static_cast<int>(reduced_.size());
  if (dense_) {
    for (int i = 0; i < n_red; ++i) {
      const int si = reduced_offset_[i + 1] - reduced_offset_[i];
      for (int c = row_start_[i]; c < row_start_[i + 1]; ++c) {
        const int j = row_cols_[c], sj = reduced_offset_[j + 1] - reduced_offset_[j];
        dense_s_.block(reduced_offset_[i], reduced_offset_[j], si, sj) =
            ConstMap(s_.data() + cell_offset_[c], si, sj);
      }
    }
    Eigen::LLT<Eigen::MatrixXd, Eigen::Lower> llt(dense_s_);
    if (llt.info() != Eigen::Success) return false;
    llt.solveInPlace(*rhs);
    return rhs->allFinite();
  }
  double* values = sparse_->s.valuePtr();
  for (size_t k = 0; k < sparse_->source.size(); ++k) values[k] = s_[sparse_->source[k]];
  sparse_->llt->factorize(sparse_->s);
  if (sparse_->llt->info() != Eigen::Success) return false;
  *rhs = sparse_->llt->solve(*rhs);
  return sparse_->llt->info() == Eigen::Success && rhs->allFinite();
}

bool ReducedSystem::Reduce(const ResidualEvaluator& ev, bool pseudo) {
  std::atomic<bool> ok{true};
  // V_e^-1 (damped), Q_e = V_e^-1 W_e, V_e^-1 g_e per point.
  ParallelRanges(point_bounds_, [&](int begin, int end, int) {
    for (int e = begin; e < end; ++e) {
      const int pb = points_[e], t = ev.block(pb).tangent, to = ev.tangent_offset(pb);
      double* vinv = vinv_.data() + v_offset_[e];
      const double* v = v_.data() + v_offset_[e];
      const bool inverted = t == 3
                                ? InvertDamped<3>(v, d2_.data() + to, t, pseudo, vinv)
                                : InvertDamped<Eigen::Dynamic>(v, d2_.data() + to, t, pseudo, vinv);
      if (!inverted) {
        ok = false;
        continue;
      }
      // V^-1 is symmetric (InvertDamped), so V^-1 x = (V^-1)^T x: the transposed kernel serves.
      std::fill_n(qg_.data() + to, t, 0.0);
      AddTransposedProduct(vinv, g_.data() + to, t, t, 1, 1.0, qg_.data() + to);
      const int a0 = point_blk_start_[e], a1 = point_blk_start_[e + 1];
      if (a0 < a1)
        std::fill(q_.data() + point_w_[a0],
                  a1 < static_cast<int>(point_w_.size()) ? q_.data() + point_w_[a1]
                                                         : q_.data() + q_.size(),
                  0.0);
      for (int a = a0; a < a1; ++a) {
        const int sj = ev.block(reduced_[point_blk_[a]]).tangent;
        AddTransposedProduct(vinv, w_.data() + point_w_[a], t, t, sj, 1.0, q_.data() + point_w_[a]);
      }
    }
  });
  if (!ok) return false;
  rhs_.resize(n_reduced_);
  ParallelRanges(part_bounds_, [&](int begin, int end, int) {
    for (int p = begin; p < end; ++p) AssembleRow(ev, row_parts_[p]);
  });
  return true;
}

bool ReducedSystem::UndampedLower(const ResidualEvaluator& ev, Eigen::SparseMatrix<double>* s) {
  d2_.setZero(ev.num_tangent());
  if (!Reduce(ev, true)) return false;
  if (sparse_) {  // the solve's pattern, handed over (no copy: the statistics' peak memory)
    double* values = sparse_->s.valuePtr();
    for (size_t k = 0; k < sparse_->source.size(); ++k) values[k] = s_[sparse_->source[k]];
    *s = std::move(sparse_->s);
    sparse_.reset();
    return true;
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (size_t i = 0; i < reduced_.size(); ++i) {
    const int si = reduced_offset_[i + 1] - reduced_offset_[i];
    for (int c = row_start_[i]; c < row_start_[i + 1]; ++c) {
      const int j = row_cols_[c], sj = reduced_offset_[j + 1] - reduced_offset_[j];
      const double* cell = s_.data() + cell_offset_[c];
      for (int a = 0; a < si; ++a)
        for (int b = 0; b < sj && (j != static_cast<int>(i) || b <= a); ++b)
          triplets.emplace_back(reduced_offset_[i] + a, reduced_offset_[j] + b, cell[a * sj + b]);
    }
  }
  s->resize(n_reduced_, n_reduced_);
  s->setFromTriplets(triplets.begin(), triplets.end());
  return true;
}

void ReducedSystem::ReleaseFactor() {
  if (sparse_) sparse_->llt.reset();
  dense_s_.resize(0, 0);
}

bool ReducedSystem::Solve(const ResidualEvaluator& ev, double radius, Eigen::VectorXd* dx) {
  d2_ = diag_.cwiseMax(kMinDiagonal).cwiseMin(kMaxDiagonal) / radius;
  if (!Reduce(ev, false) || !Factorize(&rhs_)) return false;
  dx->resize(ev.num_tangent());
  for (size_t j = 0; j < reduced_.size(); ++j)
    dx->segment(ev.tangent_offset(reduced_[j]), reduced_offset_[j + 1] - reduced_offset_[j]) =
        rhs_.segment(reduced_offset_[j], reduced_offset_[j + 1] - reduced_offset_[j]);
  // Back-substitution: dx_e = -V_e^-1 g_e - Q_e dx_F.
  ParallelRanges(point_bounds_, [&](int begin, int end, int) {
    for (int e = begin; e < end; ++e) {
      const int pb = points_[e], t = ev.block(pb).tangent, to = ev.tangent_offset(pb);
      double* x = dx->data() + to;
      for (int k = 0; k < t; ++k) x[k] = -qg_[to + k];
      for (int a = point_blk_start_[e]; a < point_blk_start_[e + 1]; ++a) {
        const int j = point_blk_[a], sj = reduced_offset_[j + 1] - reduced_offset_[j];
        SubtractProduct(q_.data() + point_w_[a], rhs_.data() + reduced_offset_[j], t, sj, x);
      }
    }
  });
  return dx->allFinite();
}

}  // namespace aerocal::calib::internal
