#include "calib/problem/problem_builder.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/core/log.h"
#include "calib/core/stopwatch.h"
#include "calib/problem/levenberg_marquardt.h"
#include "calib/problem/normal_equations.h"
#include "calib/problem/parallel_for.h"
#include "calib/problem/rotation_manifold.h"
#include "calib/problem/scaled_subset_manifold.h"
#include "calib/problem/smallest_eigenpairs.h"

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

namespace aerocal::calib {

struct ProblemBuilder::Block {
  std::string name;
  double* values = nullptr;
  int size = 0;
  BlockKind kind = BlockKind::kOther;
  std::vector<std::string> entry_names;
  bool constant = false;
  std::vector<bool> entry_fixed;
  int num_residuals = 0;  // residual blocks that use it
  /// The block's manifold (owned by the ceres::Problem), created once per set of free entries
  /// and rescaled in place on every UpdateManifolds() (mutable: set up lazily, see
  /// ProblemBuilder::SettleManifolds).
  mutable ScaledSubsetManifold* manifold = nullptr;
  /// A rotation block (AddRotationBlock): a quaternion of 4 entries with 3 tangent (and 3
  /// reported, entry_names: omega, phi, kappa) entries, its manifold ScaledRotationManifold.
  bool rotation = false;
  mutable ScaledRotationManifold* rotation_manifold = nullptr;

  std::vector<int> FreeEntries() const {
    std::vector<int> out;
    for (int i = 0; i < size; ++i)
      if (!entry_fixed[i]) out.push_back(i);
    return out;
  }
  /// Entries of the tangent space (a rotation block: its 3 increment axes).
  std::vector<int> TangentEntries() const {
    return rotation ? std::vector<int>{0, 1, 2} : FreeEntries();
  }
  int TangentSize() const { return constant ? 0 : static_cast<int>(TangentEntries().size()); }
  /// Entries in a CovarianceReport: a rotation block reports omega, phi, kappa.
  int ReportSize() const { return rotation ? 3 : size; }
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
  // Owned here, not by the ceres::Problem, so that a removed residual can be restored.
  std::unique_ptr<ceres::CostFunction> cost;
  std::unique_ptr<ceres::LossFunction> loss;
  std::vector<BlockId> blocks;
  int size = 0;
  bool active = true;
  bool has_loss = false;
};

struct ProblemBuilder::Factorized {
  long long structure_version = -1;
  bool loss_applied = false;  // a loss function was applied to the Jacobian
  int max_dense = 0;          // max_dense_parameters of the inverse
  std::vector<double> values;
  std::vector<BlockId> free_blocks;
  std::vector<int> first_row;
  std::unique_ptr<internal::SchurComplement> schur;
  internal::SelectedInverse inverse;
  bool inverse_ok = false;
  // Pending (schur not built yet): aerocal's engine at the end of a solve without loss functions,
  // its Jacobian and reduced system at the solution. Factorize builds the Schur complement from
  // them instead of evaluating and reducing again when the state is still the same (issue 31).
  std::unique_ptr<internal::ResidualEvaluator> evaluator;
  std::unique_ptr<internal::ReducedSystem> system;
};

const ResidualGroupStats* SolveReport::Group(const std::string& name) const {
  for (const auto& g : groups)
    if (g.name == name) return &g;
  return nullptr;
}

Eigen::MatrixXd CovarianceReport::BlockCovariance(BlockId id, int size) const {
  const auto it = blocks.find({id, id});
  return it == blocks.end() ? Eigen::MatrixXd::Zero(size, size) : it->second;
}

Eigen::VectorXd CovarianceReport::BlockSigma(BlockId id, int size) const {
  return sigma.segment(offsets.at(id), size);
}

bool CovarianceReport::CrossCovariance(BlockId a, BlockId b, Eigen::MatrixXd* out) const {
  const auto it = blocks.find({std::min(a, b), std::max(a, b)});
  if (it == blocks.end()) return false;
  *out = a <= b ? it->second : Eigen::MatrixXd(it->second.transpose());
  return true;
}

double CovarianceReport::Correlation(int i, int k) const {
  if (i == k) return 1.0;
  if (!(sigma(i) > 0 && sigma(k) > 0)) return 0.0;
  const BlockId a = entry_block[i], b = entry_block[k];
  const auto it = blocks.find({std::min(a, b), std::max(a, b)});
  if (it == blocks.end()) return 0.0;
  const double c = a <= b ? it->second(entry_local[i], entry_local[k])
                          : it->second(entry_local[k], entry_local[i]);
  return c / (sigma(i) * sigma(k));
}

double NormalCriticalValue(double alpha) {
  // Solve erfc(z / sqrt 2) = alpha by bisection (monotone) down to adjacent doubles (~55 halvings
  // of [0, 40]). Once lo and hi are adjacent the midpoint rounds to one of them and every further
  // halving returns that same midpoint, so stopping there gives the same bits as bisecting on. Data
  // snooping calls this once per observation (its w of two components as a normal value).
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (mid == lo || mid == hi) return mid;
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
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_ = std::make_unique<ceres::Problem>(options);
}

ProblemBuilder::~ProblemBuilder() { problem_.reset(); }  // before the residuals it points to

std::vector<double> ProblemBuilder::ValuesSnapshot() const {
  std::vector<double> out;
  for (const Block& b : blocks_) out.insert(out.end(), b.values, b.values + b.size);
  return out;
}

void ProblemBuilder::RestoreValues(const std::vector<double>& snapshot) {
  size_t at = 0;
  for (const Block& b : blocks_) {
    const size_t size = static_cast<size_t>(b.size);
    AEROCAL_CHECK(at + size <= snapshot.size()) << "RestoreValues: snapshot of another builder";
    std::copy(snapshot.begin() + at, snapshot.begin() + at + size, b.values);
    at += size;
  }
  AEROCAL_CHECK(at == snapshot.size()) << "RestoreValues: snapshot of another builder";
}

namespace {

// The Schur system's columns (the free blocks in order: tangent size, eliminable) and each active
// residual's first row (-1 inactive). Templated on the builder's private block and residual types.
template <typename Blocks, typename Residuals>
internal::ColumnBlocks SchurLayout(const Blocks& blocks,
                                   const std::vector<BlockId>& free_blocks,
                                   const Residuals& residuals,
                                   std::vector<int>* first_row) {
  internal::ColumnBlocks columns;
  for (BlockId id : free_blocks) {
    columns.size.push_back(blocks[id].TangentSize());
    columns.eliminable.push_back(blocks[id].Eliminable());
  }
  first_row->assign(residuals.size(), -1);
  int row = 0;
  for (size_t i = 0; i < residuals.size(); ++i) {
    if (!residuals[i].active) continue;
    (*first_row)[i] = row;
    row += residuals[i].size;
  }
  return columns;
}

}  // namespace

void ProblemBuilder::ReleaseFactorized() const { factorized_.reset(); }

const ProblemBuilder::Factorized* ProblemBuilder::Factorize(bool apply_loss,
                                                            int max_dense_parameters) const {
  SettleManifolds();
  // With no loss function on an active residual, applying the loss changes nothing.
  bool any_loss = false;
  for (const Residual& r : residuals_) any_loss = any_loss || (r.active && r.has_loss);
  const bool loss_applied = apply_loss && any_loss;
  std::vector<double> values = ValuesSnapshot();
  if (factorized_ && factorized_->schur && factorized_->structure_version == structure_version_ &&
      factorized_->loss_applied == loss_applied && factorized_->values == values &&
      ((factorized_->inverse_ok && !factorized_->inverse.singular()) ||
       factorized_->max_dense == max_dense_parameters))
    return factorized_.get();
  std::unique_ptr<Factorized> f = std::move(factorized_);
  // The engine's reduced system at the solution when it is current (no loss function there, so
  // its Jacobian is the loss-free one and S is the loss-free S), else evaluated and reduced here.
  Eigen::SparseMatrix<double> s_lower;
  if (f && f->system && f->structure_version == structure_version_ && f->values == values &&
      f->system->UndampedLower(*f->evaluator, &s_lower)) {
    f->system.reset();  // each part freed as soon as it is copied: the statistics' peak memory
    ceres::CRSMatrix jacobian = f->evaluator->TangentJacobian();
    f->evaluator.reset();
    f->free_blocks = FreeBlocksInOrder();
    f->schur = std::make_unique<internal::SchurComplement>(
        std::move(jacobian),
        SchurLayout(blocks_, f->free_blocks, residuals_, &f->first_row),
        std::move(s_lower));
  } else {
    f = std::make_unique<Factorized>();
    f->schur = BuildSchurComplement(loss_applied, &f->free_blocks, &f->first_row);
  }
  if (!f->schur) return nullptr;
  f->structure_version = structure_version_;
  f->loss_applied = loss_applied;
  f->max_dense = max_dense_parameters;
  f->values = std::move(values);
  f->inverse_ok =
      f->inverse.Compute(f->schur->s_lower(), dense_inverse_limit_, max_dense_parameters);
  factorized_ = std::move(f);
  return factorized_.get();
}

ceres::Problem& ProblemBuilder::problem() {
  SettleManifolds();  // the caller may read the manifolds of entries fixed since the last use
  return *problem_;
}

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
  const BlockId id = static_cast<BlockId>(blocks_.size());
  blocks_.push_back(std::move(block));
  block_by_name_[name] = id;
  block_by_pointer_[values] = id;
  problem_->AddParameterBlock(values, size);
  ++structure_version_;
  return id;
}

