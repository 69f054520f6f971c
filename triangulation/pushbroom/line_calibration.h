// Calibration of a line (pushbroom) camera from cloud control points (issue 17; module README):
// one joint adjustment, through calib::ProblemBuilder, of
// - per-line exterior-orientation corrections to the POS, a uniform cubic B-spline in the line
// index
//   with nodes every `node_spacing_lines` lines (6 values per node: dX, dY, dZ m, domega, dphi,
//   dkappa rad, added to the POS position and angles), with the POS sigmas as priors on the node
//   values (the POS error is modelled as smooth; white POS noise stays in the residuals);
// - the detector calibration: a polynomial per sub-camera and axis in the normalised index
//   (degree <= 5, jumps allowed at the seams), its degree chosen top-down by a Wald test of the
//   highest coefficient (alpha 5 %; not for the datum's sub-camera; line_degree_choice.h), giving
//   dx_i, dy_i with sigmas for every detector (after a reduction: SelectedTableSigma, which
//   accounts for the selection);
// - the control points as weighted ground points (their survey sigmas);
// - optionally the principal distance c (`free_c`; it is nearly a scale of the table).
// Datum (module README "Datum"), `datum`:
// - kGauge (default): derived from the null space of the problem as configured (c fixed or free,
//   boresight and lever-arm modes, POS priors on or off): the rank defect k of the reduced normal
//   matrix without a datum (ProblemBuilder::NullSpace) is counted, and exactly k constraints are
//   put on the reference sub-camera's polynomial block (then, only if the gauge does not reach it
//   fully, on the mount, lever arm, c and the spline nodes): the projection of the parameters
//   onto the null space's components there is held at its start value (C V nonsingular, so the
//   fit, sigma0 and every gauge-invariant quantity equal those of the datum-free problem). With
//   the POS priors on and the boresight and lever arm fixed the defect is 0: nothing is held.
//   The gauge functions found (pitch, roll, yaw, scale in the table) are named in the result.
// - kReference: the earlier datum, kept for an explicit request only: the reference sub-camera's
//   Legendre mean and slope per axis are zero (LineDatumResidual, 4 constraints whatever the
//   null space): it over-constrains (holds the scale and the mean roll, which the control and the
//   POS determine) unless the defect is exactly those four functions.
// - kNone: no datum; an undetermined problem is reported ill-posed by name.
// The sub-camera that carries the constraints (gauge, reference) keeps the start degree.
#pragma once

#include "calib/camera/line_camera.h"
#include "calib/core/finding.h"
#include "calib/problem/problem_builder.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/line_scan_camera.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

enum class LineDatum { kGauge, kReference, kNone };
/// "gauge", "reference", "none" (the --datum values).
const char* LineDatumName(LineDatum datum);

struct LineCalibrationOptions {
  int node_spacing_lines = 100;         // spline node spacing N, lines, >= 1
  int max_degree = 5;                   // highest polynomial degree tried, 0 .. 5
  std::optional<int> degree;            // a fixed degree (0 .. 5) instead of the test
  double degree_test_alpha = 0.05;      // significance of the top-down Wald test, (0, 0.5)
  LineDatum datum = LineDatum::kGauge;  // the datum (header comment)
  int reference_subcamera = -1;         // the sub-camera carrying the datum; -1: the middle one
  // Relative eigenvalue (of the Jacobi-scaled reduced normal matrix) below which a direction is
  // a gauge freedom, (0, 1e-3]. The angular residual makes the rotation and scale gauges exact
  // (1e-16 .. 1.5e-10); a time offset without the POS priors is a near-gauge at 2.1e-8 (only the
  // spline's representation error of the shifted POS "determines" it: +-1 s); the weakest
  // determined direction measured lies at 7.5e-7 (no POS priors: position against attitude,
  // told apart by the relief). 1e-7 lies a factor 4.8 or more from both (module README "Datum").
  double gauge_threshold = 1e-7;
  bool free_c = false;                    // estimate c (nearly a scale of the table: scale_vs_c)
  bool pos_prior = true;                  // the POS sigmas as priors on the node values
  double pos_sigma_m = 0.05;              // used when pos.csv gives no sigmas, > 0
  double pos_sigma_deg = 0.005;           // used when pos.csv gives no sigmas, > 0
  int min_observations_per_segment = 12;  // fewer between two nodes: few_points_per_line
  double correlation_warn = 0.95;         // |rho| above: warning by name
  double correlation_fail = 0.999;  // |rho| above: the result cannot be trusted (valid = false)
  double max_sigma0 = 3.0;          // sigma0 above: valid = false (absurd a-priori sigmas)
  // Boresight (the camera file's mount M) and lever arm: fixed at the file's values (default),
  // free, or weighted around them with these sigmas (as PlatformSpec of a frame block).
  PlatformParamMode boresight = PlatformParamMode::kFixed;
  double boresight_sigma_rad = 0.0;  // weighted: per angle, rad, > 0
  PlatformParamMode lever_arm = PlatformParamMode::kFixed;
  double lever_arm_sigma_m = 0.0;  // weighted: per axis, m, > 0
  // Estimate a time offset dt (s) of the line camera against the POS (shutter / POS latency;
  // LineScanCamera "time_offset"). It is an along-track shift v dt plus the attitude change over
  // dt: only the POS priors tell it from the trajectory's along-track and pitch corrections
  // (named time_offset_vs_along_track); without them it is not determinable (named, invalid).
  bool time_offset = false;
  calib::SolverOptions solver;
  void Validate() const;  // ConfigError naming the option
};

