// How a block is adjusted (STYLE.md section 6): which interior parameters are free, which weighted
// observations enter, gross-error detection and the solver. What is adjusted (images, points and
// their roles, a-priori sigmas) is data from the block files, not options.
#pragma once

#include "calib/problem/problem_builder.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct AdjustOptions {
  /// Interior parameters estimated per camera, by table name (c, x0, y0, K1, K2, K3, P1, P2, B1,
  /// B2); empty = conventional adjustment (interior fixed at the camera file's values).
  std::vector<std::string> free_interior;
  /// Camera-file `interior_sigma` values enter as weighted observations of the free parameters.
  bool use_interior_sigma = true;
  /// The sigma columns of exposures.csv enter as GNSS/IMU weighted observations.
  bool use_eo_priors = true;
  /// Without control points and GNSS priors, define the minimal datum of a free network as a
  /// dependent relative orientation: the first exposure of exposures.csv keeps its starting
  /// orientation and the exposure farthest from it keeps the coordinate of the largest base
  /// component (scale). Off: the datum defect is reported as not determinable.
  bool free_network_datum = true;
  /// Baarda data snooping on the image observations; rejected observations are listed.
  bool data_snooping = true;
  /// Robust start: adjust first with a Cauchy loss on the image observations (scale
  /// `robust_scale_sigma` sigmas), then re-adjust without it from that solution, snooping as set.
  /// For blocks with large gross errors and poor starting values.
  bool robust_start = false;
  double robust_scale_sigma = 3.0;  // > 0
  /// After the robust adjustment, observations whose residual exceeds this many robust scales
  /// (1.4826 median |v / sigma|) are rejected before the clean re-adjustment, > 0. Only the
  /// obvious: data snooping (exact redundancy numbers) decides the rest.
  double robust_reject_sigma = 8.0;
  /// Estimate the covariance (sigmas, correlations, determinability). Off only for speed.
  bool estimate_covariance = true;
  /// Critical value of the standardized residual |w|; 0: from alpha = 5 % / n_tested (>= 3.29).
  double snooping_critical_value = 0.0;
  int max_rejections = 100;  // > 0
  /// |correlation| above which a pair of parameters is reported as not separable, (0, 1).
  double correlation_threshold = 0.95;
  /// Free-parameter limit for the exact redundancy numbers of data snooping (dense reduced
  /// normal matrix); larger blocks use the mean redundancy r / n.
  int max_dense_parameters = 4000;
  calib::SolverOptions solver;

  /// Throws ConfigError naming the field, the value and the rule.
  void Validate() const;
};

/// "none" -> {}, "all" -> the 10 names, "c,x0,K1" -> those names (checked against the table).
/// Throws ConfigError on an unknown name.
std::vector<std::string> ParseSelfCalibration(const std::string& text);

}  // namespace aerocal::triangulation