BlockId ProblemBuilder::AddRotationBlock(const std::string& name,
                                         double* quaternion,
                                         std::vector<std::string> report_names) {
  AEROCAL_CHECK(report_names.size() == 3) << "rotation block " << name << " needs 3 names";
  AEROCAL_CHECK(quaternion != nullptr) << "rotation block " << name;
  const double norm = std::sqrt(quaternion[0] * quaternion[0] + quaternion[1] * quaternion[1] +
                                quaternion[2] * quaternion[2] + quaternion[3] * quaternion[3]);
  AEROCAL_CHECK(std::abs(norm - 1.0) < 1e-9)
      << "rotation block " << name << " is not a unit quaternion (norm " << norm << ")";
  const BlockId id = AddBlock(name, quaternion, 4, BlockKind::kRotation);
  blocks_[id].rotation = true;
  blocks_[id].entry_names = std::move(report_names);
  return id;
}

BlockId ProblemBuilder::FindBlock(const std::string& name) const {
  const auto it = block_by_name_.find(name);
  return it == block_by_name_.end() ? -1 : it->second;
}

void ProblemBuilder::FixBlock(BlockId id) {
  ++structure_version_;
  blocks_.at(id).constant = true;
  problem_->SetParameterBlockConstant(blocks_[id].values);
}

void ProblemBuilder::FreeBlock(BlockId id) {
  ++structure_version_;
  Block& b = blocks_.at(id);
  b.constant = std::all_of(b.entry_fixed.begin(), b.entry_fixed.end(), [](bool f) { return f; });
  if (!b.constant) problem_->SetParameterBlockVariable(b.values);
}

void ProblemBuilder::FixEntries(BlockId id, const std::vector<int>& entries) {
  ++structure_version_;
  Block& b = blocks_.at(id);
  AEROCAL_CHECK(!b.rotation || entries.empty() || static_cast<int>(entries.size()) == b.size)
      << "rotation block " << b.name << " is fixed as a whole or not at all";
  for (int e : entries) {
    AEROCAL_CHECK(e >= 0 && e < b.size) << "entry " << e << " of block " << b.name;
    b.entry_fixed[e] = true;
  }
  if (b.FreeEntries().empty()) {
    FixBlock(id);
    return;
  }
  // In force at the next use (Solve, covariance, cofactors, null space, problem()), not here: the
  // update evaluates the whole problem's Jacobian, and a caller fixing one entry per point (the
  // rig stitching's tie heights) paid one whole-problem evaluation per point, quadratic in the
  // points.
  manifolds_stale_ = true;
}

void ProblemBuilder::SettleManifolds() const {
  if (manifolds_stale_) UpdateManifolds();
}

bool ProblemBuilder::IsBlockFixed(BlockId id) const { return blocks_.at(id).constant; }
int ProblemBuilder::BlockSize(BlockId id) const { return blocks_.at(id).size; }
const std::string& ProblemBuilder::BlockName(BlockId id) const { return blocks_.at(id).name; }
BlockKind ProblemBuilder::BlockKindOf(BlockId id) const { return blocks_.at(id).kind; }
const std::vector<BlockId>& ProblemBuilder::ResidualBlocks(ResidualId id) const {
  return residuals_.at(id).blocks;
}
int ProblemBuilder::NumResiduals() const { return static_cast<int>(residuals_.size()); }
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
  r.has_loss = loss_function != nullptr;
  r.cost = std::move(cost);
  r.loss.reset(loss_function);
  r.id = problem_->AddResidualBlock(r.cost.get(), loss_function, pointers);
  ++structure_version_;
  for (BlockId b : blocks) ++blocks_[b].num_residuals;
  residuals_.push_back(std::move(r));
  return static_cast<ResidualId>(residuals_.size() - 1);
}

void ProblemBuilder::RemoveResidual(ResidualId id) {
  Residual& r = residuals_.at(id);
  if (!r.active) return;
  problem_->RemoveResidualBlock(r.id);
  r.active = false;
  ++structure_version_;
  for (BlockId b : r.blocks) --blocks_[b].num_residuals;
}

void ProblemBuilder::RestoreResidual(ResidualId id) {
  Residual& r = residuals_.at(id);
  if (r.active) return;
  std::vector<double*> pointers;
  for (BlockId b : r.blocks) pointers.push_back(blocks_.at(b).values);
  r.id = problem_->AddResidualBlock(r.cost.get(), r.loss.get(), pointers);
  r.active = true;
  ++structure_version_;
  for (BlockId b : r.blocks) ++blocks_[b].num_residuals;
}

bool ProblemBuilder::IsActive(ResidualId id) const { return residuals_.at(id).active; }

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
  SettleManifolds();
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

bool ProblemBuilder::RotationManifoldsSet() const {
  for (BlockId id : FreeBlocksInOrder())
    if (blocks_[id].rotation && blocks_[id].rotation_manifold == nullptr) return false;
  return true;
}

