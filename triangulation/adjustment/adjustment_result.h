// What a block adjustment reports (FORMATS.md "Results", kind "adjust"): sigma0 (unitless, px,
// um), redundancy, convergence, per camera the initial / estimated interior with sigmas, exterior
// orientations with sigmas, control and check statistics (CONVENTIONS.md "Statistics": RMSE, mean,
// max |d| per axis, planimetric and spatial RMSE), rejected observations, and the determinability
// of the free parameters (correlations above the threshold, null-space parameters).
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/camera_model_json.h"
#include "calib/core/finding.h"
#include "calib/core/result_file.h"
#include "calib/problem/problem_builder.h"
#include "calib/problem/suspect_effect.h"
#include "triangulation/block/block.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// Adjusted minus surveyed coordinates of one control or check point (m, object frame).
struct PointDifference {
  std::string point;
  Eigen::Vector3d surveyed_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d adjusted_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d difference_m = Eigen::Vector3d::Zero();
  int rays = 0;
  /// Check points after snooping: non-empty when the point's estimate rests on a ray component
  /// no test can judge (r < min_redundancy; r ~ 0 along the base of a two-ray point), with why.
  /// A blunder there moves the point unseen, so its difference measures the blunder as much as
  /// the block: such points are listed apart from AdjustmentResult::check_controlled.
  std::string uncontrolled;
};

/// A control point whose survey data snooping left out, in whole or in part
/// (AdjustmentResult::control_left_out).
struct LeftOutControl {
  PointDifference difference;  // the survey against the position the block gives the point
  /// The components left out ("plan", "height") with the w of their failed test.
  std::vector<std::pair<std::string, double>> components;
  /// The largest w of the components (nullopt: none recorded).
  std::optional<double> LargestW() const;
  /// The components' names joined by " and " ("plan", "plan and height").
  std::string ComponentNames() const;
};

struct PointStatistics {
  int n = 0;
  Eigen::Vector3d rmse_m = Eigen::Vector3d::Zero();  // per axis X, Y, Z
  Eigen::Vector3d mean_m = Eigen::Vector3d::Zero();  // bias
  Eigen::Vector3d max_abs_m = Eigen::Vector3d::Zero();
  double planimetric_rmse_m = 0.0;  // sqrt(mX^2 + mY^2)
  double spatial_rmse_m = 0.0;      // sqrt(mX^2 + mY^2 + mZ^2)
};
PointStatistics ComputePointStatistics(const std::vector<PointDifference>& points);

/// One camera's interior after the adjustment, in the camera's own model (its table order and
/// units; default-constructed: the 10-parameter model).
struct CameraEstimate {
  std::string id;
  calib::CameraModelId model = calib::Camera::Model::kId;
  calib::InteriorParams initial{}, estimated{}, sigma{};  // table units; sigma 0 when fixed
  calib::ParamVector<bool> free{};
};

/// The GNSS/IMU platform after the adjustment (triangulation/README.md "GNSS/IMU priors on the
/// platform"): values (the given ones when fixed) and sigmas of the estimated ones.
struct PlatformEstimate {
  PlatformSpec spec;  // modes and given values
  bool gnss = false;  // lever arm and time offset took part (GNSS priors)
  bool imu = false;   // boresight took part (IMU priors)
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d boresight_rad = Eigen::Vector3d::Zero();
  double time_offset_s = 0.0;
  std::optional<Eigen::Vector3d> lever_arm_sigma_m, boresight_sigma_rad;  // free or weighted
  std::optional<double> time_offset_sigma_s;
};

struct ExposureEstimate {
  std::string image;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();
  /// When the covariance is known and the exposure took part; null in JSON otherwise.
  std::optional<Eigen::Vector3d> center_sigma_m, opk_sigma_rad;
  bool used = true;  // false: left out of the adjustment (too few points)
};

/// What data snooping found for one image observation (calib/problem/data_snooping.h), per
/// component (x, y of the photo frame): redundancy number r, standardized residual w (NaN where
/// r ~ 0: untestable) and the marginal detectable blunder (MDB, +inf where untestable).
struct ObservationTest {
  bool tested = false;
  Eigen::Vector2d redundancy = Eigen::Vector2d::Zero();
  Eigen::Vector2d w = Eigen::Vector2d::Zero();
  Eigen::Vector2d mdb_sigma = Eigen::Vector2d::Zero();  // in sigmas of the observation
  Eigen::Vector2d mdb_px = Eigen::Vector2d::Zero();
  int group_size = 1;   // observations it cannot be told apart from, itself included
  std::string verdict;  // calib::VerdictName
  std::string reason;
};

