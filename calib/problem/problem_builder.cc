#include "calib/problem/problem_builder.h"

#include "calib/core/error.h"
#include "calib/problem/scaled_subset_manifold.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <ceres/ceres.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <thread>

namespace aerocal::calib {

struct ProblemBuilder::Block {
  std::string name;
  double* values = nullptr;
  int size = 0;
  BlockKind kind = BlockKind::kOther;
  std::vector<std::string> entry_names;
  bool constant = false;
  std::vector<bool> entry_fixed;
  std::vector<double> scales;  // per free entry, tangent scaling
  int num_residuals = 0;       // residual blocks that use it

  std::vector<int> FreeEntries() const {
    std::vector<int> out;
    for (int i = 0; i < size; ++i)
      if (!entry_fixed[i]) out.push_back(i);
    return out;
  }
  int TangentSize() const { return constant ? 0 : static_cast<int>(FreeEntries().size()); }
  /// Ground and virtual tie points: the blocks a Schur complement eliminates.
  bool Eliminable() const {
    return kind == BlockKind::kGroundPoint || kind == BlockKind::kTiePoint2d;
  }
  /// "block.entry", the name of one parameter in reports.
  std::string EntryName(int e) const { return name + "." + entry_names[e]; }
};

struct ProblemBuilder::Residual {
  std::string group, label;
  ceres::ResidualBlockId id = nullptr;
  std::vector<BlockId> blocks;
  int size = 0;
  bool active = true;
};

const ResidualGroupStats* SolveReport::Group(const std::string& name) const {
  for (const auto& g : groups)
    if (g.name == name) return &g;
  return nullptr;
}

Eigen::MatrixXd CovarianceReport::BlockCovariance(BlockId id, int size) const {
  const int offset = offsets.at(id);
  return covariance.block(offset, offset, size, size);
}

Eigen::VectorXd CovarianceReport::BlockSigma(BlockId id, int size) const {
  return sigma.segment(offsets.at(id), size);
}

double NormalCriticalValue(double alpha) {
  // Solve erfc(z / sqrt 2) = alpha by bisection (monotone), to 1e-10.
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (std::erfc(mid / std::sqrt(2.0)) > alpha)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

ProblemBuilder::ProblemBuilder() {
  ceres::Problem::Options options;
  options.enable_fast_removal = true;
  problem_ = std::make_unique<ceres::Problem>(options);
}

ProblemBuilder::~ProblemBuilder() = default;

ceres::Problem& ProblemBuilder::problem() { return *problem_; }

BlockId ProblemBuilder::AddBlock(const std::string& name,
                                 double* values,
                                 int size,
                                 BlockKind kind,
                                 std::vector<std::string> entry_names) {
  AEROCAL_CHECK(size > 0 && values != nullptr) << "block " << name;
  AEROCAL_CHECK(block_by_name_.count(name) == 0) << "duplicate block name " << name;
  AEROCAL_CHECK(block_by_pointer_.count(values) == 0) << "block memory registered twice: " << name;
  if (entry_names.empty())
    for (int i = 0; i < size; ++i) entry_names.push_back(std::to_string(i));
  AEROCAL_CHECK(static_cast<int>(entry_names.size()) == size) << "entry names of " << name;
  Block block;
  block.name = name;
  block.values = values;
  block.size = size;
  block.kind = kind;
  block.entry_names = std::move(entry_names);
  block.entry_fixed.assign(size, false);
  block.scales.assign(size, 1.0);
  const BlockId id = static_cast<BlockId>(blocks_.size());
  blocks_.push_back(std::move(block));
  block_by_name_[name] = id;
  block_by_pointer_[values] = id;
  problem_->AddParameterBlock(values, size);
  return id;
}

BlockId ProblemBuilder::FindBlock(const std::string& name) const {
  const auto it = block_by_name_.find(name);
  return it == block_by_name_.end() ? -1 : it->second;
}

void ProblemBuilder::FixBlock(BlockId id) {
  blocks_.at(id).constant = true;
  problem_->SetParameterBlockConstant(blocks_[id].values);
}

void ProblemBuilder::FreeBlock(BlockId id) {
  Block& b = blocks_.at(id);
  b.constant = std::all_of(b.entry_fixed.begin(), b.entry_fixed.end(), [](bool f) { return f; });
  if (!b.constant) problem_->SetParameterBlockVariable(b.values);
}

void ProblemBuilder::FixEntries(BlockId id, const std::vector<int>& entries) {
  Block& b = blocks_.at(id);
  for (int e : entries) {
    AEROCAL_CHECK(e >= 0 && e < b.size) << "entry " << e << " of block " << b.name;
    b.entry_fixed[e] = true;
  }
  if (b.FreeEntries().empty()) {
    FixBlock(id);
    return;
  }
  // In force at once, for a covariance or redundancy numbers before the next Solve().
  UpdateManifolds();
}

bool ProblemBuilder::IsBlockFixed(BlockId id) const { return blocks_.at(id).constant; }
int ProblemBuilder::BlockSize(BlockId id) const { return blocks_.at(id).size; }
const std::string& ProblemBuilder::BlockName(BlockId id) const { return blocks_.at(id).name; }
BlockKind ProblemBuilder::BlockKindOf(BlockId id) const { return blocks_.at(id).kind; }
const std::vector<BlockId>& ProblemBuilder::ResidualBlocks(ResidualId id) const {
  return residuals_.at(id).blocks;
}
double* ProblemBuilder::BlockValues(BlockId id) const { return blocks_.at(id).values; }

ResidualId ProblemBuilder::AddResidual(const std::string& group,
                                       std::unique_ptr<ceres::CostFunction> cost,
                                       const std::vector<BlockId>& blocks,
                                       const std::string& label,
                                       const LossOptions& loss) {
  AEROCAL_CHECK(cost != nullptr) << "null cost function in group " << group;
  AEROCAL_CHECK(cost->parameter_block_sizes().size() == blocks.size())
      << "group " << group << ": cost function expects " << cost->parameter_block_sizes().size()
      << " blocks, got " << blocks.size();
  std::vector<double*> pointers;
  for (size_t i = 0; i < blocks.size(); ++i) {
    const Block& b = blocks_.at(blocks[i]);
    AEROCAL_CHECK(cost->parameter_block_sizes()[i] == b.size)
        << "group " << group << ": block " << b.name << " has size " << b.size
        << ", functor expects " << cost->parameter_block_sizes()[i];
    pointers.push_back(b.values);
  }
  ceres::LossFunction* loss_function = nullptr;
  if (loss.kind == LossKind::kHuber) loss_function = new ceres::HuberLoss(loss.scale);
  if (loss.kind == LossKind::kCauchy) loss_function = new ceres::CauchyLoss(loss.scale);
  Residual r;
  r.group = group;
  r.label = label;
  r.blocks = blocks;
  r.size = cost->num_residuals();
  r.id = problem_->AddResidualBlock(cost.release(), loss_function, pointers);
  for (BlockId b : blocks) ++blocks_[b].num_residuals;
  residuals_.push_back(std::move(r));
  return static_cast<ResidualId>(residuals_.size() - 1);
}

void ProblemBuilder::RemoveResidual(ResidualId id) {
  Residual& r = residuals_.at(id);
  if (!r.active) return;
  problem_->RemoveResidualBlock(r.id);
  r.active = false;
  for (BlockId b : r.blocks) --blocks_[b].num_residuals;
}

bool ProblemBuilder::IsActive(ResidualId id) const { return residuals_.at(id).active; }

int ProblemBuilder::NumResiduals() const { return static_cast<int>(residuals_.size()); }

int ProblemBuilder::NumActiveResiduals() const {
  return static_cast<int>(std::count_if(
      residuals_.begin(), residuals_.end(), [](const Residual& r) { return r.active; }));
}

const std::string& ProblemBuilder::ResidualGroup(ResidualId id) const {
  return residuals_.at(id).group;
}
const std::string& ProblemBuilder::ResidualLabel(ResidualId id) const {
  return residuals_.at(id).label;
}

std::vector<double> ProblemBuilder::EvaluateResidual(ResidualId id) const {
  const Residual& r = residuals_.at(id);
  std::vector<double> values(r.size, 0.0);
  if (!r.active) return values;
  double cost = 0.0;
  problem_->EvaluateResidualBlock(r.id, false, &cost, values.data(), nullptr);
  return values;
}

std::vector<BlockId> ProblemBuilder::FreeBlocksInOrder() const {
  std::vector<BlockId> out;
  for (BlockId i = 0; i < static_cast<BlockId>(blocks_.size()); ++i)
    if (!blocks_[i].constant && blocks_[i].num_residuals > 0) out.push_back(i);
  return out;
}

int ProblemBuilder::NumFreeParameters() const {
  int n = 0;
  for (BlockId b : FreeBlocksInOrder()) n += blocks_[b].TangentSize();
  return n;
}

int ProblemBuilder::NumObservations() const {
  int n = 0;
  for (const auto& r : residuals_)
    if (r.active) n += r.size;
  return n;
}

Eigen::MatrixXd ProblemBuilder::DenseJacobian(const std::vector<BlockId>& blocks,
                                              std::vector<ResidualId>* row_owner) const {
  ceres::Problem::EvaluateOptions options;
  for (BlockId b : blocks) options.parameter_blocks.push_back(blocks_[b].values);
  std::vector<ResidualId> owners;
  for (ResidualId i = 0; i < static_cast<ResidualId>(residuals_.size()); ++i) {
    if (!residuals_[i].active) continue;
    options.residual_blocks.push_back(residuals_[i].id);
    for (int k = 0; k < residuals_[i].size; ++k) owners.push_back(i);
  }
  options.apply_loss_function = false;
  ceres::CRSMatrix crs;
  double cost = 0.0;
  problem_->Evaluate(options, &cost, nullptr, nullptr, &crs);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int row = 0; row < crs.num_rows; ++row)
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) dense(row, crs.cols[k]) = crs.values[k];
  if (row_owner) *row_owner = std::move(owners);
  return dense;
}

