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
// - Data snooping lives beside it, in data_snooping.h (it only uses this class's public API).
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

#include <Eigen/Core>
#include <ceres/cost_function.h>

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ceres {
class Problem;
}

namespace aerocal::calib {

using BlockId = int;
using ResidualId = int;

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

enum class LinearSolverChoice { kAuto, kDenseQr, kDenseSchur, kSparseSchur, kSparseNormalCholesky };

struct SolverOptions {
  int max_iterations = 100;           // Levenberg-Marquardt iterations, > 0
  double function_tolerance = 1e-12;  // relative cost change to stop
  double gradient_tolerance = 1e-14;
  double parameter_tolerance = 1e-12;  // relative step size to stop
  LinearSolverChoice linear_solver = LinearSolverChoice::kAuto;
  int num_threads = 0;   // 0: all cores
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
  std::vector<ResidualGroupStats> groups;
  std::vector<std::string> diagnostics;
  const ResidualGroupStats* Group(const std::string& name) const;
};

struct HighCorrelation {
  std::string a, b;
  double correlation = 0.0;
};

/// Covariance of selected blocks, scaled by sigma0^2 (a-posteriori), in ambient coordinates.
struct CovarianceReport {
  bool ok = false;
  std::string message;  // why it failed, when !ok
  /// How it was computed: "schur" (points eliminated, sparse LDLT), "ceres_dense_svd" or
  /// "ceres_sparse_qr" (ceres::Covariance).
  std::string method;
  std::vector<std::string> names;  // "block.entry" per row
  std::vector<bool> free;          // false for fixed entries (sigma 0)
  Eigen::MatrixXd covariance;      // sigma0^2 Q
  Eigen::VectorXd sigma;           // sqrt(diag)
  Eigen::MatrixXd correlation;
  std::vector<HighCorrelation> high_correlations;  // |rho| above the threshold, free entries only
  std::vector<std::string> undetermined;           // parameters in the null space (rank defect)
  std::map<BlockId, int> offsets;                  // row of each block's first entry
  /// Sub-matrix of one block (size x size).
  Eigen::MatrixXd BlockCovariance(BlockId id, int size) const;
  Eigen::VectorXd BlockSigma(BlockId id, int size) const;
};

/// Whitened Q_vv among the stacked components of the requested residuals observing one point
/// block (ground or tie point).
struct ResidualCluster {
  BlockId point = -1;
  std::vector<ResidualId> residuals;
  Eigen::MatrixXd qvv;
};
/// Cofactors of the residuals: redundancy numbers r_i = (Q_vv P)_ii per scalar component and,
/// on request, Q_vv within each point cluster; `method` says how they were computed.
struct ObservationCofactors {
  std::string method;
  std::map<ResidualId, std::vector<double>> redundancy;
  std::vector<ResidualCluster> clusters;
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
  BlockId FindBlock(const std::string& name) const;  // -1 when absent
  void FixBlock(BlockId id);
  void FreeBlock(BlockId id);
  /// Fixes the listed entries (0-based); the others stay free. All entries -> FixBlock.
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
  bool IsActive(ResidualId id) const;
  int NumActiveResiduals() const;
  /// Residuals ever added (ids 0 .. NumResiduals() - 1, removed ones included).
  int NumResiduals() const;
  const std::string& ResidualGroup(ResidualId id) const;
  const std::string& ResidualLabel(ResidualId id) const;
  /// Current whitened residual values (loss not applied).
  std::vector<double> EvaluateResidual(ResidualId id) const;

  /// Blocks a residual was added on, in order; the kind of a block.
  const std::vector<BlockId>& ResidualBlocks(ResidualId id) const;
  BlockKind BlockKindOf(BlockId id) const;

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

  /// Redundancy numbers r_ii of every scalar residual of the listed residuals (whitened problem).
  /// Exact: with point blocks (ground / tie points) by their elimination (Schur complement) when
  /// the other parameters number at most max_dense_parameters; else from the dense normal matrix
  /// up to max_dense_parameters free parameters; r/n otherwise.
  std::map<ResidualId, std::vector<double>> RedundancyNumbers(const std::vector<ResidualId>& ids,
                                                              int max_dense_parameters) const;
  /// Redundancy numbers of `ids` and, with `with_clusters`, Q_vv within each point cluster.
  ObservationCofactors ComputeObservationCofactors(const std::vector<ResidualId>& ids,
                                                   bool with_clusters) const;

  /// Free parameters (tangent space) and scalar residuals currently in the problem.
  int NumFreeParameters() const;
  int NumObservations() const;

  ceres::Problem& problem();

 private:
  struct Block;
  struct Residual;
  std::vector<BlockId> FreeBlocksInOrder() const;
  /// Subset manifolds of the free entries, columns scaled to unit Jacobian norm at the current
  /// values; false when the residuals cannot be evaluated there (then the scales are 1).
  bool UpdateManifolds();
  /// Names of the parameters in the null space of the normal matrix: from the dense matrix up to
  /// `max_parameters` free parameters, above that from the normal equations reduced to the
  /// non-point parameters (points eliminated) while those number at most `max_parameters`.
  std::vector<std::string> NullSpaceParameters(int max_parameters) const;
  struct ReducedSystem;
  /// Normal equations with the ground / tie points eliminated (Schur complement); false when no
  /// point or no other block is free, or a residual observes two points.
  bool ReduceNormalEquations(ReducedSystem* out) const;
  bool RedundancyNumbersBySchur(const std::vector<ResidualId>& ids,
                                int max_dense,
                                std::map<ResidualId, std::vector<double>>* out,
                                std::vector<ResidualCluster>* clusters = nullptr) const;
  Eigen::MatrixXd DenseJacobian(const std::vector<BlockId>& blocks,
                                std::vector<ResidualId>* row_owner) const;
  /// Covariance blocks (ambient, unscaled Q) of `pairs` of non-eliminable blocks by eliminating the
  /// ground points (Schur complement, sparse LDLT); false when not applicable or not positive
  /// definite (the caller then falls back to Ceres' covariance).
  bool SchurCovariance(const std::vector<std::pair<BlockId, BlockId>>& pairs,
                       std::map<std::pair<BlockId, BlockId>, Eigen::MatrixXd>* out) const;

  std::unique_ptr<ceres::Problem> problem_;
  std::vector<Block> blocks_;
  std::vector<Residual> residuals_;
  std::map<std::string, BlockId> block_by_name_;
  std::map<const double*, BlockId> block_by_pointer_;
};

/// Two-sided standard-normal quantile: z with P(|N(0,1)| > z) = alpha.
double NormalCriticalValue(double alpha);

}  // namespace aerocal::calib