bool ProblemBuilder::UpdateManifolds() const {
  // Tangent scaling: unit Jacobian columns at the current values (scaled_subset_manifold.h).
  // One manifold per block: a new one only when its free entries change (Ceres keeps every
  // manifold it was given until the problem dies), otherwise rescaled in place.
  ++structure_version_;  // the scales change the tangent space of a kept factorisation
  manifolds_stale_ = false;
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  for (BlockId id : free_blocks) {
    const Block& b = blocks_[id];
    if (b.rotation) {
      if (b.rotation_manifold != nullptr) {
        b.rotation_manifold->SetScales({1.0, 1.0, 1.0});
        continue;
      }
      b.rotation_manifold = new ScaledRotationManifold();
      problem_->SetManifold(b.values, b.rotation_manifold);
      continue;
    }
    const auto free = b.FreeEntries();
    if (b.manifold != nullptr && b.manifold->free_entries() == free) {
      b.manifold->SetScales(std::vector<double>(free.size(), 1.0));
      continue;
    }
    b.manifold = new ScaledSubsetManifold(b.size, free, std::vector<double>(free.size(), 1.0));
    problem_->SetManifold(b.values, b.manifold);
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
    const Block& b = blocks_[id];
    const size_t n_free = b.TangentEntries().size();
    std::vector<double> scales;
    for (size_t k = 0; k < n_free; ++k, ++col)
      scales.push_back(norm2[col] > 0 ? 1.0 / std::sqrt(norm2[col]) : 1.0);
    if (b.rotation)
      b.rotation_manifold->SetScales({scales[0], scales[1], scales[2]});
    else
      b.manifold->SetScales(std::move(scales));
  }
  return true;
}

std::unique_ptr<ceres::Problem> ProblemBuilder::CopyInBlockOrder(std::vector<double>* buffer,
                                                                 std::vector<double*>* pointers,
                                                                 bool all) const {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // problem_ owns them
  auto mirror = std::make_unique<ceres::Problem>(options);
  size_t total = 0;
  for (const Block& b : blocks_)
    if (all || b.Eliminable()) total += b.size;
  buffer->assign(total, 0.0);  // never resized below: the pointers into it stay valid
  pointers->assign(blocks_.size(), nullptr);
  size_t offset = 0;
  for (size_t id = 0; id < blocks_.size(); ++id) {
    const Block& b = blocks_[id];
    double* values = b.values;
    if (all || b.Eliminable()) {
      values = buffer->data() + offset;
      std::copy(b.values, b.values + b.size, values);
      offset += b.size;
    }
    (*pointers)[id] = values;
    mirror->AddParameterBlock(
        values, b.size, const_cast<ceres::Manifold*>(problem_->GetManifold(b.values)));
    if (problem_->IsParameterBlockConstant(b.values)) mirror->SetParameterBlockConstant(values);
  }
  for (const Residual& r : residuals_) {
    if (!r.active) continue;
    std::vector<double*> blocks;
    for (BlockId id : r.blocks) blocks.push_back((*pointers)[id]);
    mirror->AddResidualBlock(r.cost.get(), r.loss.get(), blocks);
  }
  return mirror;
}

namespace {

// Ceres' options from ours: tolerances, threads (one when deterministic), the iteration log.
ceres::Solver::Options BaseCeresOptions(const SolverOptions& options) {
  ceres::Solver::Options ceres_options;
  ceres_options.max_num_iterations = options.max_iterations;
  ceres_options.function_tolerance = options.function_tolerance;
  ceres_options.gradient_tolerance = options.gradient_tolerance;
  ceres_options.parameter_tolerance = options.parameter_tolerance;
  ceres_options.num_threads =
      options.deterministic ? 1 : internal::ResolveThreads(options.num_threads);
  // The solver's iterations: asked for by the caller, or by the command line's --verbose.
  const bool verbose = options.verbose || GetLogLevel() == LogLevel::kInfo;
  ceres_options.minimizer_progress_to_stdout = verbose;
  ceres_options.logging_type = verbose ? ceres::PER_MINIMIZER_ITERATION : ceres::SILENT;

  return ceres_options;
}

// What Ceres' summary says of the solve: termination, iterations, costs, where the time went.
void CopyCeresSummary(const ceres::Solver::Summary& summary, SolveReport* report) {
  report->termination = ceres::TerminationTypeToString(summary.termination_type);
  report->message = summary.message;
  report->converged = summary.termination_type == ceres::CONVERGENCE;
  report->usable = summary.IsSolutionUsable();
  report->iterations =
      std::max(0, static_cast<int>(summary.iterations.size()) - 1);  // [0] is the start
  report->initial_cost = summary.initial_cost;
  report->final_cost = summary.final_cost;
  report->evaluation_seconds =
      summary.residual_evaluation_time_in_seconds + summary.jacobian_evaluation_time_in_seconds;
  report->linear_solver_seconds = summary.linear_solver_time_in_seconds;
}

// The linear solver: options.linear_solver, or by the problem's size (kAuto): dense QR for small
// problems, a Schur solver when points can be eliminated beside other parameters (iterative above
// min_iterative_schur_parameters, dense up to max_dense_schur_parameters or without a sparse
// library, else sparse), else sparse normal Cholesky. Sets it in `ceres_options`; returns its name.
std::string SetLinearSolver(const SolverOptions& options,
                            int eliminable_params,
                            int other_params,
                            bool has_eliminable,
                            ceres::Solver::Options* ceres_options_ptr) {
  ceres::Solver::Options& ceres_options = *ceres_options_ptr;
  std::string name;
  const bool sparse_available =
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::SUITE_SPARSE) ||
      ceres::IsSparseLinearAlgebraLibraryTypeAvailable(ceres::EIGEN_SPARSE);
  LinearSolverChoice choice = options.linear_solver;
  if (choice == LinearSolverChoice::kAuto) {
    if (eliminable_params + other_params <= options.max_dense_qr_parameters)
      choice = LinearSolverChoice::kDenseQr;
    else if (has_eliminable && other_params > 0)
      choice = options.min_iterative_schur_parameters > 0 &&
                       other_params > options.min_iterative_schur_parameters
                   ? LinearSolverChoice::kIterativeSchur
               : other_params <= options.max_dense_schur_parameters || !sparse_available
                   ? LinearSolverChoice::kDenseSchur
                   : LinearSolverChoice::kSparseSchur;
    else
      choice = sparse_available ? LinearSolverChoice::kSparseNormalCholesky
                                : LinearSolverChoice::kDenseQr;
  }
  switch (choice) {
    case LinearSolverChoice::kDenseQr:
    case LinearSolverChoice::kAuto:
      ceres_options.linear_solver_type = ceres::DENSE_QR;
      name = "dense_qr";
      break;
    case LinearSolverChoice::kDenseSchur:
      ceres_options.linear_solver_type = ceres::DENSE_SCHUR;
      name = "dense_schur";
      break;
    case LinearSolverChoice::kSparseSchur:
      ceres_options.linear_solver_type = ceres::SPARSE_SCHUR;
      name = "sparse_schur";
      break;
    case LinearSolverChoice::kIterativeSchur:
      ceres_options.linear_solver_type = ceres::ITERATIVE_SCHUR;
      ceres_options.preconditioner_type = ceres::SCHUR_JACOBI;
      name = "iterative_schur";
      break;
    case LinearSolverChoice::kSparseNormalCholesky:
      ceres_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
      name = "sparse_normal_cholesky";
      break;
  }
  return name;
}

}  // namespace

