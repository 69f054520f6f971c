// What a block adjustment reports (FORMATS.md "Results", kind "adjust"): sigma0 (unitless, px,
// um), redundancy, convergence, per camera the initial / estimated interior with sigmas, exterior
// orientations with sigmas, control and check statistics (CONVENTIONS.md "Statistics": RMSE, mean,
// max |d| per axis, planimetric and spatial RMSE), rejected observations, and the determinability
// of the free parameters (correlations above the threshold, null-space parameters).
#pragma once

#include "calib/camera/camera.h"
#include "calib/problem/problem_builder.h"

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

struct CameraEstimate {
  std::string id;
  calib::InteriorParams initial{}, estimated{}, sigma{};  // table units; sigma 0 when fixed
  std::array<bool, calib::BrownFraser10Model::kNumParams> free{};
};

struct ExposureEstimate {
  std::string image;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> center_sigma_m, opk_sigma_rad;  // when the covariance is known
};

struct RejectedObservation {
  std::string image, point;
  Eigen::Vector2d measured_px = Eigen::Vector2d::Zero();  // the observation (col, row), or (u, v)
  Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();  // v in (corrected) photo space, px
  double w = 0.0;                                         // standardized residual
  std::string subimage;  // non-empty: measured_px is (u, v) in this raw sub-image
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

/// A finding that makes a result doubtful, by name, for people and programs (JSON `warnings`:
/// [{name, subject, value, limit, message}]).
struct ResultWarning {
  std::string name;     // kWarningGroupRms, ...
  std::string subject;  // what it is about (for kWarningGroupRms the residual group)
  double value = 0, limit = 0;
  std::string message;  // one sentence for people
};

/// Name of the warning for a residual group whose RMS in a-priori sigmas exceeds the limit: the
/// model does not fit those observations (or their sigmas are far too small).
inline constexpr const char* kWarningGroupRms = "group_rms";
/// The limit of that RMS, in sigmas: with right sigmas a group's RMS is about 1 (up to the
/// redundancy share), so 3 is far outside any chance.
inline constexpr double kGroupRmsLimit = 3.0;

/// One kWarningGroupRms warning per residual group of `solve` whose RMS exceeds `limit`.
std::vector<ResultWarning> GroupRmsWarnings(const calib::SolveReport& solve, double limit = kGroupRmsLimit);

struct AdjustmentResult {
  calib::SolveReport solve;
  std::vector<std::string> free_interior;  // names; empty = conventional
  double sigma0 = 0, sigma0_px = 0, sigma0_um = 0;
  std::vector<CameraEstimate> cameras;
  std::vector<ExposureEstimate> exposures;
  std::vector<PointDifference> control_points, check_points;
  PointStatistics control, check;
  std::vector<RejectedObservation> rejected;
  std::vector<ObservationResidual> residuals;  // every image observation of the adjustment
  Determinability determinability;
  std::map<std::string, Eigen::Vector3d> points_m;  // adjusted coordinates of every point
  std::vector<std::string> notes;                   // points left out, and why
  std::string frame;                                // the object frame, stated
  std::string datum;                                // how the datum is defined, stated
  std::vector<ResultWarning> warnings;              // the result is doubtful: by name

  bool converged() const { return solve.converged; }
};

/// JSON of FORMATS.md (kind "adjust"); angles in degrees, coordinates in the object frame.
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
