// THE problem builder: the only owner of a ceres::Problem in aerocal (STYLE.md section 5).
//
// Every adjustment in the project goes through it: sub-image stitching, aerial triangulation,
// the joint stitching + triangulation adjustment and, later, multi-head rigs and pushbroom cameras.
//
// What it does
// - Registry of named parameter blocks (camera interior, sub-image mapping, rotation, centre,
//   ground point, virtual tie point, other), with whole-block fixing and per-entry fixing
//   (a SubsetManifold, e.g. "c, x0, y0, K1, K2 free").
// - Residuals are registered under a named GROUP (kGroupImage, kGroupControl, ... or any string),
//   each with a human label ("image 0001 point t17"), so statistics, snooping and reports come per
//   group with no second bookkeeping. Every residual must be WHITENED (divided by its a-priori
//   sigma), so that sum r^2 = v^T P v (CONVENTIONS.md "Statistics").
// - Solve(): picks the linear solver by shape (dense QR for small problems, Schur complement when
//   points can be eliminated, sparse Cholesky otherwise), optional robust loss per residual, and
//   returns a SolveReport: sigma0 = sqrt(v^T P v / r) with the redundancy r = n_obs - n_unknowns,
//   iterations, convergence, per-group counts and RMS.
// - EstimateCovariance(): covariance of the chosen blocks, scaled by sigma0^2 (Ceres' covariance;
//   for large problems whose requested blocks are not ground points, the points are eliminated
//   first: Q_rr = S^-1 with the reduced normal matrix S = N_rr - N_rp N_pp^-1 N_pr), with standard
//   deviations, correlations, the pairs above a threshold, and, for a rank-deficient problem, the
//   parameters that span the null space (from an eigen-decomposition of the Jacobi-scaled normal
//   matrix when the problem is small enough).
// - Data snooping lives beside it, in data_snooping.h (it uses this class's public API only).
//
// How to add a residual family
// 1. Write a small templated functor (see calib/residuals/*.h): constructor takes the measurement
//    and its sigma, operator() takes one const T* per block and writes a whitened residual;
//    return false where the geometry is undefined. Derive AutoDiffResidual<Self, N, sizes...>.
// 2. Put it beside the model it uses, with a GradientChecker test.
// 3. In the adjustment: AddBlock() each parameter block once (name it), then
//    AddResidual(group, Functor::Create(...), {blocks...}, label). Pick an existing group name or
//    a new one: statistics appear per group automatically.
#pragma once

#include "calib/problem/observation_cofactors.h"

#include <Eigen/Core>
#include <ceres/cost_function.h>
#include <ceres/types.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ceres {
class Problem;
}