SolveReport ProblemBuilder::Solve(const SolverOptions& options) {
  const Stopwatch solve_time;
  ReleaseFactorized();  // stale after the solve; its memory is the solver's now
  SolveReport report;
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  if (!UpdateManifolds())
    report.diagnostics.push_back(
        "the residuals cannot be evaluated at the starting values (a point behind a camera?)");

  ceres::Solver::Options ceres_options = BaseCeresOptions(options);
  std::unique_ptr<ceres::Problem> mirror;  // the Schur solve's problem (see the ordering below)
  std::vector<double> mirror_buffer;
  std::vector<double*> mirror_pointers;
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
  report.linear_solver = SetLinearSolver(
      options, eliminable_params, other_params, !eliminable.empty(), &ceres_options);
  if (report.diagnostics.empty() &&
      SolveWithAerocal(options, ceres_options.linear_solver_type, free_blocks, &report)) {
    report.seconds = solve_time.Seconds();
    return report;
  }
  if (ceres_options.linear_solver_type == ceres::DENSE_SCHUR ||
      ceres_options.linear_solver_type == ceres::SPARSE_SCHUR ||
      ceres_options.linear_solver_type == ceres::ITERATIVE_SCHUR) {
    if (eliminable.empty() || other_params == 0) {
      ceres_options.linear_solver_type = ceres::DENSE_QR;
      report.linear_solver = "dense_qr";
    } else {
      // Ceres orders the blocks of one group by their memory address (a std::set<double*>), so
      // with all non-eliminated blocks in one group the reduced system's layout, and its rounding,
      // depended on where the owners' vectors happened to be allocated: a second adjustment in the
      // same process (flight, the Python module) differed from a fresh one in the last digits.
      // Each non-eliminated block gets its own group, in BlockId (registration) order. The
      // eliminated points share group 0 (Ceres eliminates the first group only) and are summed
      // into the reduced system in their address order: with several owners (the block's ground
      // points, a sub-image camera's virtual tie points in a deque) that order followed the heap's
      // history, and `aerocal batch merge` differed from `aerocal flight` in the joint step's last
      // digits. So the solve runs on a copy whose eliminated blocks lie in one buffer in BlockId
      // order (CopyInBlockOrder), and the solution is copied back.
      mirror = CopyInBlockOrder(&mirror_buffer, &mirror_pointers);
      auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
      int group = 0;
      for (BlockId id : free_blocks)
        ordering->AddElementToGroup(mirror_pointers[id], blocks_[id].Eliminable() ? 0 : ++group);
      ceres_options.linear_solver_ordering = ordering;
    }
  }

  ceres::Solver::Summary summary;
  if (report.diagnostics.empty())
    ceres::Solve(ceres_options, mirror ? mirror.get() : problem_.get(), &summary);
  if (mirror)
    for (BlockId id = 0; id < static_cast<BlockId>(blocks_.size()); ++id)
      if (mirror_pointers[id] != blocks_[id].values)
        std::copy(mirror_pointers[id], mirror_pointers[id] + blocks_[id].size, blocks_[id].values);

  CopyCeresSummary(summary, &report);
  FinishSolveReport(&report);
  report.seconds = solve_time.Seconds();
  return report;
}

void ProblemBuilder::FinishSolveReport(SolveReport* report) const {
  AddSolveStatistics(report);
  if (!report->converged)
    report->diagnostics.push_back("the adjustment did not converge: " + report->message);
  for (BlockId id = 0; id < static_cast<BlockId>(blocks_.size()); ++id)
    if (!blocks_[id].constant && blocks_[id].num_residuals == 0)
      report->diagnostics.push_back("block " + blocks_[id].name + " has no observations");
}

bool ProblemBuilder::SolveWithAerocal(const SolverOptions& options,
                                      ceres::LinearSolverType chosen,
                                      const std::vector<BlockId>& free_blocks,
                                      SolveReport* report) {
  // The engine takes the place of Ceres' dense and sparse Schur solvers, factorising the reduced
  // system as the chosen one would.
  if (options.engine != SolverEngine::kAerocal ||
      (chosen != ceres::DENSE_SCHUR && chosen != ceres::SPARSE_SCHUR))
    return false;
  const int max_dense = chosen == ceres::DENSE_SCHUR ? std::numeric_limits<int>::max() : -1;
  std::vector<int> free_index(blocks_.size(), -1);
  std::vector<internal::FreeBlock> free;
  for (BlockId id : free_blocks) {
    const Block& b = blocks_[id];
    free_index[id] = static_cast<int>(free.size());
    free.push_back(
        {b.values, b.size, b.TangentSize(), problem_->GetManifold(b.values), b.Eliminable()});
  }
  std::vector<internal::ResidualTerm> terms;
  for (const Residual& r : residuals_) {
    if (!r.active) continue;
    internal::ResidualTerm t{r.cost.get(), r.loss.get(), {}, {}};
    for (BlockId id : r.blocks) {
      t.free.push_back(free_index[id]);
      t.constant.push_back(blocks_[id].values);
    }
    terms.push_back(std::move(t));
  }
  bool any_loss = false;
  for (const internal::ResidualTerm& t : terms) any_loss = any_loss || t.loss != nullptr;
  auto evaluator = std::make_unique<internal::ResidualEvaluator>(
      std::move(free), std::move(terms), internal::ResolveThreads(options.num_threads));
  auto system = internal::ReducedSystem::Create(*evaluator, max_dense);
  if (system == nullptr) return false;
  internal::LmOptions lm{options.max_iterations,
                         options.function_tolerance,
                         options.gradient_tolerance,
                         options.parameter_tolerance};
  const internal::LmSummary summary =
      internal::MinimizeLevenbergMarquardt(lm, evaluator.get(), system.get());
  report->linear_solver = system->dense() ? "dense_schur" : "sparse_schur";
  report->termination = summary.termination;
  report->message = summary.message;
  report->converged = summary.converged;
  report->usable = summary.usable;
  report->iterations = summary.iterations;
  report->initial_cost = summary.initial_cost;
  report->final_cost = summary.final_cost;
  report->evaluation_seconds = summary.evaluation_seconds;
  report->linear_solver_seconds = summary.linear_solver_seconds;
  FinishSolveReport(report);
  // Kept for the statistics at this solution (the evaluator's Jacobian is the one at the returned
  // values: the minimiser linearises at every accepted state and ends on one).
  if (summary.usable && !any_loss) {
    system->ReleaseFactor();
    factorized_ = std::make_unique<Factorized>();
    factorized_->structure_version = structure_version_;
    factorized_->values = ValuesSnapshot();
    factorized_->evaluator = std::move(evaluator);
    factorized_->system = std::move(system);
  }
  return true;
}

void ProblemBuilder::AddSolveStatistics(SolveReport* report_ptr) const {
  SolveReport& report = *report_ptr;
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
}