bool ProblemBuilder::UpdateManifolds() {
  // Tangent scaling: unit Jacobian columns at the current values (scaled_subset_manifold.h).
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  for (BlockId id : free_blocks) {
    Block& b = blocks_[id];
    const auto free = b.FreeEntries();
    problem_->SetManifold(
        b.values, new ScaledSubsetManifold(b.size, free, std::vector<double>(free.size(), 1.0)));
  }
  if (free_blocks.empty()) return true;
  ceres::Problem::EvaluateOptions eval;
  for (BlockId b : free_blocks) eval.parameter_blocks.push_back(blocks_[b].values);
  eval.apply_loss_function = false;
  ceres::CRSMatrix crs;
  double cost = 0;
  if (!problem_->Evaluate(eval, &cost, nullptr, nullptr, &crs)) return false;
  std::vector<double> norm2(crs.num_cols, 0.0);
  for (size_t k = 0; k < crs.values.size(); ++k)
    norm2[crs.cols[k]] += crs.values[k] * crs.values[k];
  int col = 0;
  for (BlockId id : free_blocks) {
    Block& b = blocks_[id];
    const auto free = b.FreeEntries();
    std::vector<double> scales;
    for (size_t k = 0; k < free.size(); ++k, ++col)
      scales.push_back(norm2[col] > 0 ? 1.0 / std::sqrt(norm2[col]) : 1.0);
    problem_->SetManifold(b.values, new ScaledSubsetManifold(b.size, free, scales));
  }
  return true;
}

