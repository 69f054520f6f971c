// A simulated flight of a combined line camera (issue 17, `aerocal simulate --pushbroom`,
// geometry mode): three line cameras looking -tilt / 0 / +tilt across track (optical axes meeting
// in one point), combined into one virtual line camera; smooth per-detector errors (a cubic per
// sub-camera and axis, jumps at the seams); a flight along +Y with smooth attitude and position
// variation; a POS whose error is a smooth cubic B-spline (random node values with the POS sigmas,
// nodes every `node_spacing_lines`); terrain; cloud control points with coordinate noise; image
// measurements with noise; truth files.
//
// Truth, exactly as the calibration models it (module README "Simulation"):
// - the true body pose at a fractional line is the POS interpolation (pos_trajectory.h) of the
//   true per-line poses; the POS rows are the true rows plus the spline error at each line;
// - without `subcamera_error_px` the reference (middle) sub-camera's true errors have zero
//   Legendre mean and slope (the earlier datum, --datum reference); with it every sub-camera has
//   its own offset, scale, rotation and curvature error.
#pragma once

#include "calib/camera/line_camera.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/pos_trajectory.h"

#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct LineSimulationOptions {
  int detectors_per_camera = 300;  // per sub-camera, 10 .. 100000
  double tilt_deg = 20.0;          // across-track look angle of the outer cameras, 0 .. 40
  double pitch_mm = 0.01;          // detector pitch, > 0
  double overlap = 0.05;           // fraction of a sub-camera's field shared with its neighbour
  int lines = 2000;                // scan lines, 20 .. 1e6
  double height_m = 1000.0;        // flying height above the mean terrain, > 0
  double speed_m_s = 60.0;         // ground speed, > 0
  double relief_m = 100.0;         // terrain relief peak to peak, >= 0
  int control_points = 1500;       // cloud control points placed in the swath
  double image_noise_px = 0.25;    // measurement noise (col and row), >= 0
  double image_sigma_px = 0.25;    // a-priori sigma written, > 0
  double control_noise_m = 0.1;    // coordinate noise of the control points, >= 0
  double control_sigma_m = 0.1;    // their a-priori sigma written, > 0
  double pos_error_m = 0.05;       // sigma of the POS error spline nodes (position), >= 0
  double pos_error_deg = 0.005;    // sigma of the POS error spline nodes (attitude), >= 0
  int node_spacing_lines = 100;    // of the POS error spline, >= 1
  double detector_error_px = 0.5;  // size of the smooth per-detector errors, >= 0
  // Per sub-camera errors of EVERY sub-camera (the reference too; issue 28): an offset (dx, dy),
  // a scale (dx ~ u), a rotation of the line in the focal plane (dy ~ u) and a curvature
  // (dy ~ u^2), each drawn with this sigma at the sub-camera's ends, px; 0: none (then the
  // reference's cubic errors satisfy the earlier Legendre datum, as before), >= 0.
  double subcamera_error_px = 0.0;
  // The sub-cameras stitched by their design onto ONE straight virtual CCD: the nominal camera has
  // no `subcameras` section, the sub-cameras are the calibration's polynomial ranges (zero in the
  // nominal camera); the truth's polynomials carry the errors.
  bool linear_layout = false;
  // POS error beyond the spline's random nodes: a constant (bias) and a linear drift over the
  // flight (its value at the end), each component drawn with these sigmas (m, deg), >= 0.
  double pos_bias_m = 0.0, pos_bias_deg = 0.0, pos_drift_m = 0.0, pos_drift_deg = 0.0;
  // Shutter / POS latency: line l is exposed time_offset_s after its pos.csv time stamp (the
  // calibration's --time-offset estimates it), s, |.| <= 1.
  double time_offset_s = 0.0;
  double attitude_variation_deg = 0.5;  // amplitude of the smooth attitude variation
  double position_variation_m = 3.0;    // amplitude of the smooth position variation
  std::uint64_t seed = 1;
  void Validate() const;  // ConfigError naming the option
};

struct LineSimulation {
  calib::LineCamera truth, nominal;       // truth: polynomial calibration; nominal: none
  std::vector<PosRecord> pos_truth, pos;  // per line
  std::vector<LineObservation> observations;
  std::vector<GroundPoint> points, points_truth;
  /// True per-line corrections the calibration should find (= minus the POS error): per line
  /// [dX dY dZ m, domega dphi dkappa rad].
  std::vector<Eigen::Matrix<double, 6, 1>> true_corrections;
  int reference_subcamera = 1;
};

LineSimulation SimulateLineFlight(const LineSimulationOptions& options);

/// The terrain height (m) of the simulation at (X, Y): a smooth wave of `relief_m` peak to peak.
double SimulatedTerrainHeight(const LineSimulationOptions& options, double x_m, double y_m);

/// Writes camera_nominal.yaml, camera_truth.yaml, pos.csv, pos_truth.csv, observations.csv,
/// points.csv, points_truth.csv, truth_detectors.csv (i,subcamera,dx_mm,dy_mm) and
/// truth_trajectory.csv (line,dX,dY,dZ,domega,dphi,dkappa in m, deg) into `folder`.
void WriteLineSimulation(const LineSimulation& simulation, const std::string& folder);

}  // namespace aerocal::triangulation