namespace {
// The smallest eigenpairs of the Jacobi-scaled reduced matrix that NullSpace reports: the 16
// smallest and every one below `relative_threshold` x the largest (the count doubled while all
// of those found are below it). Iterative (smallest_eigenpairs.h) above `dense_limit` rows, dense
// at or below it and wherever the iteration fails.
internal::SymmetricEigenpairs SmallestNullSpaceEigenpairs(const Eigen::SparseMatrix<double>& m,
                                                          double relative_threshold,
                                                          int dense_limit) {
  const int n = static_cast<int>(m.rows());
  for (int count = std::min(n, 16);; count = std::min(n, 2 * count)) {
    const internal::SymmetricEigenpairs eig = internal::SmallestEigenpairs(m, count, dense_limit);
    if (!eig.ok) return internal::DenseEigenpairs(m);
    const int below =
        static_cast<int>((eig.values.array() <= relative_threshold * eig.largest).count());
    if (below < count || count == n) return eig;
  }
}

// The names of the parameters that the eigenvectors of (Jacobi-scaled) `lower` with eigenvalues
// below 1e-12 of the largest involve (|component| > 0.2); the smallest eigenpairs only.
std::set<std::string> NullSpaceNames(const Eigen::SparseMatrix<double>& lower,
                                     const std::vector<std::string>& names,
                                     int dense_limit) {
  Eigen::VectorXd d = lower.diagonal().cwiseSqrt();
  for (int i = 0; i < d.size(); ++i) d(i) = d(i) > 0 ? 1.0 / d(i) : 1.0;
  const Eigen::SparseMatrix<double> m = d.asDiagonal() * lower * d.asDiagonal();
  const internal::SymmetricEigenpairs eig = SmallestNullSpaceEigenpairs(m, 1e-12, dense_limit);
  std::set<std::string> out;
  for (int k = 0; k < eig.values.size(); ++k) {
    if (eig.values(k) > 1e-12 * eig.largest) break;  // ascending order
    const Eigen::VectorXd v = eig.vectors.col(k);
    for (int i = 0; i < v.size(); ++i)
      if (std::abs(v(i)) > 0.2) out.insert(names[i]);
  }
  return out;
}

// Up to this many free parameters the covariance is Ceres' (dense SVD).
constexpr int kCeresCovarianceLimit = 300;
}  // namespace

std::unique_ptr<internal::SchurComplement> ProblemBuilder::BuildSchurComplement(
    bool apply_loss, std::vector<BlockId>* free_blocks, std::vector<int>* first_row) const {
  SettleManifolds();
  *free_blocks = FreeBlocksInOrder();
  const internal::ColumnBlocks columns = SchurLayout(blocks_, *free_blocks, residuals_, first_row);
  ceres::Problem::EvaluateOptions eval;
  for (BlockId id : *free_blocks) eval.parameter_blocks.push_back(blocks_[id].values);
  for (const Residual& r : residuals_)
    if (r.active) eval.residual_blocks.push_back(r.id);
  eval.apply_loss_function = apply_loss;
  ceres::CRSMatrix crs;
  double cost = 0.0;
  if (!problem_->Evaluate(eval, &cost, nullptr, nullptr, &crs)) return nullptr;
  return std::make_unique<internal::SchurComplement>(std::move(crs), columns);
}

namespace {

/// Redundancy numbers and point clusters from the reduced system and its (selected) inverse,
/// one group of residuals at a time: the residuals observing one point (the block index in the
/// Schur system) together, the others one by one. H = J N^- J^T over a group's rows:
///   h_ij = a_i A^+ a_j^T + d_i^T S^- d_j,  d_i = B^T A^+ a_i - f_i  (normal_equations.h),
/// and Q_vv = I - H for the whitened residuals.
class CofactorAssembly {
 public:
  CofactorAssembly(const internal::SchurComplement& schur,
                   const internal::SelectedInverse& inverse,
                   const std::vector<int>& first_row,
                   const std::vector<BlockId>& free_blocks,
                   std::function<int(ResidualId)> size_of,
                   bool with_clusters,
                   ObservationCofactors* out)
      : schur_(schur),
        inverse_(inverse),
        first_row_(first_row),
        free_blocks_(free_blocks),
        size_of_(std::move(size_of)),
        with_clusters_(with_clusters),
        out_(out) {}

  /// The residuals observing eliminated point `point`: a_i from the point's columns, f_i and
  /// S^- on the reduced columns the point couples to.
  void AddPointGroup(int point, const std::vector<ResidualId>& group) {
    const internal::SchurComplement::PointTerms t = schur_.Point(point);
    Eigen::MatrixXd f;
    ReducedParts(group, t.cols, &f);
    Eigen::MatrixXd a(t.a_pinv.rows(), f.cols());
    int c = 0;
    for (ResidualId id : group)
      for (int k = 0; k < size_of_(id); ++k, ++c)
        a.col(c) = schur_.RowPointPart(first_row_[id] + k);
    const Eigen::MatrixXd ta = t.a_pinv * a;
    Eigen::MatrixXd h = a.transpose() * ta;
    if (!t.cols.empty()) {
      const Eigen::MatrixXd d = t.b.transpose() * ta - f;
      h.noalias() += d.transpose() * inverse_.Gather(t.cols, t.cols) * d;
    }
    Store(group, h, point);
  }

  /// A residual that observes no point: h = f^T S^- f over the reduced columns it touches.
  void AddSingle(ResidualId id) {
    std::vector<int> set_cols;
    for (int k = 0; k < size_of_(id); ++k) {
      schur_.RowReduced(first_row_[id] + k, &cols_, &vals_);
      set_cols.insert(set_cols.end(), cols_.begin(), cols_.end());
    }
    std::sort(set_cols.begin(), set_cols.end());
    set_cols.erase(std::unique(set_cols.begin(), set_cols.end()), set_cols.end());
    Eigen::MatrixXd f;
    ReducedParts({id}, set_cols, &f);
    Eigen::MatrixXd h = Eigen::MatrixXd::Zero(f.cols(), f.cols());
    if (!set_cols.empty()) h = f.transpose() * inverse_.Gather(set_cols, set_cols) * f;
    Store({id}, h, -1);
  }

 private:
  /// f: the group's rows of the reduced Jacobian on `set_cols` (sorted), one column per row.
  void ReducedParts(const std::vector<ResidualId>& group,
                    const std::vector<int>& set_cols,
                    Eigen::MatrixXd* f) {
    int m = 0;
    for (ResidualId id : group) m += size_of_(id);
    *f = Eigen::MatrixXd::Zero(set_cols.size(), m);
    int c = 0;
    for (ResidualId id : group)
      for (int k = 0; k < size_of_(id); ++k, ++c) {
        schur_.RowReduced(first_row_[id] + k, &cols_, &vals_);
        for (size_t q = 0; q < cols_.size(); ++q) {
          const auto at = std::lower_bound(set_cols.begin(), set_cols.end(), cols_[q]);
          (*f)(at - set_cols.begin(), c) = vals_[q];
        }
      }
  }

  /// r_ii = (Q_vv)_ii clamped to [0, 1]; with clusters, the symmetrised Q_vv of a point group.
  void Store(const std::vector<ResidualId>& group, const Eigen::MatrixXd& h, int point) {
    const Eigen::MatrixXd qvv = Eigen::MatrixXd::Identity(h.rows(), h.cols()) - h;
    int c = 0;
    for (ResidualId id : group) {
      std::vector<double>& r = out_->redundancy[id];
      for (int k = 0; k < size_of_(id); ++k, ++c) r.push_back(std::clamp(qvv(c, c), 0.0, 1.0));
    }
    if (with_clusters_ && point >= 0) {
      ResidualCluster cluster;
      cluster.point = free_blocks_[point];
      cluster.residuals = group;
      cluster.qvv = 0.5 * (qvv + qvv.transpose());
      out_->clusters.push_back(std::move(cluster));
    }
  }