struct RejectedObservation {
  std::string image, point;
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();  // the observation (col, row), or (u, v)
  Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();  // v in (corrected) photo space, px
  double w = 0.0;                                         // standardized residual
  std::string subimage;  // non-empty: measured_px is (u, v) in this raw sub-image
  std::string head;      // non-empty: measured_px is a pixel of this rig head
  ObservationTest test;  // at the rejection (robust start: tested == false, w its robust w)
  std::vector<std::string> group;  // images of the correlated group (same point), with its own
  std::string by = "snooping";     // "snooping" or "robust start"
};

/// An observation (or a control point's survey) tested above the critical value and NOT
/// rejected: vetoed (datum), held (survey, model error), weakly controlled, or left at the cap.
struct FlaggedObservation {
  std::string what;  // "image 0012 point T442", "control C5"
  std::string verdict, reason;
  double w = 0.0;
  double redundancy = 0.0;  // of the tested component
  double mdb_sigma = 0.0;
  int group_size = 1;
};

/// An image observation no test can judge (data_snooping.h): a component with a redundancy
/// number below min_redundancy. With r ~ 0 (untestable: along the base of a two-ray point, or
/// a component no other ray checks) a blunder moves only its point and no test can see it; a
/// weakly controlled one is found only above its MDB.
struct UncontrolledObservation {
  std::string image, point;
  Eigen::Vector2d redundancy = Eigen::Vector2d::Zero();  // r per component (photo x, y)
  Eigen::Vector2d mdb_px = Eigen::Vector2d::Zero();      // +inf (JSON null) where r ~ 0
  int rays = 0;                                          // active rays of its point
  bool untestable = false;                               // a component with r ~ 0
  std::string reason;
};

/// A control survey (its plan or its height) that fails the surveys-first test but could not be
/// left out (calib::SnoopingOutcome::unresolved).
struct UnresolvedSurvey {
  std::string survey;         // "control C1 height"
  double w = 0;               // its test over all its components
  double redundancy = 0;      // of its least redundant component
  double residual_sigma = 0;  // its largest residual, in a-priori sigmas
};

/// The effect of the unresolved suspects on the results (issue 28 part 2: a calibration is invalid
/// when a suspicion matters, not whenever a test fires).
using calib::SuspectEffect;  // calib/problem/suspect_effect.h

/// How data snooping was run and what it could not decide (data_snooping.h).
struct SnoopingSummary {
  bool run = false;
  double alpha = 0, alpha0 = 0, critical_value = 0, power = 0, delta0 = 0;
  double delta0_joint = 0;  // of the joint x, y test: the MDBs of image observations use it
  double min_redundancy = 0, group_correlation = 0, reference_sigma = 1;
  std::string cofactor_method;
  bool cofactors_ok = true;
  std::string cofactor_message;
  int n_tested_components = 0, rounds = 0, max_rejections = 0;
  bool cap_reached = false;
  int remaining_above_critical = 0;
  int n_weakly_controlled = 0;  // observations with a component r < min_redundancy
  int n_untestable = 0;         // observations with a component r ~ 0
  int n_in_groups = 0;          // observations whose correlated group has > 1 member
  bool model_error_suspected = false;
  std::vector<std::string> model_error_evidence;
  std::string suggestion;  // e.g. self-calibration
  std::vector<std::string> findings;
  /// Failing control surveys none of which could be left out (kWarningControlBlunderUnresolved).
  std::vector<UnresolvedSurvey> unresolved_surveys;
  std::string unresolved_reason;
  SuspectEffect unresolved_effect;  // computed when unresolved_surveys is not empty
  std::vector<FlaggedObservation> flagged;
  /// Every active observation no test can judge, one by one (the counts above summarise them).
  std::vector<UncontrolledObservation> uncontrolled;
  double seconds_testing = 0;
  // Robust start: why it ran (forced or by the residuals), what it excluded and re-admitted.
  bool robust_start = false;
  std::string robust_start_reason;
  double gross_share = 0;  // of image components above robust_trigger_w in the first solve
  int robust_excluded = 0, robust_readmitted = 0;
  /// Excluded rays of points the clean solution did not hold (all or all but one of their rays
  /// excluded): handed back to snooping in the final adjustment instead of being dropped.
  int robust_retested = 0;
};