namespace aerocal::calib {

namespace internal {
class SchurComplement;
}
class ScaledSubsetManifold;

enum class BlockKind { kInterior, kMapping, kRotation, kCenter, kGroundPoint, kTiePoint2d, kOther };

// Standard residual group names.
inline constexpr const char* kGroupImage = "image";              // collinearity, virtual image
inline constexpr const char* kGroupSubimage = "subimage_image";  // collinearity, raw sub-image
inline constexpr const char* kGroupControl = "control";          // control-point coordinates
inline constexpr const char* kGroupEoPrior = "eo_prior";         // GNSS/IMU priors
inline constexpr const char* kGroupInteriorPrior = "interior_prior";
inline constexpr const char* kGroupStitchReference = "stitch_reference";
inline constexpr const char* kGroupStitchTie = "stitch_tie";

enum class LossKind { kNone, kHuber, kCauchy };

struct LossOptions {
  LossKind kind = LossKind::kNone;
  double scale = 3.0;  // in whitened units (multiples of sigma), > 0
};

enum class LinearSolverChoice {
  kAuto,
  kDenseQr,
  kDenseSchur,
  kSparseSchur,
  kIterativeSchur,
  kSparseNormalCholesky
};

enum class SolverEngine { kAerocal, kCeres };

struct SolverOptions {
  int max_iterations = 100;           // Levenberg-Marquardt iterations, > 0
  double function_tolerance = 1e-12;  // relative cost change to stop
  double gradient_tolerance = 1e-14;
  double parameter_tolerance = 1e-12;  // relative step size to stop
  LinearSolverChoice linear_solver = LinearSolverChoice::kAuto;
  /// kAuto: dense QR up to this many free parameters (count, >= 0).
  int max_dense_qr_parameters = 300;
  /// kAuto with point blocks: dense Schur while the reduced (non-point) parameters number at most
  /// this (count, >= 0), sparse Schur (Cholesky of the reduced matrix) above it.
  int max_dense_schur_parameters = 800;
  /// kAuto with point blocks: above this many reduced parameters (count, >= 0; 0: never) the
  /// reduced system is solved iteratively (ITERATIVE_SCHUR, conjugate gradients with the
  /// SCHUR_JACOBI preconditioner) instead of factorised: memory grows linearly with the block.
  int min_iterative_schur_parameters = 0;
  /// Who minimises: aerocal's own Levenberg-Marquardt (levenberg_marquardt.h) wherever the
  /// linear solver is a Schur one (dense or sparse) and every residual sees at most one point
  /// block, else Ceres; kCeres: Ceres always (the reference path).
  SolverEngine engine = SolverEngine::kAerocal;
  /// Threads of aerocal's engine (0: all cores): its results are the same bits for every count.
  /// Ceres' threads: `num_threads` when !deterministic, else one.
  int num_threads = 0;
  /// Ceres' engine only: identical inputs give bit-identical results, the solve runs on one
  /// thread (Ceres' threaded gradient and Schur reductions add in scheduling order).
  bool deterministic = true;
  bool verbose = false;  // Ceres per-iteration log on stdout
};

struct ResidualGroupStats {
  std::string name;
  int n_residual_blocks = 0;
  int n_observations = 0;  // scalar residuals
  double vtpv = 0.0;       // sum of squared whitened residuals
  double rms = 0.0;        // sqrt(vtpv / n_observations): RMS in units of the a-priori sigmas
};

struct SolveReport {
  bool converged = false;
  bool usable = false;  // Ceres returned a usable solution (converged or hit iteration limit)
  int iterations = 0;
  double initial_cost = 0.0, final_cost = 0.0;  // 0.5 v^T P v
  std::string termination;                      // Ceres' termination type
  std::string message;                          // Ceres' message
  std::string linear_solver;
  int n_observations = 0;  // scalar residuals
  int n_unknowns = 0;      // free parameters (tangent space)
  int redundancy = 0;
  double vtpv = 0.0;
  double sigma0 = 0.0;  // unitless, 1 when the a-priori sigmas are right
  double seconds = 0.0;
  /// Of `seconds`: residual and Jacobian evaluation, and the linear solver (Schur reduction,
  /// factorisation, back-substitution), summed over the iterations, s.
  double evaluation_seconds = 0.0, linear_solver_seconds = 0.0;
  std::vector<ResidualGroupStats> groups;
  std::vector<std::string> diagnostics;
  const ResidualGroupStats* Group(const std::string& name) const;
};

struct HighCorrelation {
  std::string a, b;
  double correlation = 0.0;
};

/// Covariance of selected blocks, scaled by sigma0^2 (a-posteriori), in ambient coordinates;
/// rotation blocks (AddRotationBlock) in omega, phi, kappa (3 entries).
/// Only the requested pairs of blocks are held (never a dense matrix of all requested entries).
struct CovarianceReport {
  bool ok = false;
  std::string message;  // why it failed, when !ok
  /// How it was computed: "schur_selected_inverse" (points eliminated, sparse LDL^T of the reduced
  /// matrix, its inverse on the factor's pattern), "normal_selected_inverse" (no point blocks),
  /// "schur_dense_inverse" / "normal_dense_inverse" (small reduced matrix), or "ceres_dense_svd"
  /// (ceres::Covariance, up to 300 free parameters). All exact.
  std::string method;
  std::vector<std::string> names;                  // "block.entry" per row
  std::vector<bool> free;                          // false for fixed entries (sigma 0)
  Eigen::VectorXd sigma;                           // sqrt(diag)
  std::vector<HighCorrelation> high_correlations;  // |rho| above the threshold, free entries only
  std::vector<std::string> undetermined;           // parameters in the null space (rank defect)
  std::map<BlockId, int> offsets;                  // row of each block's first entry
  /// The computed blocks sigma0^2 Q(a, b) (ambient, size_a x size_b), keyed (a, b) with a <= b.
  std::map<std::pair<BlockId, BlockId>, Eigen::MatrixXd> blocks;
  /// Full correlation matrix of the interior (BlockKind::kInterior) entries among the requested
  /// blocks, rows named by interior_names.
  std::vector<std::string> interior_names;
  Eigen::MatrixXd interior_correlation;
  std::vector<BlockId> entry_block;  // block of each row of names
  std::vector<int> entry_local;      // entry within that block