  const internal::SchurComplement& schur_;
  const internal::SelectedInverse& inverse_;
  const std::vector<int>& first_row_;
  const std::vector<BlockId>& free_blocks_;
  const std::function<int(ResidualId)> size_of_;
  const bool with_clusters_;
  ObservationCofactors* out_;
  std::vector<int> cols_;  // scratch of RowReduced
  std::vector<double> vals_;
};

}  // namespace

ObservationCofactors ProblemBuilder::ComputeObservationCofactors(const std::vector<ResidualId>& ids,
                                                                 bool with_clusters,
                                                                 int max_dense_parameters) const {
  SettleManifolds();
  ObservationCofactors out;
  auto not_computed = [&](const std::string& why) {
    out.ok = false;
    out.method = "not_computed";
    out.message = why;
    out.clusters.clear();
    for (ResidualId id : ids)
      if (residuals_.at(id).active)
        out.redundancy[id] =
            std::vector<double>(residuals_[id].size, std::numeric_limits<double>::quiet_NaN());
    return out;
  };
  const Factorized* factorized = Factorize(false, max_dense_parameters);
  if (!factorized) return not_computed("the residuals cannot be evaluated at the current values");
  const std::vector<BlockId>& free_blocks = factorized->free_blocks;
  const std::vector<int>& first_row = factorized->first_row;
  const internal::SchurComplement* schur = factorized->schur.get();
  const internal::SelectedInverse& inverse = factorized->inverse;
  if (!factorized->inverse_ok) {
    std::string why = inverse.message();
    ReleaseFactorized();  // before the null-space search builds its own system
    const std::vector<std::string> null_space = NullSpaceParameters(3000);
    for (size_t i = 0; i < null_space.size() && i < 20; ++i)
      why += (i ? ", " : " (null space: ") + null_space[i];
    if (!null_space.empty()) why += null_space.size() > 20 ? ", ...)" : ")";
    return not_computed(why);
  }
  bool any_point = false;
  for (size_t b = 0; b < free_blocks.size(); ++b) any_point |= schur->is_point(static_cast<int>(b));
  out.ok = true;
  out.method = std::string(any_point ? "schur_" : "normal_") +
               (inverse.dense() ? "dense_pseudo_inverse" : "selected_inverse");
  out.reduced_parameters = schur->num_reduced();
  out.factor_nonzeros = inverse.factor_nonzeros();
  if (inverse.singular())
    out.message = "the normal matrix is singular (datum defect); Q_vv from its pseudo-inverse";

  // Residuals grouped by the point they observe; the others one by one.
  std::map<int, std::vector<ResidualId>> by_point;
  std::vector<ResidualId> pointless;
  for (ResidualId id : ids) {
    if (!residuals_.at(id).active) continue;
    const int point = schur->RowPoint(first_row[id]);
    if (point >= 0)
      by_point[point].push_back(id);
    else
      pointless.push_back(id);
  }
  CofactorAssembly assembly(
      *schur,
      inverse,
      first_row,
      free_blocks,
      [&](ResidualId id) { return residuals_[id].size; },
      with_clusters,
      &out);
  for (const auto& [point, group] : by_point) assembly.AddPointGroup(point, group);
  for (ResidualId id : pointless) assembly.AddSingle(id);
  return out;
}

std::map<ResidualId, std::vector<double>> ProblemBuilder::RedundancyNumbers(
    const std::vector<ResidualId>& ids, int max_dense_parameters) const {
  return ComputeObservationCofactors(ids, false, max_dense_parameters).redundancy;
}

std::vector<std::string> ProblemBuilder::NullSpaceParameters(int max_parameters) const {
  SettleManifolds();
  if (!RotationManifoldsSet()) return {};  // not solved yet: nothing is known about the rank
  const std::vector<BlockId> free_blocks = FreeBlocksInOrder();
  if (NumFreeParameters() > max_parameters) {
    // Large blocks: the datum defect lives in the exterior / interior parameters; find it in the
    // reduced system (points eliminated), and name points that are undetermined on their own.
    std::vector<BlockId> blocks;
    std::vector<int> first_row;
    const auto schur = BuildSchurComplement(true, &blocks, &first_row);
    if (!schur || !schur->eliminated() || schur->num_reduced() > max_parameters) return {};
    std::vector<std::string> names;
    std::set<std::string> out;
    for (size_t b = 0; b < blocks.size(); ++b) {
      if (schur->is_point(static_cast<int>(b))) {
        if (schur->Point(static_cast<int>(b)).singular) out.insert(blocks_[blocks[b]].name);
        continue;
      }
      for (int e : blocks_[blocks[b]].TangentEntries())
        names.push_back(blocks_[blocks[b]].EntryName(e));
    }
    const std::set<std::string> reduced =
        NullSpaceNames(schur->s_lower(), names, dense_null_space_limit_);
    out.insert(reduced.begin(), reduced.end());
    return {out.begin(), out.end()};
  }
  const Eigen::MatrixXd j = DenseJacobian(free_blocks, nullptr);
  std::vector<std::string> names;
  for (BlockId b : free_blocks)
    for (int e : blocks_[b].TangentEntries()) names.push_back(blocks_[b].EntryName(e));
  const Eigen::SparseMatrix<double> sparse_j = j.sparseView();
  const Eigen::SparseMatrix<double> n =
      (sparse_j.transpose() * sparse_j).triangularView<Eigen::Lower>();
  const std::set<std::string> out = NullSpaceNames(n, names, dense_null_space_limit_);
  return {out.begin(), out.end()};
}

Eigen::MatrixXd ProblemBuilder::PlusJacobianOf(BlockId id) const {
  SettleManifolds();
  const Block& block = blocks_[id];
  const ceres::Manifold* manifold = problem_->GetManifold(block.values);
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> j(block.size,
                                                                           block.TangentSize());
  if (manifold)
    manifold->PlusJacobian(block.values, j.data());
  else
    j.setIdentity();
  return Eigen::MatrixXd(j);
}

