// The steps of one line-camera calibration (CalibrateLineCamera, line_calibration.h), each a
// function of the run's state, in the order the driver calls them:
//   set-up   (line_calibration_setup.cc): the sensor kind and its blocks, the control points, the
//            image observations, the segment coverage, the entries above the start degree;
//   datum    (line_datum.cc): the null space as configured, the gauge or reference datum;
//   solve    (line_calibration_solve.cc): the solve, the covariance, the degree test, the RMS per
//            sub-camera, sigma0 in px and the validity rules (not converged, sigma0, covariance);
//   results  (line_calibration_results.cc): the detector table and its sigmas, the error samples,
//            the trajectory, c / boresight / lever arm / time offset, the updated camera;
//   correlations (line_correlations.cc): the named correlations and their warnings.
// Internal to triangulation/pushbroom: the public interface is line_calibration.h.
#pragma once

#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/block/platform.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_degree_choice.h"
#include "triangulation/sensor/frame_camera.h"
#include "triangulation/sensor/line_scan_camera.h"

#include <map>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation::internal {

/// u in [-1, 1] of detector i in its sub-camera's range (module README "The model").
inline double NormalisedIndex(const std::pair<int, int>& range, int i) {
  return calib::LinePolynomial{range.first, range.second, {}, {}}.Normalised(i);
}

/// The state of one calibration. Not copyable: the sensor context, the problem's blocks and the
/// kind's residuals point into it.
struct LineRun {
  LineRun(const calib::LineCamera& camera,
          const PosTrajectory& pos,
          const LineCalibrationOptions& options,
          const std::string& observations_file);
  LineRun(const LineRun&) = delete;
  LineRun& operator=(const LineRun&) = delete;

  const calib::LineCamera& camera;
  const PosTrajectory& pos;
  const LineCalibrationOptions& options;
  const std::string& observations_file;
  const std::vector<std::pair<int, int>> ranges;  // detector range of each sub-camera
  const int n_sub;
  const int reference;  // the sub-camera carrying the datum
  std::vector<std::string> sub_ids;
  const double first_line, last_line;
  const int spacing, n_nodes;
  const int start_degree;  // --degree, else --max-degree

  // The line camera as a sensor kind (triangulation/sensor/line_scan_camera.h): it owns the
  // spline nodes, detector polynomials, c, mount and lever arm, and builds the residual of every
  // observation; the calibration owns the control points, the datum, the degree test and the
  // report. A line strip is not a block of frame exposures: its SensorContext has an empty
  // project (the observations file named in errors) and no exposure poses.
  Project strip;
  const AdjustOptions adjust_options{};
  const DenseIndex dense_index;
  const std::vector<PoseBlocks> no_poses;
  const FrameCamera no_frame{};
  calib::ProblemBuilder builder;
  LineScanCamera sensor;
  const SensorContext context;

  std::vector<Eigen::Vector3d> point_values;       // the control points' blocks point into it
  std::vector<calib::ResidualId> image_residuals;  // in the order of the kind's Terms()
  std::vector<std::set<int>> fixed_entries;        // per detector block: above the degree
  std::vector<std::set<int>> datum_entries;        // per detector block: held by the datum

  // The datum as applied (line_datum.cc).
  calib::ResidualId datum_residual = -1;
  bool time_offset_in_null_space = false;

  std::vector<calib::BlockId> cov_blocks;  // the blocks the covariance is computed for
  calib::CovarianceReport cov;
  std::vector<TableValue> start_table;  // the start-degree table, after a reduction only

  LineCalibrationResult result;
};

// ---- set-up (line_calibration_setup.cc) ----
/// Observation counts per spline segment (first node j) and per node.
struct LineCoverage {
  std::vector<int> per_segment, per_node;
};
/// The control points as weighted ground points; the other roles are not usable by one line
/// camera (one ray per point). Block of each control point by id.
std::map<std::string, calib::BlockId> AddControlPoints(LineRun& run,
                                                       const std::vector<GroundPoint>& points);
/// Every observation of a control point, built by the kind; InputError by FILE:LINE for a point
/// behind the camera at the start, or when no observation reaches a control point.
LineCoverage AddImageObservations(LineRun& run,
                                  const std::vector<LineObservation>& observations,
                                  const std::map<std::string, calib::BlockId>& control);
/// Warnings few_points_per_line; a node no observation reaches is fixed without the POS prior.
void CheckCoverage(LineRun& run, const LineCoverage& coverage);
/// The polynomial entries above the start degree are held; the reference datum's entries noted.
void HoldEntriesAboveStartDegree(LineRun& run);
/// Hands the fixed entries of every sub-camera to the kind (their values to 0).
void ApplyFixedEntries(LineRun& run);

// ---- datum (line_datum.cc) ----
/// (Re)derives the datum from the null space of the problem as configured (header of
/// line_calibration.h): result.datum, time_offset_in_null_space, the datum residual.
void DeriveDatum(LineRun& run);
/// Whether the datum's constraints act on the reference sub-camera's polynomial block.
bool DatumOnReference(const LineRun& run);

// ---- solve and statistics (line_calibration_solve.cc) ----
/// Solves and estimates the covariance of the calibrated blocks (run.cov; empty when unusable).
void SolveAndEstimateCovariance(LineRun& run);
/// The per-detector table (values and variances, axis-major) at the current solution.
std::vector<TableValue> DetectorTable(const LineRun& run, const calib::CovarianceReport& cov);
/// The top-down degree test per sub-camera and axis (line_degree_choice.h); re-solves when it
/// drops a term. Not applied with --degree nor when sigma0 ~ 0: the start degree.
void ApplyDegreeTest(LineRun& run);
/// RMS of the whitened image residuals per sub-camera (before the solve or after it).
void RmsBySubcamera(LineRun& run, bool after);
/// sigma0 and the RMS in px: the whitened values times the median image sigma.
void ScaleToPixels(LineRun& run, const std::vector<LineObservation>& observations);
/// Not converged, sigma0 above its limit, no covariance, undetermined parameters: by name.
void CheckSolve(LineRun& run);

// ---- results (line_calibration_results.cc) ----
/// The a-posteriori sigma of one entry; nullopt when fixed or without a covariance.
std::optional<double> EntrySigma(const LineRun& run, calib::BlockId block, int entry);
void CollectDetectorCalibration(LineRun& run);
void CollectErrorSamples(LineRun& run);
void CollectTrajectory(LineRun& run);
/// c, boresight, lever arm and time offset with their sigmas; the requested parameters the null
/// space reaches (not determined by the data) by name.
void CollectMountedParameters(LineRun& run);
/// The updated camera: design + the estimated calibration.
void CollectUpdatedCamera(LineRun& run);

// ---- correlations (line_correlations.cc) ----
/// The named correlations (result.correlations) and their warnings; needs the covariance.
void NameCorrelations(LineRun& run);

}  // namespace aerocal::triangulation::internal