  /// Sub-matrix of one block (size x size); zero for a fixed block.
  Eigen::MatrixXd BlockCovariance(BlockId id, int size) const;
  Eigen::VectorXd BlockSigma(BlockId id, int size) const;
  /// Covariance of blocks a and b (size_a x size_b); false when the pair was not computed.
  bool CrossCovariance(BlockId a, BlockId b, Eigen::MatrixXd* out) const;
  /// Correlation of rows i and k of names; 0 when their pair of blocks was not computed or one of
  /// them has no spread.
  double Correlation(int i, int k) const;
};

/// The null space of the normal matrix N = J^T J at the current values (loss not applied), the
/// ground points eliminated (Schur complement; a point block is never part of a null vector here:
/// a weighted point is determined once the other parameters are). From the smallest eigenpairs of
/// the Jacobi-scaled reduced matrix D S D (D = diag(S)^-1/2): the eigenvectors whose eigenvalue is
/// below `relative_threshold` x the largest, mapped back to AMBIENT block entries (d = D w through
/// each block's manifold). Used to derive a minimal datum (e.g. triangulation/pushbroom).
struct NullSpaceReport {
  bool ok = false;
  std::string message;         // why it was not computed, when !ok
  int reduced_parameters = 0;  // size of S
  double threshold = 0.0;      // the relative eigenvalue threshold used
  /// Ascending eigenvalues of D S D divided by the largest (the smallest ones, up to 16): the
  /// rank defect is the count below the threshold; the next one shows the gap.
  std::vector<double> smallest_relative_eigenvalues;
  int rank_defect = 0;
  /// Ambient components of the null vectors (size x rank_defect) per free non-point block;
  /// fixed entries are 0. The columns span the null space (any basis of it).
  std::map<BlockId, Eigen::MatrixXd> vectors;
  /// The same null vectors in Jacobi-scaled coordinates z_e = scale_e x_e (unitless; the columns
  /// over all blocks are orthonormal), and scale_e = sqrt(S_ee) in 1 / (the entry's unit), 0 for
  /// fixed entries. Not for rotation blocks (their ambient entries are a quaternion).
  std::map<BlockId, Eigen::MatrixXd> scaled;
  std::map<BlockId, Eigen::VectorXd> scale;
};

class ProblemBuilder {
 public:
  ProblemBuilder();
  ~ProblemBuilder();
  ProblemBuilder(const ProblemBuilder&) = delete;
  ProblemBuilder& operator=(const ProblemBuilder&) = delete;

  /// Registers `size` doubles at `values` (caller keeps them alive) under a unique name.
  /// `entry_names` name each entry in reports (default "0", "1", ...).
  BlockId AddBlock(const std::string& name,
                   double* values,
                   int size,
                   BlockKind kind,
                   std::vector<std::string> entry_names = {});
  /// Registers a rotation (object_from_image) as a unit quaternion [w, x, y, z] at `quaternion`
  /// (4 doubles, caller keeps them alive; |q| = 1 to 1e-9) under BlockKind::kRotation. Inside the
  /// solver it moves on the rotation-increment manifold (rotation_manifold.h: 3 tangent entries,
  /// rotations about the object axes); covariance reports give it as omega, phi, kappa (rad,
  /// `report_names`, CONVENTIONS.md), propagated through the conversion's Jacobian: at
  /// phi = +-90 deg the omega and kappa sigmas are NaN (not separable). Fixed only as a whole.
  BlockId AddRotationBlock(const std::string& name,
                           double* quaternion,
                           std::vector<std::string> report_names = {"omega", "phi", "kappa"});
  BlockId FindBlock(const std::string& name) const;  // -1 when absent
  void FixBlock(BlockId id);
  void FreeBlock(BlockId id);
  /// Fixes the listed entries (0-based); the others stay free. All entries -> FixBlock.
  /// In force from the next Solve, EstimateCovariance, ComputeObservationCofactors, NullSpace or
  /// problem() on, which set up the manifolds of the free entries at the values they find then
  /// (one evaluation of the problem for any number of FixEntries calls before it).
  void FixEntries(BlockId id, const std::vector<int>& entries);
  bool IsBlockFixed(BlockId id) const;
  int BlockSize(BlockId id) const;
  const std::string& BlockName(BlockId id) const;
  double* BlockValues(BlockId id) const;