NullSpaceReport ProblemBuilder::NullSpace(double relative_threshold, int max_parameters) const {
  SettleManifolds();
  NullSpaceReport report;
  report.threshold = relative_threshold;
  if (!RotationManifoldsSet()) {  // before the first Solve the rotations have no tangent space
    report.message = "the problem has not been solved yet (Solve sets up the rotations' manifolds)";
    return report;
  }
  std::vector<BlockId> free_blocks;
  std::vector<int> first_row;
  const auto schur = BuildSchurComplement(false, &free_blocks, &first_row);
  if (!schur) {
    report.message = "the residuals cannot be evaluated at the current values";
    return report;
  }
  const int n = schur->num_reduced();
  report.reduced_parameters = n;
  if (n > max_parameters) {
    report.message = std::to_string(n) + " reduced parameters, above the dense limit " +
                     std::to_string(max_parameters);
    return report;
  }
  if (n == 0) {
    report.ok = true;
    return report;
  }
  // Jacobi scaling D S D, D = diag(S)^-1/2 (1 where S_ee = 0).
  Eigen::VectorXd d = schur->s_lower().diagonal().cwiseSqrt();
  for (int i = 0; i < n; ++i) d(i) = d(i) > 0 ? 1.0 / d(i) : 1.0;
  const Eigen::SparseMatrix<double> scaled_s = d.asDiagonal() * schur->s_lower() * d.asDiagonal();
  const internal::SymmetricEigenpairs eig =
      SmallestNullSpaceEigenpairs(scaled_s, relative_threshold, dense_null_space_limit_);
  const double max_eig = eig.largest;
  if (!(max_eig > 0)) {
    report.message = "the normal matrix is zero";
    return report;
  }
  for (int k = 0; k < eig.values.size() && k < 16; ++k)
    report.smallest_relative_eigenvalues.push_back(eig.values(k) / max_eig);
  while (report.rank_defect < eig.values.size() &&
         eig.values(report.rank_defect) <= relative_threshold * max_eig)
    ++report.rank_defect;
  const Eigen::MatrixXd w = eig.vectors.leftCols(report.rank_defect);
  for (size_t b = 0; b < free_blocks.size(); ++b) {
    if (schur->is_point(static_cast<int>(b))) continue;
    const BlockId id = free_blocks[b];
    const Block& block = blocks_[id];
    const int offset = schur->reduced_offset(static_cast<int>(b));
    const int size = block.TangentSize();
    report.vectors[id] =
        PlusJacobianOf(id) * d.segment(offset, size).asDiagonal() * w.middleRows(offset, size);
    if (block.rotation) continue;
    // A subset (or no) manifold: tangent entry t is ambient entry free[t], scaled by s_t, so the
    // Jacobi-scaled coordinate sqrt(S_ee) x_e of the ambient entry is the eigenvector's.
    const std::vector<int> free = block.TangentEntries();
    Eigen::MatrixXd scaled = Eigen::MatrixXd::Zero(block.size, report.rank_defect);
    Eigen::VectorXd scale = Eigen::VectorXd::Zero(block.size);
    const Eigen::MatrixXd plus = PlusJacobianOf(id);
    for (int t = 0; t < size; ++t) {
      scaled.row(free[t]) = w.row(offset + t);
      scale(free[t]) = 1.0 / (d(offset + t) * plus(free[t], t));
    }
    report.scaled[id] = scaled;
    report.scale[id] = scale;
  }
  report.ok = true;
  return report;
}

namespace {

using BlockPairs = std::vector<std::pair<BlockId, BlockId>>;

/// Pairs: every block with itself, interior x interior, and, with cross_blocks, the pairs with
/// one of those; without cross_blocks every pair.
BlockPairs CovariancePairs(const std::vector<BlockId>& free_requested,
                           const std::vector<BlockId>& cross_blocks,
                           const std::function<bool(BlockId)>& is_interior) {
  const std::set<BlockId> cross(cross_blocks.begin(), cross_blocks.end());
  BlockPairs pairs;
  for (size_t i = 0; i < free_requested.size(); ++i)
    for (size_t k = i; k < free_requested.size(); ++k) {
      const BlockId a = free_requested[i], b = free_requested[k];
      const bool interior_pair = is_interior(a) && is_interior(b);
      if (cross.empty() || i == k || interior_pair || cross.count(a) || cross.count(b))
        pairs.emplace_back(std::min(a, b), std::max(a, b));
    }
  return pairs;
}

/// `why`, followed by up to 20 of the undetermined parameters in parentheses.
std::string WithUndetermined(const std::string& why, const std::vector<std::string>& undetermined) {
  std::string message = why;
  if (!undetermined.empty()) {
    message += " (";
    for (size_t i = 0; i < undetermined.size() && i < 20; ++i)
      message += (i ? ", " : "") + undetermined[i];
    if (undetermined.size() > 20) message += ", ...";
    message += ")";
  }
  return message;
}

/// Small problems: Ceres' covariance (dense SVD; its rank test is the reference), computed on
/// `mirror`, the problem copied in BlockId order (`in_order[id]`: where block id lives in the
/// copy), since Ceres orders the Jacobian's columns by block address. False when singular.
bool CeresCovarianceBlocks(ceres::Problem* mirror,
                           const std::vector<double*>& in_order,
                           const BlockPairs& pairs,
                           const std::function<int(BlockId)>& size_of,
                           double s2,
                           CovarianceReport* report) {
  ceres::Covariance::Options options;
  options.algorithm_type = ceres::DENSE_SVD;
  options.min_reciprocal_condition_number = 1e-14;
  options.num_threads = 1;
  options.apply_loss_function = true;
  ceres::Covariance covariance(options);
  std::vector<std::pair<const double*, const double*>> ceres_pairs;
  for (const auto& [a, b] : pairs) ceres_pairs.emplace_back(in_order[a], in_order[b]);
  if (!ceres_pairs.empty() && !covariance.Compute(ceres_pairs, mirror)) return false;
  for (const auto& [a, b] : pairs) {
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> m(size_of(a),
                                                                             size_of(b));
    covariance.GetCovarianceBlock(in_order[a], in_order[b], m.data());
    report->blocks[{a, b}] = s2 * Eigen::MatrixXd(m);
  }
  return true;
}

/// A requested block as a linear function of the reduced parameters s: x = G s (+ an own term
/// A^+ for a point: p = -A^+ B s + ...), and d(ambient)/d(tangent) of the block.
struct Lift {
  std::vector<int> cols;
  Eigen::MatrixXd g, own, plus;
};

/// Points eliminated, S factorised, S^-1 on the pattern of its factor (normal_equations.h):
/// Q(a, b) = G_a S^-1(cols_a, cols_b) G_b^T (+ A^+ on a point's own diagonal block), in ambient
/// entries through each block's plus Jacobian. False when a requested point is singular.
bool SchurCovarianceBlocks(const std::vector<BlockId>& order,
                           const internal::SchurComplement& schur,
                           const internal::SelectedInverse& inverse,
                           const std::vector<BlockId>& free_requested,
                           const BlockPairs& pairs,
                           const std::function<Eigen::MatrixXd(BlockId)>& plus_jacobian,
                           double s2,
                           CovarianceReport* report) {
  std::map<BlockId, int> index;  // block -> index in the Schur system
  for (size_t b = 0; b < order.size(); ++b) index[order[b]] = static_cast<int>(b);
  bool any_point = false;
  for (size_t b = 0; b < order.size(); ++b) any_point |= schur.is_point(static_cast<int>(b));
  report->method = std::string(any_point ? "schur_" : "normal_") +
                   (inverse.dense() ? "dense_inverse" : "selected_inverse");
  std::map<BlockId, Lift> lifts;
  for (BlockId id : free_requested) {
    Lift lift;
    const int b = index.at(id);
    if (schur.is_point(b)) {
      const auto t = schur.Point(b);
      if (t.singular) return false;
      lift.cols = t.cols;
      lift.g = -t.a_pinv * t.b;
      lift.own = t.a_pinv;
    } else {
      lift.cols = schur.ReducedColumns({b});
      lift.g = Eigen::MatrixXd::Identity(lift.cols.size(), lift.cols.size());
    }
    lift.plus = plus_jacobian(id);
    lifts[id] = std::move(lift);
  }
  for (const auto& [a, b] : pairs) {
    const Lift& la = lifts.at(a);
    const Lift& lb = lifts.at(b);
    Eigen::MatrixXd q = Eigen::MatrixXd::Zero(la.g.rows(), lb.g.rows());
    if (!la.cols.empty() && !lb.cols.empty())
      q = la.g * inverse.Gather(la.cols, lb.cols) * lb.g.transpose();
    if (a == b && la.own.size() > 0) q += la.own;
    report->blocks[{a, b}] = s2 * la.plus * q * lb.plus.transpose();
  }
  return true;
}

/// Rotation blocks are reported in omega, phi, kappa: C_opk = J C_q J^T with J the conversion's
/// Jacobian (calib/camera/rotation.h OpkJacobianOfQuaternion; NaN rows for omega and kappa at
/// phi = +-90 deg, whose sigmas are then unknown). `quaternion_of`: a rotation block's values,
/// nullptr for any other block.
void ReportRotationsInOpk(const std::function<const double*(BlockId)>& quaternion_of,
                          CovarianceReport* report) {
  const auto report_jacobian = [&](BlockId id, int size) -> Eigen::MatrixXd {
    const double* q = quaternion_of(id);
    if (!q) return Eigen::MatrixXd::Identity(size, size);
    return OpkJacobianOfQuaternion(Eigen::Map<const Eigen::Vector4d>(q));
  };
  for (auto& [ab, c] : report->blocks) {
    if (!quaternion_of(ab.first) && !quaternion_of(ab.second)) continue;
    c = report_jacobian(ab.first, c.rows()) * c * report_jacobian(ab.second, c.cols()).transpose();
  }
}

/// sqrt of each requested block's diagonal (NaN, not separable, stays NaN).
void FillSigmas(const std::vector<BlockId>& free_requested, CovarianceReport* report) {
  for (BlockId id : free_requested) {
    const Eigen::MatrixXd& c = report->blocks.at({id, id});
    for (int e = 0; e < c.rows(); ++e)
      report->sigma(report->offsets[id] + e) =
          std::isnan(c(e, e)) ? c(e, e) : std::sqrt(std::max(0.0, c(e, e)));
  }
}

/// Correlations above the threshold, in the order of the requested entries.
void FindHighCorrelations(double correlation_threshold, CovarianceReport* report) {
  struct Pair {
    int i, k;
    double rho;
  };
  std::vector<Pair> high;
  for (const auto& [ab, c] : report->blocks) {
    const int oa = report->offsets.at(ab.first), ob = report->offsets.at(ab.second);
    for (int r = 0; r < c.rows(); ++r)
      for (int q = ab.first == ab.second ? r + 1 : 0; q < c.cols(); ++q) {
        const int i = std::min(oa + r, ob + q), k = std::max(oa + r, ob + q);
        if (!report->free[i] || !report->free[k]) continue;
        const double rho = report->Correlation(i, k);
        if (std::abs(rho) > correlation_threshold) high.push_back({i, k, rho});
      }
  }
  std::sort(high.begin(), high.end(), [](const Pair& x, const Pair& y) {
    return x.i != y.i ? x.i < y.i : x.k < y.k;
  });
  for (const Pair& h : high)
    report->high_correlations.push_back({report->names[h.i], report->names[h.k], h.rho});
}

/// The full correlation matrix of the interior entries.
void FillInteriorCorrelation(const std::function<bool(BlockId)>& is_interior,
                             CovarianceReport* report) {
  std::vector<int> interior_rows;
  for (int i = 0; i < static_cast<int>(report->names.size()); ++i)
    if (is_interior(report->entry_block[i])) interior_rows.push_back(i);
  report->interior_correlation =
      Eigen::MatrixXd::Identity(interior_rows.size(), interior_rows.size());
  for (size_t r = 0; r < interior_rows.size(); ++r) {
    report->interior_names.push_back(report->names[interior_rows[r]]);
    for (size_t q = 0; q < interior_rows.size(); ++q)
      if (r != q)
        report->interior_correlation(r, q) =
            report->Correlation(interior_rows[r], interior_rows[q]);
  }
}

}  // namespace

