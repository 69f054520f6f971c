// Cofactors of the (whitened) observations of a ProblemBuilder adjustment: redundancy numbers
// r_ii and, per eliminated point, the cofactor matrix Q_vv of the residuals observing it.
// Computed by ProblemBuilder::ComputeObservationCofactors (problem_builder.h); the method is
// described in calib/README.md ("Observation cofactors and covariance").
#pragma once

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace aerocal::calib {

using BlockId = int;
using ResidualId = int;

/// The requested residuals that observe one eliminable (point) block, with their joint cofactors.
struct ResidualCluster {
  BlockId point = -1;
  std::vector<ResidualId> residuals;  // in order; rows of qvv are their scalar components stacked
  Eigen::MatrixXd qvv;                // whitened Q_vv among those components (symmetric)
};

/// Cofactor information of whitened observations (v = whitened residual, P = I):
/// Q_vv = I - J N^-1 J^T (N^-1 a generalised inverse on a datum defect: Q_vv does not depend on
/// which). r_ii = (Q_vv)_ii.
struct ObservationCofactors {
  /// False when the cofactors could not be computed exactly (then `redundancy` holds NaN for
  /// every requested component and `message` says why); never an approximation in disguise.
  bool ok = false;
  /// How r_ii were computed:
  ///   "schur_selected_inverse"      points eliminated, reduced matrix S factorised (sparse LDL^T,
  ///                                 AMD ordering), S^-1 evaluated on the pattern of its factor
  ///                                 (Takahashi equations); exact.
  ///   "schur_dense_pseudo_inverse"  points eliminated, S^+ from an eigen-decomposition (small S,
  ///                                 or a singular S up to max_dense_parameters); exact.
  ///   "normal_selected_inverse" / "normal_dense_pseudo_inverse": the same without point blocks.
  ///   "not_computed"                see message.
  std::string method;
  std::string message;
  std::map<ResidualId, std::vector<double>> redundancy;  // r_ii per scalar component, in [0, 1]
  std::vector<ResidualCluster> clusters;                 // filled when with_clusters
  int reduced_parameters = 0;                            // size of S
  long long factor_nonzeros = 0;  // entries of the sparse factor L (0 for the dense path)
};

}  // namespace aerocal::calib
