// Calibration of a line (pushbroom) camera from cloud control points (issue 17; module README):
// one joint adjustment, through calib::ProblemBuilder, of
// - per-line exterior-orientation corrections to the POS, a uniform cubic B-spline in the line index
//   with nodes every `node_spacing_lines` lines (6 values per node: dX, dY, dZ m, domega, dphi,
//   dkappa rad, added to the POS position and angles), with the POS sigmas as priors on the node
//   values (the POS error is modelled as smooth; white POS noise stays in the residuals);
// - the detector calibration: a polynomial per sub-camera and axis in the normalised index
//   (degree <= 5, jumps allowed at the seams), its degree chosen top-down by a Wald test of the
//   highest coefficient (alpha 5 %; not for the datum's sub-camera; line_degree_test.h), giving
//   dx_i, dy_i with sigmas for every detector (after a reduction: SelectedTableSigma, which
//   accounts for the selection);
// - the control points as weighted ground points (their survey sigmas);
// - optionally the principal distance c (`free_c`; it is nearly a scale of the table).
// Datum (module README "Datum"): the reference sub-camera's correction (on top of the file's) has
// zero Legendre mean and slope in x and y (LineDatumResidual), whatever its degree; it keeps the
// start degree (the degree test leaves it). The common along-track offset is exactly a pitch, the
// common across-track offset nearly a roll, the slopes nearly kappa and the scale; the trajectory
// corrections take them. `reference_datum = false` frees them: the result is then reported
// ill-posed by name (offset_vs_roll, offset_vs_pitch, scale_vs_c) with the correlations.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "calib/camera/line_camera.h"
#include "calib/problem/problem_builder.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/line_scan_camera.h"