CovarianceReport ProblemBuilder::EstimateCovariance(
    const std::vector<BlockId>& blocks,
    double sigma0,
    double correlation_threshold,
    const std::vector<BlockId>& cross_blocks) const {
  SettleManifolds();
  CovarianceReport report;
  int total = 0;
  for (BlockId id : blocks) {
    report.offsets[id] = total;
    const Block& b = blocks_.at(id);
    for (int e = 0; e < b.ReportSize(); ++e) {
      report.names.push_back(b.EntryName(e));
      report.free.push_back(!b.constant && !b.entry_fixed[e] && b.num_residuals > 0);
      report.entry_block.push_back(id);
      report.entry_local.push_back(e);
    }
    total += b.ReportSize();
  }
  report.sigma = Eigen::VectorXd::Zero(total);
  std::vector<BlockId> free_requested;
  for (BlockId id : blocks)
    if (!blocks_[id].constant && blocks_[id].num_residuals > 0) free_requested.push_back(id);
  const auto is_interior = [&](BlockId id) { return blocks_[id].kind == BlockKind::kInterior; };
  const BlockPairs pairs = CovariancePairs(free_requested, cross_blocks, is_interior);
  auto fail = [&](const std::string& why) {
    ReleaseFactorized();
    report.ok = false;
    report.undetermined = NullSpaceParameters(3000);
    report.message = WithUndetermined(why, report.undetermined);
    report.blocks.clear();
    return report;
  };
  const std::string singular_message =
      "the normal matrix is singular or badly conditioned: the problem has a datum defect or "
      "parameters the observations cannot determine";
  const double s2 = sigma0 * sigma0;
  if (NumFreeParameters() <= kCeresCovarianceLimit) {
    report.method = "ceres_dense_svd";
    // On a copy in BlockId order: Ceres orders the Jacobian's columns by block address.
    std::vector<double> buffer;
    std::vector<double*> in_order;
    const std::unique_ptr<ceres::Problem> mirror = CopyInBlockOrder(&buffer, &in_order, true);
    const auto size_of = [&](BlockId id) { return blocks_[id].size; };
    if (!CeresCovarianceBlocks(mirror.get(), in_order, pairs, size_of, s2, &report))
      return fail(singular_message);
  } else {
    // The factorisation of the last redundancy numbers when nothing changed since (snooping's
    // final test): one factorisation and selected inversion for both. Released at the end.
    const Factorized* factorized = Factorize(true, 0);
    if (!factorized) return fail("the residuals cannot be evaluated at the current values");
    if (!factorized->inverse_ok || factorized->inverse.singular()) return fail(singular_message);
    const auto plus_jacobian = [&](BlockId id) { return PlusJacobianOf(id); };
    if (!SchurCovarianceBlocks(factorized->free_blocks,
                               *factorized->schur,
                               factorized->inverse,
                               free_requested,
                               pairs,
                               plus_jacobian,
                               s2,
                               &report))
      return fail(singular_message);
    ReleaseFactorized();
  }
  ReportRotationsInOpk(
      [&](BlockId id) { return blocks_[id].rotation ? blocks_[id].values : nullptr; }, &report);
  report.ok = true;
  FillSigmas(free_requested, &report);
  FindHighCorrelations(correlation_threshold, &report);
  FillInteriorCorrelation(is_interior, &report);
  return report;
}

}  // namespace aerocal::calib
