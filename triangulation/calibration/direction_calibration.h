// Laboratory geometric calibration from known directions (issue 36 item 6): a collimator array
// (every target's direction known in the instrument frame, each cross measured in the image) or a
// goniometer (the camera turned by known instrument rotations G_k, one fixed target of unknown
// direction measured at every setting). The unknowns are the camera's rotation to the instrument
// and the interior orientation and distortion in the camera file's model; no position, no scale.
// The residual is calib/residuals/direction.h; the problem is built by calib/problem's builder
// (residual group "direction").
//
// A direction's angular sigma (a collimator's direction or a goniometer setting) is folded into
// its observation's focal-plane covariance (DirectionCovarianceMm2 at the start camera's c): each
// observation has its own direction error, so this is the rigorous weighting; a target seen in
// several images would need its angles as weighted unknowns instead (not done).
#pragma once

#include "calib/camera/camera.h"
#include "calib/problem/problem_builder.h"

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace aerocal::triangulation {

inline constexpr const char* kGroupDirection = "direction";

struct DirectionTarget {
  std::string id;
  Eigen::Vector2d angles_rad =
      Eigen::Vector2d::Zero();  // azimuth, elevation (direction.h); start value when !known
  bool known = true;            // a collimator: known (fixed); a goniometer's target: estimated
};

struct DirectionObservation {
  std::string target;   // id of a DirectionTarget
  std::string setting;  // names the instrument setting in labels ("" for a collimator array)
  Eigen::Matrix3d instrument_rotation = Eigen::Matrix3d::Identity();  // G of direction.h
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // measured (col, row), camera pixel frame
  double sigma_px = 0.1;                            // image measurement sigma, > 0
  double sigma_rad = 0.0;  // angular sigma of the direction (collimator or setting), >= 0
  std::string where;       // FILE:LINE of the observation for messages ("" : its number)
};

struct DirectionCalibrationOptions {
  std::vector<std::string> free_interior = {
      "c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};
  calib::SolverOptions solver;
};

struct DirectionCalibration {
  calib::SolveReport report;
  calib::Camera camera;                // the start camera with the estimated interior
  std::vector<double> interior_sigma;  // a-posteriori, table order (0 for fixed entries)
  /// A-posteriori covariance of the interior, table order and units (zero rows and columns for
  /// fixed entries); empty when !covariance_ok.
  Eigen::MatrixXd interior_covariance;
  std::vector<calib::HighCorrelation> high_correlations;  // |rho| > 0.95 of free parameters
  std::vector<std::string> undetermined;                  // null-space parameters (rank defect)
  /// Per observation: v = measured - adjusted in the (corrected) photo space, (col, row) px; and
  /// its a-priori sigma sqrt(trace(C) / 2) / pixel size (C of DirectionCovarianceMm2: the image
  /// measurement and the direction's angular sigma), px.
  std::vector<Eigen::Vector2d> residual_px;
  std::vector<double> apriori_sigma_px;
  Eigen::Vector3d opk_rad =
      Eigen::Vector3d::Zero();  // R (instrument_from_camera) as omega, phi, kappa
  Eigen::Vector3d opk_sigma_rad = Eigen::Vector3d::Zero();
  std::map<std::string, Eigen::Vector2d> target_angles_rad;  // estimated (unknown) targets
  std::map<std::string, Eigen::Vector2d> target_sigma_rad;
  std::string method;  // "collimator array" (every target known) or "goniometer"
  bool covariance_ok = false;
};

/// One camera unit of a multi-unit instrument: a sub-image (CCD) of a multi-CCD camera or a head
/// of a rig, with its own interior (camera model, format) and its own mount on the instrument.
struct DirectionUnit {
  std::string id;       // sub-image or head id ("" for a single camera)
  calib::Camera start;  // start interior, format and model of the unit
  Eigen::Vector3d start_opk_rad = Eigen::Vector3d::Zero();  // start of instrument_from_unit
  std::vector<DirectionObservation> observations;
};

/// The units of one instrument calibrated in ONE adjustment: a shared instrument rotation R (the
/// first unit's, instrument_from_reference), per unit its interior and its mount M_k =
/// reference_from_unit (M = identity for the first unit), the targets' directions shared by all.
/// The problem is parameterised by each unit's rotation to the instrument, R_k = R M_k: a
/// one-to-one reparameterisation of (R, M_2 .. M_n), so the estimate, sigma0 and the covariance
/// (propagated through M_k = R_1^T R_k with the joint cross-covariance) are those of the
/// (R, M) parameterisation. Units are coupled by the targets they share (a goniometer's fixed
/// target seen by several heads) and by the common sigma0.
struct DirectionUnitsCalibration {
  calib::SolveReport report;
  std::string method;                       // "collimator array" or "goniometer"
  std::vector<DirectionCalibration> units;  // per unit: camera, sigmas, residuals, R_k (opk_rad)
  /// Per unit: M_k = R_1^T R_k as omega, phi, kappa and its sigma (zero for the first unit).
  std::vector<Eigen::Vector3d> mount_opk_rad, mount_sigma_rad;
  std::map<std::string, Eigen::Vector2d> target_angles_rad, target_sigma_rad;
  bool covariance_ok = false;
};

/// Adjusts every unit's observations of `targets` in one problem (DirectionUnitsCalibration).
/// Throws as CalibrateFromDirections, naming the unit; LogicError without units.
DirectionUnitsCalibration CalibrateUnitsFromDirections(
    const std::vector<DirectionUnit>& units,
    const std::vector<DirectionTarget>& targets,
    const DirectionCalibrationOptions& options = {});

/// Adjusts `observations` of `targets` starting from `start` (interior, format, model) and the
/// rotation `start_opk_rad` (CalibrateUnitsFromDirections with one unit). Throws InputError naming
/// the observation for an unknown target id, a sigma out of range or a parameter name not in the
/// model's table.
DirectionCalibration CalibrateFromDirections(const calib::Camera& start,
                                             const Eigen::Vector3d& start_opk_rad,
                                             const std::vector<DirectionTarget>& targets,
                                             const std::vector<DirectionObservation>& observations,
                                             const DirectionCalibrationOptions& options = {});

/// A start of R (instrument_from_camera, as omega, phi, kappa) from the known targets: the rotation
/// that best turns the start camera's rays u (principal distance and point, no distortion) into
/// the known directions turned back by their settings, G^T t = R u (Wahba's problem, solved by the
/// SVD of sum (G^T t) u^T). Zero when fewer than two distinct known targets are observed.
Eigen::Vector3d StartRotationFromDirections(const calib::Camera& start,
                                            const std::vector<DirectionTarget>& targets,
                                            const std::vector<DirectionObservation>& observations);

/// Start angles of the targets not known: the first observation's ray of the start camera turned
/// into the instrument frame, t = G R u (the azimuth and elevation of t).
void StartUnknownTargets(const calib::Camera& start,
                         const Eigen::Vector3d& start_opk_rad,
                         const std::vector<DirectionObservation>& observations,
                         std::vector<DirectionTarget>* targets);

}  // namespace aerocal::triangulation
