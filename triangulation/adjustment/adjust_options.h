// How a block is adjusted (STYLE.md section 6): which interior parameters are free, which weighted
// observations enter, gross-error detection and the solver. What is adjusted (images, points and
// their roles, a-priori sigmas) is data from the block files, not options.
#pragma once

#include "calib/camera/camera_model.h"
#include "calib/problem/problem_builder.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct AdjustOptions {
  /// Interior parameters estimated per camera, by the names of the camera's model's table
  /// (brown_fraser_10: c, x0, y0, K1, K2, K3, P1, P2, B1, B2; opencv: fx, fy, cx, cy, k1, ...);
  /// empty = conventional adjustment (interior fixed at the camera file's values).
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
  /// Data snooping (calib/problem/data_snooping.h) on the image observations; the control
  /// coordinates are tested too and named when their survey disagrees, never rejected.
  bool data_snooping = true;
  /// With data_snooping: the control surveys are tested first over all their components; the
  /// worst failing ones are left out (a suspected control blunder, named; its rays kept) when
  /// that makes every other survey fit, up to a third of them, never below 3 control points
  /// without GNSS centres. Off: a failing survey is only named and held.
  bool leave_out_failing_control = true;
  /// Robust start: adjust first with a Cauchy loss on the image observations (scale
  /// `robust_scale_sigma` sigmas), then re-adjust without it from that solution, snooping as set.
  /// For blocks with large gross errors and poor starting values.
  bool robust_start = false;
  /// Without robust_start: start robustly anyway when the first adjustment's residuals call for
  /// it: more than `robust_trigger_share` of the image components above `robust_trigger_w`
  /// (whitened |v| / sigma).
  bool auto_robust_start = true;
  double robust_trigger_share = 0.01;  // [0, 1)
  double robust_trigger_w = 10.0;      // > 0
  double robust_scale_sigma = 3.0;     // > 0
  /// After the robust adjustment, observations whose w = |v| / (s sqrt(r)) (redundancy numbers r,
  /// s = the robust scale of w) exceeds this are excluded from the clean re-adjustment, > 0;
  /// those that fit the clean solution (|v| / sigma below the snooping critical value) are
  /// re-admitted. Data snooping decides the rest.
  double robust_reject_sigma = 8.0;
  /// Snooping policy (data_snooping.h): family-wise alpha, power for the MDB, the redundancy
  /// below which an observation is weakly controlled (reported, never rejected), the correlation
  /// above which observations cannot be told apart (acted on as a group).
  double snooping_alpha = 0.05;     // (0, 1)
  double snooping_power = 0.80;     // (0.5, 1)
  double min_redundancy = 0.1;      // [0, 1)
  double group_correlation = 0.99;  // (0, 1]
  /// Final sigma0 above which a model error is suspected (besides the clustering of the largest
  /// w on one point / image / the control), > 0.
  double model_error_sigma0 = 1.5;
  /// A result whose final sigma0 exceeds this is not valid (exit 3), > 0.
  double max_sigma0 = 3.0;
  /// Failing control surveys that snooping cannot leave out (a group it cannot tell apart) are
  /// judged by their effect (SuspectEffect): the block re-solved without them; when no parameter
  /// with a sigma (free interior, platform, exterior orientation) moves by more than this many of
  /// its sigmas, the result stays valid with a warning naming them, else it is not valid (exit 3).
  /// (0, 1e3]; 0 is refused: a limit of zero sigmas would call every suspicion decisive.
  double suspect_effect_limit = 1.0;
  /// Estimate the covariance (sigmas, correlations, determinability). Off only for speed.
  bool estimate_covariance = true;
  /// Critical value of the standardized residual |w|; 0: from alpha = 5 % / n_tested (>= 3.29).
  double snooping_critical_value = 0.0;
  /// Rejection cap of data snooping; reaching it makes the result invalid (exit 3), >= 0.
  /// 0: 10 % of the tested image observations, at least 100 (a fixed 100 stops a block of 2,700
  /// observations with 5 % gross errors half-way; the cap guards against a runaway, not against
  /// many blunders).
  int max_rejections = 0;
  /// |correlation| above which a pair of parameters is reported as not separable, (0, 1).
  double correlation_threshold = 0.95;
  calib::SolverOptions solver;

  /// Throws ConfigError naming the field, the value and the rule.
  void Validate() const;
};

/// "none" -> {}, "all" -> every name of `model`'s table (the 10 of brown_fraser_10),
/// "c,x0,K1" -> those names (checked against that table). Throws ConfigError on an unknown name.
std::vector<std::string> ParseSelfCalibration(
    const std::string& text, calib::CameraModelId model = calib::CameraModelId::kBrownFraser10);

}  // namespace aerocal::triangulation