  /// Adds a whitened residual on `blocks` under `group`; `label` names the observation.
  ResidualId AddResidual(const std::string& group,
                         std::unique_ptr<ceres::CostFunction> cost,
                         const std::vector<BlockId>& blocks,
                         const std::string& label = "",
                         const LossOptions& loss = {});
  /// Removes a residual (e.g. a gross error); its statistics leave the groups.
  void RemoveResidual(ResidualId id);
  /// Puts a removed residual back (same id, cost and loss): a trial removal undone.
  void RestoreResidual(ResidualId id);
  bool IsActive(ResidualId id) const;
  int NumActiveResiduals() const;
  const std::string& ResidualGroup(ResidualId id) const;
  const std::string& ResidualLabel(ResidualId id) const;
  /// Every parameter value, block after block: the state a kept factorisation belongs to, and a
  /// state to return to after a trial solve (RestoreValues).
  std::vector<double> ValuesSnapshot() const;
  /// Puts back every parameter value of a ValuesSnapshot of this builder (the same blocks).
  void RestoreValues(const std::vector<double>& snapshot);
  /// Current whitened residual values (loss not applied).
  std::vector<double> EvaluateResidual(ResidualId id) const;

  /// Blocks a residual was added on, in order; the kind of a block.
  const std::vector<BlockId>& ResidualBlocks(ResidualId id) const;
  BlockKind BlockKindOf(BlockId id) const;
  /// Residuals ever added (ids 0 .. NumResiduals() - 1, removed ones included).
  int NumResiduals() const;

  SolveReport Solve(const SolverOptions& options);

  /// Covariance of `blocks` at the current values, scaled by sigma0^2; correlations above
  /// `correlation_threshold` are listed.
  /// With `cross_blocks` non-empty, only the diagonal blocks and the pairs involving one of
  /// `cross_blocks` are computed (e.g. interior x every exterior block, for large blocks); the
  /// other off-diagonal entries stay 0 and their correlations are not examined.
  CovarianceReport EstimateCovariance(const std::vector<BlockId>& blocks,
                                      double sigma0,
                                      double correlation_threshold = 0.95,
                                      const std::vector<BlockId>& cross_blocks = {}) const;

  /// The null space of the normal matrix at the current state (NullSpaceReport); not computed
  /// (ok false) above `max_parameters` reduced parameters. Only the smallest eigenpairs are
  /// computed (shift-invert subspace iteration, smallest_eigenpairs.h); dense up to
  /// SetDenseNullSpaceLimit parameters and wherever the iteration fails. Not computed (ok false)
  /// before the first Solve, which sets up the rotations' tangent manifolds.
  NullSpaceReport NullSpace(double relative_threshold, int max_parameters = 3000) const;
  /// Reduced matrices up to `parameters` (default 200) are eigen-decomposed densely by NullSpace,
  /// larger ones iteratively. For tests that compare the two on one problem.
  void SetDenseNullSpaceLimit(int parameters) { dense_null_space_limit_ = parameters; }

  /// Cofactors of the listed (active) residuals at the current values, loss not applied:
  /// redundancy numbers r_ii of every scalar component and, with `with_clusters`, Q_vv among the
  /// listed residuals of each point block. Exact at any size (observation_cofactors.h): points
  /// eliminated, the reduced matrix factorised sparsely and inverted on its pattern only. A
  /// singular reduced matrix (datum defect) is inverted densely (any generalised inverse gives the
  /// same Q_vv) up to `max_dense_parameters` reduced parameters; above that the result is not ok.
  ObservationCofactors ComputeObservationCofactors(const std::vector<ResidualId>& ids,
                                                   bool with_clusters,
                                                   int max_dense_parameters = 4000) const;
  /// r_ii of the listed residuals: ComputeObservationCofactors(ids, false, ...).redundancy
  /// (NaN components when they cannot be computed; never an approximation).
  std::map<ResidualId, std::vector<double>> RedundancyNumbers(const std::vector<ResidualId>& ids,
                                                              int max_dense_parameters) const;

  /// Reduced matrices up to `parameters` (count, >= 0; default 300) are inverted densely by
  /// ComputeObservationCofactors / EstimateCovariance, larger ones by the sparse selected
  /// inverse. For tests and benchmarks that compare the two paths on one problem.
  void SetDenseInverseLimit(int parameters) {
    dense_inverse_limit_ = parameters;
    ++structure_version_;
  }

  /// Free parameters (tangent space) and scalar residuals currently in the problem.
  int NumFreeParameters() const;
  int NumObservations() const;

  ceres::Problem& problem();