SolveReport ProblemBuilder::Solve(const SolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  SolveReport report;
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  if (!UpdateManifolds())
    report.diagnostics.push_back(
        "the residuals cannot be evaluated at the starting values (a point behind a camera?)");

  ceres::Solver::Options ceres_options;
  ceres_options.max_num_iterations = options.max_iterations;
  ceres_options.function_tolerance = options.function_tolerance;
  ceres_options.gradient_tolerance = options.gradient_tolerance;
  ceres_options.parameter_tolerance = options.parameter_tolerance;
  ceres_options.num_threads = options.num_threads > 0
                                  ? options.num_threads
                                  : std::max(1u, std::thread::hardware_concurrency());
  ceres_options.minimizer_progress_to_stdout = options.verbose;
  ceres_options.logging_type = options.verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;

  int eliminable_params = 0, other_params = 0;
  std::vector<BlockId> eliminable;
  for (BlockId id : free_blocks) {
    const Block& b = blocks_[id];
    if (b.Eliminable()) {
      eliminable.push_back(id);
      eliminable_params += b.TangentSize();
    } else {
      other_params += b.TangentSize();
    }
  }
  const bool sparse_available =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  LinearSolverChoice choice = options.linear_solver;
  if (choice == LinearSolverChoice::kAuto) {
    if (eliminable_params + other_params <= 300)
      choice = LinearSolverChoice::kDenseQr;
    else if (!eliminable.empty() && other_params > 0)
      choice = other_params <= 800 || !sparse_available ? LinearSolverChoice::kDenseSchur
                                                        : LinearSolverChoice::kSparseSchur;
    else
      choice = sparse_available ? LinearSolverChoice::kSparseNormalCholesky
                                : LinearSolverChoice::kDenseQr;
  }
  switch (choice) {
    case LinearSolverChoice::kDenseQr:
    case LinearSolverChoice::kAuto:
      ceres_options.linear_solver_type = ceres::DENSE_QR;
      report.linear_solver = "dense_qr";
      break;
    case LinearSolverChoice::kDenseSchur:
      ceres_options.linear_solver_type = ceres::DENSE_SCHUR;
      report.linear_solver = "dense_schur";
      break;
    case LinearSolverChoice::kSparseSchur:
      ceres_options.linear_solver_type = ceres::SPARSE_SCHUR;
      report.linear_solver = "sparse_schur";
      break;
    case LinearSolverChoice::kSparseNormalCholesky:
      ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
      report.linear_solver = "sparse_normal_cholesky";
      break;
  }
  if (ceres_options.linear_solver_type == ceres::DENSE_SCHUR ||
      ceres_options.linear_solver_type == ceres::SPARSE_SCHUR) {
    if (eliminable.empty() || other_params == 0) {
      ceres_options.linear_solver_type = ceres::DENSE_QR;
      report.linear_solver = "dense_qr";
    } else {
      auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
      for (BlockId id : free_blocks) {
        const Block& b = blocks_[id];
        const bool elim = b.Eliminable();
        ordering->AddElementToGroup(b.values, elim ? 0 : 1);
      }
      ceres_options.linear_solver_ordering = ordering;
    }
  }

  ceres::Solver::Summary summary;
  if (report.diagnostics.empty()) ceres::Solve(ceres_options, problem_.get(), &summary);

  report.termination = ceres::TerminationTypeToString(summary.termination_type);
  report.message = summary.message;
  report.converged = summary.termination_type == ceres::CONVERGENCE;
  report.usable = summary.IsSolutionUsable();
  report.iterations =
      std::max(0, static_cast<int>(summary.iterations.size()) - 1);  // [0] is the start
  report.initial_cost = summary.initial_cost;
  report.final_cost = summary.final_cost;

  // Statistics without the loss function: v^T P v per group and overall.
  std::map<std::string, ResidualGroupStats> groups;
  for (ResidualId i = 0; i < static_cast<ResidualId>(residuals_.size()); ++i) {
    const Residual& r = residuals_[i];
    if (!r.active) continue;
    auto& g = groups[r.group];
    g.name = r.group;
    ++g.n_residual_blocks;
    g.n_observations += r.size;
    for (double v : EvaluateResidual(i)) g.vtpv += v * v;
  }
  for (auto& [name, g] : groups) {
    g.rms = g.n_observations > 0 ? std::sqrt(g.vtpv / g.n_observations) : 0.0;
    report.vtpv += g.vtpv;
    report.n_observations += g.n_observations;
    report.groups.push_back(g);
  }
  report.n_unknowns = NumFreeParameters();
  report.redundancy = report.n_observations - report.n_unknowns;
  if (report.redundancy > 0) {
    report.sigma0 = std::sqrt(report.vtpv / report.redundancy);
  } else {
    report.diagnostics.push_back("no redundancy: " + std::to_string(report.n_observations) +
                                 " observations for " + std::to_string(report.n_unknowns) +
                                 " unknowns; sigma0 cannot be estimated");
  }
  if (!report.converged)
    report.diagnostics.push_back("the adjustment did not converge: " + summary.message);
  for (BlockId id = 0; id < static_cast<BlockId>(blocks_.size()); ++id)
    if (!blocks_[id].constant && blocks_[id].num_residuals == 0)
      report.diagnostics.push_back("block " + blocks_[id].name + " has no observations");
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

// Normal equations reduced to the non-point parameters: S = N_rr - N_rp N_pp^-1 N_pr.
struct ProblemBuilder::ReducedSystem {
  std::vector<BlockId> free_blocks;
  std::map<BlockId, int> offset;  // tangent offset of a block in its space (points or reduced)
  int n_p = 0, n_r = 0;
  Eigen::SparseMatrix<double> s;
  std::vector<std::string> reduced_names;  // one per reduced column
  std::vector<BlockId> singular_points;    // point blocks with a singular N_pp block (left out)
};

namespace {
// The names of the parameters that the eigenvectors of (scaled) `n` with eigenvalues below
// 1e-12 of the largest involve (|component| > 0.2).
std::set<std::string> NullSpaceNames(Eigen::MatrixXd n, const std::vector<std::string>& names) {
  Eigen::VectorXd d = n.diagonal().cwiseSqrt();
  for (int i = 0; i < d.size(); ++i) d(i) = d(i) > 0 ? 1.0 / d(i) : 1.0;
  n = d.asDiagonal() * n * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(n);
  const double max_eig = eig.eigenvalues().maxCoeff();
  std::set<std::string> out;
  for (int k = 0; k < eig.eigenvalues().size(); ++k) {
    if (eig.eigenvalues()(k) > 1e-12 * max_eig) break;  // ascending order
    const Eigen::VectorXd v = eig.eigenvectors().col(k);
    for (int i = 0; i < v.size(); ++i)
      if (std::abs(v(i)) > 0.2) out.insert(names[i]);
  }
  return out;
}
}  // namespace

std::vector<std::string> ProblemBuilder::NullSpaceParameters(int max_parameters) const {
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  if (NumFreeParameters() > max_parameters) {
    // Large blocks: the datum defect lives in the exterior / interior parameters; find it in the
    // reduced system (points eliminated), and name points that are undetermined on their own.
    ReducedSystem reduced;
    if (!ReduceNormalEquations(&reduced) || reduced.n_r > max_parameters) return {};
    std::set<std::string> out = NullSpaceNames(Eigen::MatrixXd(reduced.s), reduced.reduced_names);
    for (BlockId id : reduced.singular_points) out.insert(blocks_[id].name);
    return {out.begin(), out.end()};
  }
  const Eigen::MatrixXd j = DenseJacobian(free_blocks, nullptr);
  std::vector<std::string> names;
  for (BlockId b : free_blocks)
    for (int e : blocks_[b].FreeEntries()) names.push_back(blocks_[b].EntryName(e));
  const std::set<std::string> out = NullSpaceNames(j.transpose() * j, names);
  return {out.begin(), out.end()};
}

CovarianceReport ProblemBuilder::EstimateCovariance(
    const std::vector<BlockId>& blocks,
    double sigma0,
    double correlation_threshold,
    const std::vector<BlockId>& cross_blocks) const {
  CovarianceReport report;
  int total = 0;
  for (BlockId id : blocks) {
    report.offsets[id] = total;
    const Block& b = blocks_.at(id);
    for (int e = 0; e < b.size; ++e) {
      report.names.push_back(b.EntryName(e));
      report.free.push_back(!b.constant && !b.entry_fixed[e] && b.num_residuals > 0);
    }
    total += b.size;
  }
  report.covariance = Eigen::MatrixXd::Zero(total, total);
  std::vector<BlockId> free_requested;
  for (BlockId id : blocks)
    if (!blocks_[id].constant && blocks_[id].num_residuals > 0) free_requested.push_back(id);

  ceres::Covariance::Options options;
  const int n_free = NumFreeParameters();
  options.algorithm_type = n_free <= 300 ? ceres::DENSE_SVD : ceres::SPARSE_QR;
  options.min_reciprocal_condition_number = 1e-14;
  options.num_threads = std::max(1u, std::thread::hardware_concurrency());
  options.apply_loss_function = true;
  ceres::Covariance covariance(options);
  const std::set<BlockId> cross(cross_blocks.begin(), cross_blocks.end());
  auto wanted = [&](size_t i, size_t k) {
    return cross.empty() || i == k || cross.count(free_requested[i]) ||
           cross.count(free_requested[k]);
  };
  std::vector<std::pair<const double*, const double*>> pairs;
  for (size_t i = 0; i < free_requested.size(); ++i)
    for (size_t k = i; k < free_requested.size(); ++k)
      if (wanted(i, k))
        pairs.emplace_back(blocks_[free_requested[i]].values, blocks_[free_requested[k]].values);
  std::vector<std::pair<BlockId, BlockId>> pair_ids;
  for (size_t i = 0; i < free_requested.size(); ++i)
    for (size_t k = i; k < free_requested.size(); ++k)
      if (wanted(i, k)) pair_ids.emplace_back(free_requested[i], free_requested[k]);
  std::map<std::pair<BlockId, BlockId>, Eigen::MatrixXd> schur;
  const bool use_schur = n_free > 300 && SchurCovariance(pair_ids, &schur);
  report.method = use_schur ? "schur" : n_free <= 300 ? "ceres_dense_svd" : "ceres_sparse_qr";
  const bool computed = pairs.empty() || use_schur || covariance.Compute(pairs, problem_.get());
  if (!computed) {
    report.ok = false;
    report.undetermined = NullSpaceParameters(3000);
    report.message =
        "the normal matrix is singular or badly conditioned: the problem has a "
        "datum defect or parameters the observations cannot determine";
    if (!report.undetermined.empty()) {
      report.message += " (";
      for (size_t i = 0; i < report.undetermined.size() && i < 20; ++i)
        report.message += (i ? ", " : "") + report.undetermined[i];
      if (report.undetermined.size() > 20) report.message += ", ...";
      report.message += ")";
    }
    report.sigma = Eigen::VectorXd::Zero(total);
    report.correlation = Eigen::MatrixXd::Identity(total, total);
    return report;
  }
  const double s2 = sigma0 * sigma0;
  for (size_t i = 0; i < free_requested.size(); ++i) {
    for (size_t k = i; k < free_requested.size(); ++k) {
      if (!wanted(i, k)) continue;
      const Block& a = blocks_[free_requested[i]];
      const Block& b = blocks_[free_requested[k]];
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(a.size, b.size);
      if (use_schur)
        m = schur.at({free_requested[i], free_requested[k]});
      else
        covariance.GetCovarianceBlock(a.values, b.values, m.data());
      const int ra = report.offsets[free_requested[i]], rb = report.offsets[free_requested[k]];
      report.covariance.block(ra, rb, a.size, b.size) = s2 * m;
      report.covariance.block(rb, ra, b.size, a.size) = s2 * m.transpose();
    }
  }
  report.ok = true;
  report.sigma = report.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  report.correlation = Eigen::MatrixXd::Identity(total, total);
  for (int i = 0; i < total; ++i)
    for (int k = 0; k < total; ++k)
      if (i != k && report.sigma(i) > 0 && report.sigma(k) > 0)
        report.correlation(i, k) = report.covariance(i, k) / (report.sigma(i) * report.sigma(k));
  for (int i = 0; i < total; ++i)
    for (int k = i + 1; k < total; ++k)
      if (report.free[i] && report.free[k] &&
          std::abs(report.correlation(i, k)) > correlation_threshold)
        report.high_correlations.push_back(
            {report.names[i], report.names[k], report.correlation(i, k)});
  return report;
}

// Redundancy numbers r_ii = 1 - j_i N^-1 j_i^T with the point blocks (ground points, virtual tie
// points) eliminated, as the Schur solver does: with N = [A B; B^T C] (A block-diagonal over the
// point blocks, C over the other parameters) and S = C - B^T A^-1 B, a row j = [a f] touching one
// point block e gives, with t = a A_e^-1 and q = t B_e:
//   j N^-1 j^T = t a^T + (q - f) S^+ (q - f)^T.
// Cost O(rows * n_other^2 + n_other^3) instead of O(n_free^3). Returns false (dense path) when
// there is no point block, a row touches two point blocks, or S is larger than `max_dense`.
bool ProblemBuilder::RedundancyNumbersBySchur(
    const std::vector<ResidualId>& ids,
    int max_dense,
    std::map<ResidualId, std::vector<double>>* out,
    std::vector<ResidualCluster>* clusters) const {
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  std::vector<int> column_block;  // index into free_blocks of every tangent column
  std::vector<int> local_column;  // column within the point block, or within C
  std::vector<bool> eliminable(free_blocks.size());
  int n_other = 0;
  bool any_point = false;
  for (size_t i = 0; i < free_blocks.size(); ++i) {
    const Block& b = blocks_[free_blocks[i]];
    eliminable[i] = b.Eliminable();
    any_point = any_point || eliminable[i];
    for (int k = 0; k < b.TangentSize(); ++k) {
      column_block.push_back(static_cast<int>(i));
      local_column.push_back(eliminable[i] ? k : n_other++);
    }
  }
  if (!any_point || n_other > max_dense) return false;
  ceres::Problem::EvaluateOptions options;
  for (BlockId b : free_blocks) options.parameter_blocks.push_back(blocks_[b].values);
  std::vector<ResidualId> owner;
  for (ResidualId i = 0; i < static_cast<ResidualId>(residuals_.size()); ++i) {
    if (!residuals_[i].active) continue;
    options.residual_blocks.push_back(residuals_[i].id);
    for (int k = 0; k < residuals_[i].size; ++k) owner.push_back(i);
  }
  options.apply_loss_function = false;
  ceres::CRSMatrix crs;
  double cost = 0.0;
  if (!problem_->Evaluate(options, &cost, nullptr, nullptr, &crs)) return false;
  // Split every row into its point part a (one block at most) and its other part f.
  struct Row {
    int point = -1;  // index into free_blocks, -1 when none
    Eigen::VectorXd a, f;
  };
  std::vector<Row> rows(crs.num_rows);
  std::map<int, Eigen::MatrixXd> a_blocks, b_blocks;  // per point block: A_e, B_e
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n_other, n_other);
  for (int r = 0; r < crs.num_rows; ++r) {
    Row& row = rows[r];
    row.f = Eigen::VectorXd::Zero(n_other);
    for (int k = crs.rows[r]; k < crs.rows[r + 1]; ++k) {
      const int col = crs.cols[k], block = column_block[col];
      if (!eliminable[block]) {
        row.f(local_column[col]) = crs.values[k];
        continue;
      }
      if (row.point >= 0 && row.point != block) return false;
      if (row.point < 0) {
        row.point = block;
        row.a = Eigen::VectorXd::Zero(blocks_[free_blocks[block]].TangentSize());
      }
      row.a(local_column[col]) = crs.values[k];
    }
    c.noalias() += row.f * row.f.transpose();
    if (row.point < 0) continue;
    const int ne = static_cast<int>(row.a.size());
    auto [a_it, a_new] = a_blocks.try_emplace(row.point, Eigen::MatrixXd::Zero(ne, ne));
    auto [b_it, b_new] = b_blocks.try_emplace(row.point, Eigen::MatrixXd::Zero(ne, n_other));
    a_it->second.noalias() += row.a * row.a.transpose();
    b_it->second.noalias() += row.a * row.f.transpose();
  }
  // A_e^+ (pseudo-inverse: a point seen by too few rows stays undetermined, not infinite).
  auto pseudo_inverse = [](const Eigen::MatrixXd& m) {
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(m);
    const double max_eig = eig.eigenvalues().cwiseAbs().maxCoeff();
    Eigen::VectorXd inv = eig.eigenvalues();
    for (int i = 0; i < inv.size(); ++i) inv(i) = inv(i) > 1e-12 * max_eig ? 1.0 / inv(i) : 0.0;
    return Eigen::MatrixXd(eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose());
  };
  std::map<int, Eigen::MatrixXd> a_inverse;
  Eigen::MatrixXd s = c;
  for (const auto& [block, a] : a_blocks) {
    a_inverse[block] = pseudo_inverse(a);
    const Eigen::MatrixXd& b = b_blocks[block];
    s.noalias() -= b.transpose() * a_inverse[block] * b;
  }
  const Eigen::MatrixXd s_inverse = n_other > 0 ? pseudo_inverse(s) : Eigen::MatrixXd();
  std::set<ResidualId> wanted(ids.begin(), ids.end());
  struct ClusterRows {
    std::vector<ResidualId> residuals;
    std::vector<Eigen::VectorXd> a, t, d;
  };
  std::map<int, ClusterRows> cluster_rows;
  for (int r = 0; r < crs.num_rows; ++r) {
    if (!wanted.count(owner[r])) continue;
    const Row& row = rows[r];
    double h = 0.0;
    Eigen::VectorXd d = -row.f;
    Eigen::VectorXd t;
    if (row.point >= 0) {
      t = a_inverse[row.point] * row.a;  // A_e symmetric: (a A_e^-1)^T
      h += t.dot(row.a);
      d.noalias() += b_blocks[row.point].transpose() * t;
    }
    if (n_other > 0) h += d.dot(s_inverse * d);
    (*out)[owner[r]].push_back(std::max(0.0, 1.0 - h));
    if (clusters && row.point >= 0) {
      ClusterRows& c = cluster_rows[row.point];
      if (c.residuals.empty() || c.residuals.back() != owner[r]) c.residuals.push_back(owner[r]);
      c.a.push_back(row.a);
      c.t.push_back(t);
      c.d.push_back(d);
    }
  }
  for (const auto& [point, c] : cluster_rows) {
    ResidualCluster cluster;
    cluster.point = free_blocks[point];
    cluster.residuals = c.residuals;
    const int m = static_cast<int>(c.a.size());
    cluster.qvv = Eigen::MatrixXd::Identity(m, m);
    for (int i = 0; i < m; ++i) {
      const Eigen::VectorXd sd = n_other > 0 ? Eigen::VectorXd(s_inverse * c.d[i]) : Eigen::VectorXd();
      for (int k = 0; k < m; ++k)
        cluster.qvv(i, k) -= c.t[i].dot(c.a[k]) + (n_other > 0 ? sd.dot(c.d[k]) : 0.0);
    }
    clusters->push_back(std::move(cluster));
  }
  return true;
}