namespace aerocal::triangulation {

struct LineCalibrationOptions {
  int node_spacing_lines = 100;       // spline node spacing N, lines, >= 1
  int max_degree = 5;                 // highest polynomial degree tried, 0 .. 5
  std::optional<int> degree;          // a fixed degree (0 .. 5) instead of the test
  double degree_test_alpha = 0.05;    // significance of the top-down Wald test, (0, 0.5)
  bool reference_datum = true;        // the reference sub-camera's Legendre mean + slope = 0
  int reference_subcamera = -1;       // index; -1: the middle one
  bool free_c = false;                // estimate c (nearly a scale of the table: scale_vs_c)
  bool pos_prior = true;              // the POS sigmas as priors on the node values
  double pos_sigma_m = 0.05;          // used when pos.csv gives no sigmas, > 0
  double pos_sigma_deg = 0.005;       // used when pos.csv gives no sigmas, > 0
  int min_observations_per_segment = 12;  // fewer between two nodes: few_points_per_line
  double correlation_warn = 0.95;     // |rho| above: warning by name
  double correlation_fail = 0.999;    // |rho| above: the result cannot be trusted (valid = false)
  double max_sigma0 = 3.0;            // sigma0 above: valid = false (absurd a-priori sigmas)
  // Boresight (the camera file's mount M) and lever arm: fixed at the file's values (default),
  // free, or weighted around them with these sigmas (as PlatformSpec of a frame block).
  PlatformParamMode boresight = PlatformParamMode::kFixed;
  double boresight_sigma_rad = 0.0;   // weighted: per angle, rad, > 0
  PlatformParamMode lever_arm = PlatformParamMode::kFixed;
  double lever_arm_sigma_m = 0.0;     // weighted: per axis, m, > 0
  calib::SolverOptions solver;
  void Validate() const;              // ConfigError naming the option
};

/// One image measurement: detector position (col) on scan line (row).
struct LineObservation {
  std::string point;
  double detector = 0.0, line = 0.0;
  double sigma_px = 0.3;
  int source_line = 0;
};

struct LineWarning {
  std::string name, subject;
  double value = 0.0, limit = 0.0;
  std::string message;
};

struct SubcameraRms {
  std::string id;
  int first = 0, last = 0, n = 0;
  double across_before_px = 0, along_before_px = 0, across_after_px = 0, along_after_px = 0;
  int degree_x = 0, degree_y = 0;
  std::vector<double> dx_coefficients_mm, dy_coefficients_mm;  // estimated polynomial (all terms)
  std::vector<std::optional<double>> dx_sigma_mm, dy_sigma_mm; // null: fixed (degree)
};

/// One observation's reprojection error without the detector calibration, at the adjusted
/// trajectory (the points the detector polynomial fits; plots): focal-plane error in pitches
/// (px), across (x) and along (y) track.
struct LineErrorSample {
  double detector = 0.0;
  int subcamera = 0;
  double across_px = 0.0, along_px = 0.0;
};

struct LineCalibrationResult {
  calib::SolveReport report;
  bool valid = true;               // false: cannot be trusted (warnings say why)
  std::vector<LineWarning> warnings;
  double sigma0_px = 0.0;
  std::vector<SubcameraRms> subcameras;
  /// Per detector: the estimated calibration (mm) and its sigma (mm, null when not determined).
  /// After a degree test the sigma is SelectedTableSigma (line_degree_test.h): at least the
  /// start-degree fit's; the selected polynomial's own propagated sigma is the fit sigma.
  std::vector<double> dx_mm, dy_mm;
  std::vector<std::optional<double>> dx_sigma_mm, dy_sigma_mm;
  std::vector<std::optional<double>> dx_fit_sigma_mm, dy_fit_sigma_mm;
  /// The degree test: whether it ran (not with --degree, nor on noise-free data), at which
  /// start degree and alpha, and whether it dropped a term (the table sigmas then follow
  /// SelectedTableSigma).
  struct DegreeTest {
    bool applied = false, reduced = false;
    int start_degree = 0;
    double alpha = 0.0;
  } degree_test;
  std::vector<LineErrorSample> error_samples;  // one per image observation used
  /// Spline nodes: line of each node's centre, values [dX dY dZ m, domega dphi dkappa rad], sigmas.
  std::vector<double> node_line;
  std::vector<Eigen::Matrix<double, 6, 1>> node_values, node_sigma;
  /// Per scan line (first .. last line of the POS): corrections and their sigmas.
  std::vector<double> lines;
  std::vector<Eigen::Matrix<double, 6, 1>> line_corrections, line_sigma;
  double c_mm = 0.0;
  std::optional<double> c_sigma_mm;
  /// Boresight (the camera's mount M, omega phi kappa) and lever arm (body frame): how they were
  /// estimated, their values and sigmas (null when fixed or not determined).
  PlatformParamMode boresight = PlatformParamMode::kFixed, lever_arm = PlatformParamMode::kFixed;
  Eigen::Vector3d boresight_rad = Eigen::Vector3d::Zero(), lever_arm_m = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> boresight_sigma_rad, lever_arm_sigma_m;
  /// Named correlations (max |rho| over the pairs of that kind; absent when not computed).
  std::vector<std::pair<std::string, double>> correlations;
  calib::LineCamera camera;  // the updated camera (polynomial calibration)
  int n_observations = 0, n_control = 0, n_ignored = 0;
  std::vector<std::string> undetermined;
};

/// Reads observations.csv of a line camera (`point,col,row[,sigma_px]`; `image` optional and
/// ignored: one strip): col = detector position, row = scan line.
std::vector<LineObservation> ReadLineObservations(const std::string& path, double default_sigma_px);

/// Writes observations.csv (`image,point,col,row,sigma_px`, image "strip"; full precision).
void WriteLineObservations(const std::string& path, const std::vector<LineObservation>& observations);

LineCalibrationResult CalibrateLineCamera(const calib::LineCamera& camera,
                                          const PosTrajectory& pos,
                                          const std::vector<LineObservation>& observations,
                                          const std::vector<GroundPoint>& points,
                                          const LineCalibrationOptions& options,
                                          const std::string& observations_file);
/// Per-line corrections as CSV: line,dX,dY,dZ,domega,dphi,dkappa + sigmas (m, deg).
std::string LineCorrectionsToCsv(const LineCalibrationResult& result);

/// result.json (FORMATS.md "Results": kind "pushbroom" plus the keys of the module README; written
/// by WriteResult of calib/core/result_file.h with its schema_version).
nlohmann::json LineCalibrationToJson(const LineCalibrationResult& result);

}  // namespace aerocal::triangulation