/// One image measurement: detector position (col) on scan line (row).
struct LineObservation {
  std::string point;
  double detector = 0.0, line = 0.0;
  double sigma_px = 0.3;
  int source_line = 0;
};

using LineWarning = Finding;  // calib/core/finding.h

struct SubcameraRms {
  std::string id;
  int first = 0, last = 0, n = 0;
  double across_before_px = 0, along_before_px = 0, across_after_px = 0, along_after_px = 0;
  int degree_x = 0, degree_y = 0;
  std::vector<double> dx_coefficients_mm, dy_coefficients_mm;   // estimated polynomial (all terms)
  std::vector<std::optional<double>> dx_sigma_mm, dy_sigma_mm;  // null: fixed (degree)
};

/// One observation's reprojection error without the detector calibration, at the adjusted
/// trajectory (the points the detector polynomial fits; plots): focal-plane error in pitches
/// (px), across (x) and along (y) track.
struct LineErrorSample {
  double detector = 0.0;
  int subcamera = 0;
  double across_px = 0.0, along_px = 0.0;
};

/// The datum as derived and applied (result.json "datum").
struct LineDatumReport {
  LineDatum mode = LineDatum::kGauge;
  bool null_space_computed = false;
  std::string message;                                // why the null space was not computed
  int rank_defect = 0;                                // of the normal matrix WITHOUT a datum
  double threshold = 0.0;                             // relative eigenvalue threshold
  std::vector<double> smallest_relative_eigenvalues;  // ascending, without the datum
  int n_constraints = 0;                              // constraints the datum adds
  std::string subcamera;                              // the reference sub-camera's id
  std::vector<std::string> blocks;                    // the blocks the constraints act on
  /// Gauge functions of the detector table found in the null space: name (pitch: a constant
  /// along-track shift c + y^2/c; roll: the across-track c + x^2/c; yaw: (-y, x); scale: (x, y)),
  /// the fraction of its norm over the table that the null space holds (1: a gauge freedom) and
  /// what it means. `in_table` of the defect: the directions the table takes part in; the rest
  /// (e.g. a free boresight against a trajectory without POS priors) lie outside it.
  struct Direction {
    std::string name;
    double fraction = 0.0;
    std::string meaning;
  };
  std::vector<Direction> directions;
  int in_table = 0;
  /// Parameters asked for (c, boresight, lever_arm, time_offset) that the null space reaches:
  /// not determined by the data (named warnings, the result is not valid unless the datum is
  /// the explicit `reference` convention).
  std::vector<std::string> parameters_in_null_space;
};

struct LineCalibrationResult {
  calib::SolveReport report;
  LineDatumReport datum;
  bool valid = true;  // false: cannot be trusted (warnings say why)
  std::vector<LineWarning> warnings;
  double sigma0_px = 0.0;
  std::vector<SubcameraRms> subcameras;
  /// Per detector: the estimated calibration (mm) and its sigma (mm, null when not determined).
  /// After a degree test the sigma is SelectedTableSigma (line_degree_choice.h): at least the
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
  /// The time offset (s) when estimated, and its sigma (null when not estimated or determined).
  bool time_offset_estimated = false;
  double time_offset_s = 0.0;
  std::optional<double> time_offset_sigma_s;
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
void WriteLineObservations(const std::string& path,
                           const std::vector<LineObservation>& observations);

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