bool ProblemBuilder::ReduceNormalEquations(ReducedSystem* out) const {
  ReducedSystem& r = *out;
  r.free_blocks = FreeBlocksInOrder();
  // Tangent columns: eliminable blocks -> point index space, the others -> reduced space.
  std::vector<int> column_space, column_index, column_block;
  for (BlockId id : r.free_blocks) {
    const int t = blocks_[id].TangentSize();
    const bool elim = blocks_[id].Eliminable();
    r.offset[id] = elim ? r.n_p : r.n_r;
    for (int k = 0; k < t; ++k) {
      column_space.push_back(elim ? 0 : 1);
      column_index.push_back(elim ? r.n_p + k : r.n_r + k);
      column_block.push_back(id);
    }
    if (!elim)
      for (int e : blocks_[id].FreeEntries()) r.reduced_names.push_back(blocks_[id].EntryName(e));
    (elim ? r.n_p : r.n_r) += t;
  }
  if (r.n_p == 0 || r.n_r == 0) return false;
  ceres::Problem::EvaluateOptions eval;
  for (BlockId id : r.free_blocks) eval.parameter_blocks.push_back(blocks_[id].values);
  eval.apply_loss_function = true;
  ceres::CRSMatrix crs;
  double cost = 0.0;
  if (!problem_->Evaluate(eval, &cost, nullptr, nullptr, &crs)) return false;
  using Sparse = Eigen::SparseMatrix<double>;
  std::vector<Eigen::Triplet<double>> tp, tr;
  for (int row = 0; row < crs.num_rows; ++row) {
    BlockId point = -1;
    for (int k = crs.rows[row]; k < crs.rows[row + 1]; ++k) {
      const int col = crs.cols[k];
      if (column_space[col] == 0) {
        if (point >= 0 && point != column_block[col]) return false;  // two points in one residual
        point = column_block[col];
        tp.emplace_back(row, column_index[col], crs.values[k]);
      } else {
        tr.emplace_back(row, column_index[col], crs.values[k]);
      }
    }
  }
  Sparse jp(crs.num_rows, r.n_p), jr(crs.num_rows, r.n_r);
  jp.setFromTriplets(tp.begin(), tp.end());
  jr.setFromTriplets(tr.begin(), tr.end());
  // Block-diagonal N_pp^-1 (one small block per point); a singular block is listed and left out.
  const Sparse npp = Sparse(jp.transpose()) * jp;
  std::vector<Eigen::Triplet<double>> ti;
  for (BlockId id : r.free_blocks) {
    if (!blocks_[id].Eliminable()) continue;
    const int o = r.offset[id], t = blocks_[id].TangentSize();
    Eigen::MatrixXd block = Eigen::MatrixXd(npp.block(o, o, t, t));
    Eigen::LDLT<Eigen::MatrixXd> ldlt(block);
    if (ldlt.info() != Eigen::Success ||
        !(ldlt.vectorD().minCoeff() > 1e-12 * ldlt.vectorD().maxCoeff())) {
      r.singular_points.push_back(id);
      continue;
    }
    const Eigen::MatrixXd inverse = ldlt.solve(Eigen::MatrixXd::Identity(t, t));
    for (int i = 0; i < t; ++i)
      for (int k = 0; k < t; ++k) ti.emplace_back(o + i, o + k, inverse(i, k));
  }
  Sparse npp_inverse(r.n_p, r.n_p);
  npp_inverse.setFromTriplets(ti.begin(), ti.end());
  const Sparse npr = Sparse(jp.transpose()) * jr;
  r.s = Sparse(Sparse(jr.transpose()) * jr) - Sparse(Sparse(npr.transpose()) * npp_inverse) * npr;
  return true;
}