 private:
  struct Block;
  struct Residual;
  std::vector<BlockId> FreeBlocksInOrder() const;
  /// Subset manifolds of the free entries, columns scaled to unit Jacobian norm at the current
  /// values; false when the residuals cannot be evaluated there (then the scales are 1). Const:
  /// the manifolds are derived state (the fixed entries and the Jacobian), set up when used.
  bool UpdateManifolds() const;
  /// UpdateManifolds() when entries were fixed since the last update (FixEntries defers it):
  /// called first by every public function that reads the manifolds.
  void SettleManifolds() const;
  /// Every free rotation block has its tangent manifold (set up by Solve through
  /// UpdateManifolds): the reduced system's rotation columns exist only then.
  bool RotationManifoldsSet() const;
  /// v^T P v per group and overall without the loss function, observations, unknowns,
  /// redundancy and sigma0 (a diagnostic when there is no redundancy) at the current values.
  void AddSolveStatistics(SolveReport* report) const;
  /// The statistics and the diagnostics of a solve (not converged, blocks without observations).
  void FinishSolveReport(SolveReport* report) const;
  /// The solve by aerocal's own engine (SolverOptions::engine) in place of Ceres' `chosen` Schur
  /// solver; false, and nothing changed, when the problem is not one it solves (then Ceres does).
  bool SolveWithAerocal(const SolverOptions& options,
                        ceres::LinearSolverType chosen,
                        const std::vector<BlockId>& free_blocks,
                        SolveReport* report);
  /// The problem as Ceres must see it where it orders blocks by their address: the eliminable
  /// blocks (a Schur solve) or every block (`all`: ceres::Covariance, which sorts the Jacobian's
  /// columns by address) copied into one buffer in BlockId order (`buffer`; `pointers[id]` is
  /// where block id lives in the copy, the owner's memory for the others), the same residuals,
  /// manifolds and fixed blocks. Without it the last digits followed the heap's history.
  std::unique_ptr<ceres::Problem> CopyInBlockOrder(std::vector<double>* buffer,
                                                   std::vector<double*>* pointers,
                                                   bool all = false) const;
  /// Names of the parameters in the null space of the normal matrix: from the dense matrix up to
  /// `max_parameters` free parameters, above that from the normal equations reduced to the
  /// non-point parameters (points eliminated) while those number at most `max_parameters`.
  std::vector<std::string> NullSpaceParameters(int max_parameters) const;
  /// Jacobian of all active residuals over the free blocks (tangent space), with the point
  /// blocks marked for elimination; nullptr when the residuals cannot be evaluated.
  /// `free_blocks`: the Schur system's block order; `first_row`: per residual, its first row
  /// (-1 when inactive).
  std::unique_ptr<internal::SchurComplement> BuildSchurComplement(
      bool apply_loss, std::vector<BlockId>* free_blocks, std::vector<int>* first_row) const;
  /// The reduced system with its selected inverse at the current state (values, free entries,
  /// active residuals, manifold scales). The last one is kept: ComputeObservationCofactors and
  /// EstimateCovariance at the same state (snooping's final test, then the covariance) share one
  /// factorisation and selected inversion. A stale one is released before a new one is built,
  /// so at most one is in memory. nullptr when the residuals cannot be evaluated.
  struct Factorized;
  const Factorized* Factorize(bool apply_loss, int max_dense_parameters) const;
  /// Drops the kept factorisation (its memory).
  void ReleaseFactorized() const;
  /// d(ambient)/d(tangent) of a block at its current values (identity without a manifold).
  Eigen::MatrixXd PlusJacobianOf(BlockId id) const;
  Eigen::MatrixXd DenseJacobian(const std::vector<BlockId>& blocks,
                                std::vector<ResidualId>* row_owner) const;

  std::unique_ptr<ceres::Problem> problem_;
  std::vector<Block> blocks_;
  std::vector<Residual> residuals_;
  std::map<std::string, BlockId> block_by_name_;
  std::map<const double*, BlockId> block_by_pointer_;
  int dense_inverse_limit_ = 300;
  int dense_null_space_limit_ = 200;
  /// Bumped by every change of the problem other than parameter values (blocks, residuals,
  /// fixing, manifold scales at each Solve): part of a kept factorisation's state.
  mutable long long structure_version_ = 0;
  /// FixEntries changed a block's free entries and UpdateManifolds has not run since.
  mutable bool manifolds_stale_ = false;
  mutable std::unique_ptr<Factorized> factorized_;
};

/// Two-sided standard-normal quantile: z with P(|N(0,1)| > z) = alpha.
double NormalCriticalValue(double alpha);

}  // namespace aerocal::calib