/// One image observation after the adjustment: residual v = measured - adjusted, in pixels of
/// the (corrected) photo space, (col, row) directions.
struct ObservationResidual {
  std::string image, point;
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();  // virtual-image (col, row)
  Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();
  double sigma_px = 0.0;
  bool used = true;      // false: rejected as a gross error
  std::string subimage;  // non-empty: measured in this raw sub-image at subimage_px (u, v)
  Eigen::Vector2d subimage_px = Eigen::Vector2d::Zero();
  std::string head;      // non-empty: measured_px is a pixel of this rig head
  ObservationTest test;  // the final test (or the one at its rejection)
};

struct Determinability {
  bool covariance_ok = false;
  std::string message;
  std::string covariance_method;  // calib::CovarianceReport::method
  /// Pairs with |rho| above the threshold that involve an interior parameter.
  std::vector<calib::HighCorrelation> high_correlations;
  std::vector<std::string> undetermined;  // null-space parameters (rank defect)
  std::vector<std::string> warnings;      // one human sentence per problem found
  bool determinable() const { return covariance_ok; }
};

/// A finding that makes a result doubtful, by name (calib/core/finding.h; JSON `warnings`:
/// [{name, subject, value, limit, message}]).
using ResultWarning = Finding;

/// Name of the warning for a residual group whose RMS in a-priori sigmas exceeds the limit: the
/// model does not fit those observations (or their sigmas are far too small).
inline constexpr const char* kWarningGroupRms = "group_rms";
/// The limit of that RMS, in sigmas: with right sigmas a group's RMS is about 1 (up to the
/// redundancy share), so 3 is far outside any chance.
inline constexpr double kGroupRmsLimit = 3.0;
/// Name of the warning for a control point whose survey data snooping left out as a suspected
/// control blunder (subject: the point id; value: w of its survey test; limit: the critical
/// value).
inline constexpr const char* kWarningControlBlunder = "control_blunder";
/// Name of the warning for failing control surveys that data snooping cannot resolve: the surveys
/// named (subject: their labels, e.g. "control C1 height, control C2 height") fail their test but
/// none can be singled out and left out (the test cannot tell them apart, or the block needs the
/// worst); value: the largest w; limit: the critical value. The result is not valid (exit 3): a
/// survey blunder somewhere in the datum is a model that does not fit.
inline constexpr const char* kWarningControlBlunderUnresolved = "control_blunder_unresolved";

/// One kWarningGroupRms warning per residual group of `solve` whose RMS exceeds `limit`.
std::vector<ResultWarning> GroupRmsWarnings(const calib::SolveReport& solve,
                                            double limit = kGroupRmsLimit);

/// Wall time of the stages of one BlockAdjustment::Run, s (JSON `timing`; for benchmarks and
/// profiling, not statistics).
struct AdjustmentTiming {
  double solve_s = 0;       // the solves before snooping (stage 1 of a self-calibration included)
  double snooping_s = 0;    // data snooping: its re-solves, cofactors and tests
  double testing_s = 0;     // of which the cofactors (selected inverse) and tests
  double covariance_s = 0;  // the covariance of the requested blocks
  double total_s = 0;       // the whole run (results and statistics included)
};

/// `--self-calibration auto` (self_calibration_choice.h): the candidates, the parameters held and
/// why, the free set chosen.
struct FreeSetChoice {
  std::vector<std::string> candidates, chosen;
  struct Held {
    std::string parameter;
    std::string reason;    // "not determinable" | "not significant"
    double statistic = 0;  // |rho| with `with`, or t
    std::string with;      // the parameter it is traded against (not determinable)
    int round = 0;
  };
  std::vector<Held> held;
  double significance_t = 0, correlation_limit = 0;
  int rounds = 0;
};