bool ProblemBuilder::SchurCovariance(
    const std::vector<std::pair<BlockId, BlockId>>& pairs,
    std::map<std::pair<BlockId, BlockId>, Eigen::MatrixXd>* out) const {
  for (const auto& [a, b] : pairs)
    if (blocks_[a].Eliminable() || blocks_[b].Eliminable()) return false;
  ReducedSystem reduced;
  if (!ReduceNormalEquations(&reduced) || !reduced.singular_points.empty()) return false;
  using Sparse = Eigen::SparseMatrix<double>;
  const Sparse& s = reduced.s;
  const int n_r = reduced.n_r;
  std::map<BlockId, int>& offset = reduced.offset;
  Eigen::SimplicialLDLT<Sparse> solver(s);
  if (solver.info() != Eigen::Success ||
      !(solver.vectorD().minCoeff() > 1e-14 * solver.vectorD().maxCoeff()))
    return false;
  auto plus_jacobian = [&](BlockId id) {
    const Block& block = blocks_[id];
    const ceres::Manifold* manifold = problem_->GetManifold(block.values);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> j(block.size,
                                                                             block.TangentSize());
    if (manifold)
      manifold->PlusJacobian(block.values, j.data());
    else
      j.setIdentity();
    return Eigen::MatrixXd(j);
  };
  // Columns of S^-1 one block at a time (memory n_r x block size), then the ambient blocks
  // P_a Q(a, b) P_b^T of every pair with that block as its column side.
  std::map<BlockId, std::vector<BlockId>> rows_of_column;
  for (const auto& [a, b] : pairs) rows_of_column[b].push_back(a);
  for (const auto& [b, rows] : rows_of_column) {
    const int t = blocks_[b].TangentSize();
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n_r, t);
    for (int k = 0; k < t; ++k) rhs(offset[b] + k, k) = 1.0;
    const Eigen::MatrixXd columns = solver.solve(rhs);
    const Eigen::MatrixXd pb = plus_jacobian(b);
    for (BlockId a : rows)
      (*out)[{a, b}] = plus_jacobian(a) * columns.middleRows(offset[a], blocks_[a].TangentSize()) *
                       pb.transpose();
  }
  return true;
}

std::map<ResidualId, std::vector<double>> ProblemBuilder::RedundancyNumbers(
    const std::vector<ResidualId>& ids, int max_dense_parameters) const {
  std::map<ResidualId, std::vector<double>> out;
  const int n_free = NumFreeParameters();
  const int n_obs = NumObservations();
  if (n_obs > n_free && RedundancyNumbersBySchur(ids, max_dense_parameters, &out)) return out;
  if (n_free > max_dense_parameters || n_obs <= n_free) {
    const double mean = n_obs > n_free ? static_cast<double>(n_obs - n_free) / n_obs : 0.0;
    for (ResidualId id : ids) out[id] = std::vector<double>(residuals_.at(id).size, mean);
    return out;
  }
  std::vector<ResidualId> owner;
  const Eigen::MatrixXd j = DenseJacobian(FreeBlocksInOrder(), &owner);
  const Eigen::MatrixXd n = j.transpose() * j;
  // Pseudo-inverse through the eigen-decomposition, robust to a datum defect.
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(n);
  const double max_eig = eig.eigenvalues().maxCoeff();
  Eigen::VectorXd inv = eig.eigenvalues();
  for (int i = 0; i < inv.size(); ++i) inv(i) = inv(i) > 1e-12 * max_eig ? 1.0 / inv(i) : 0.0;
  const Eigen::MatrixXd b = j * eig.eigenvectors();  // rows j_i V
  std::set<ResidualId> wanted(ids.begin(), ids.end());
  for (int row = 0; row < j.rows(); ++row) {
    if (!wanted.count(owner[row])) continue;
    const double h = (b.row(row).array().square() * inv.transpose().array()).sum();
    out[owner[row]].push_back(std::max(0.0, 1.0 - h));
  }
  return out;
}

// Interim (until the sparse selected inversion lands): the Schur path of the redundancy numbers,
// which also gives Q_vv among the rows of one point cluster.
ObservationCofactors ProblemBuilder::ComputeObservationCofactors(const std::vector<ResidualId>& ids,
                                                                 bool with_clusters) const {
  ObservationCofactors out;
  const int n_free = NumFreeParameters();
  const int n_obs = NumObservations();
  if (n_obs > n_free &&
      RedundancyNumbersBySchur(ids, 1 << 30, &out.redundancy, with_clusters ? &out.clusters : nullptr)) {
    out.method = "schur_dense_reduced";
    return out;
  }
  out.redundancy = RedundancyNumbers(ids, 4000);
  out.method = n_free > 4000 ? "mean_r_over_n" : "dense_normal_matrix";
  return out;
}

}  // namespace aerocal::calib