struct AdjustmentResult {
  calib::SolveReport solve;
  AdjustmentTiming timing;
  std::vector<std::string> free_interior;  // names; empty = conventional
  double sigma0 = 0, sigma0_px = 0, sigma0_um = 0;
  std::vector<CameraEstimate> cameras;
  std::vector<ExposureEstimate> exposures;
  std::vector<PointDifference> control_points, check_points;
  PointStatistics control, check;
  /// Control points whose survey data snooping left out, in whole or in part, as a suspected
  /// control blunder (it disagrees with the point's rays, every other survey fits without it; the
  /// rays stay): their survey against the position the block gives them (not in `control`). The
  /// plan (X, Y) and the height (Z) of a survey are tested and left out separately. JSON
  /// `control_left_out: [{point, surveyed_m, adjusted_m, difference_m, rays, w, components}]`
  /// (`components`: {"plan": w, "height": w} of the parts left out; `w` the largest).
  std::vector<LeftOutControl> control_left_out;
  /// After snooping: the check statistics over the check points whose rays are all controlled
  /// (PointDifference::uncontrolled empty). `check` stays the statistics of every check point.
  std::optional<PointStatistics> check_controlled;
  std::vector<RejectedObservation> rejected;
  std::vector<ObservationResidual> residuals;  // every image observation of the adjustment
  Determinability determinability;
  /// Correlation matrix of the interior parameters of every camera (free and fixed entries; a
  /// fixed one has a zero row), rows named "camera ID.NAME"; empty without a covariance. JSON
  /// `interior_correlation: {names, matrix}`.
  std::vector<std::string> interior_correlation_names;
  Eigen::MatrixXd interior_correlation;
  std::map<std::string, Eigen::Vector3d> points_m;  // adjusted coordinates of every point
  std::vector<std::string> notes;                   // points left out, and why
  std::string frame;                                // the object frame, stated
  std::string datum;                                // how the datum is defined, stated
  std::vector<ResultWarning> warnings;              // the result is doubtful: by name
  SnoopingSummary snooping;
  PlatformEstimate platform;
  std::optional<FreeSetChoice> free_set_choice;  // `--self-calibration auto` only
  /// False when the run must not be trusted: not converged, singular, rejection cap reached,
  /// sigma0 above AdjustOptions::max_sigma0; `invalid_reasons` says why (exit 3).
  bool valid = true;
  std::vector<std::string> invalid_reasons;
  /// Set by BlockAdjustment::Run when it stopped early because the first solve's residuals call
  /// for a robust start (only with StopWhenRobustStartNeeded).
  bool robust_start_needed = false;

  bool converged() const { return solve.converged; }
  /// Marks the result invalid with a reason (kept once).
  void Invalidate(const std::string& reason);
};

/// After snooping (result->snooping.run): lists every used observation with a component r <
/// min_redundancy in snooping.uncontrolled with the reason, marks the check points resting on
/// such a ray (PointDifference::uncontrolled) and sets check_controlled over the others.
void ClassifyUncontrolled(double min_redundancy, AdjustmentResult* result);

/// JSON of FORMATS.md (kind "adjust", schema_version ResultSchemaVersion("adjust") of
/// calib/core/result_file.h, written by WriteResult); angles in degrees, coordinates in the object
/// frame. `camera_model` is the model of its cameras with its parameter table
/// (calib::CameraModelTableToJson; the first camera's when they differ: each camera entry names
/// its `model`).
nlohmann::json AdjustmentToJson(const AdjustmentResult& result);
nlohmann::json PointStatisticsToJson(const PointStatistics& statistics);

/// Side-by-side text of two adjustments of the same block (conventional vs self-calibrating):
/// control / check RMSE per axis, sigma0 in um and px, and the calibration table (initial,
/// correction, estimate, sigma) per parameter.
std::string FormatComparison(const AdjustmentResult& conventional,
                             const AdjustmentResult& self_calibrating);
/// The same comparison as JSON: {conventional: {...}, self_calibration: {...}, ratio_check_rmse}.
nlohmann::json ComparisonToJson(const AdjustmentResult& conventional,
                                const AdjustmentResult& self_calibrating);
/// Short text summary of one adjustment (statistics, calibration table, warnings).
std::string FormatSummary(const AdjustmentResult& result);

/// The camera with its interior replaced by the estimate (sub-images carried along unchanged).
calib::Camera UpdatedCamera(const calib::Camera& camera, const CameraEstimate& estimate);

}  // namespace aerocal::triangulation
