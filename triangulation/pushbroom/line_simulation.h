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
// - the reference (middle) sub-camera's true errors have no constant and no linear term (the
//   calibration's datum: those are trajectory corrections).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "calib/camera/line_camera.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/pos_trajectory.h"

namespace aerocal::triangulation {

struct LineSimulationOptions {
  int detectors_per_camera = 300;   // per sub-camera, 10 .. 100000
  double tilt_deg = 20.0;           // across-track look angle of the outer cameras, 0 .. 40
  double pitch_mm = 0.01;           // detector pitch, > 0
  double overlap = 0.05;            // fraction of a sub-camera's field shared with its neighbour
  int lines = 2000;                 // scan lines, >= 20
  double height_m = 1000.0;         // flying height above the mean terrain, > 0
  double speed_m_s = 60.0;          // ground speed, > 0
  double relief_m = 100.0;          // terrain relief peak to peak, >= 0
  int control_points = 1500;        // cloud control points placed in the swath
  double image_noise_px = 0.25;     // measurement noise (col and row), >= 0
  double image_sigma_px = 0.25;     // a-priori sigma written, > 0
  double control_noise_m = 0.1;     // coordinate noise of the control points, >= 0
  double control_sigma_m = 0.1;     // their a-priori sigma written, > 0
  double pos_error_m = 0.05;        // sigma of the POS error spline nodes (position), >= 0
  double pos_error_deg = 0.005;     // sigma of the POS error spline nodes (attitude), >= 0
  int node_spacing_lines = 100;     // of the POS error spline, >= 1
  double detector_error_px = 0.5;   // size of the smooth per-detector errors, >= 0
  double attitude_variation_deg = 0.5;  // amplitude of the smooth attitude variation
  double position_variation_m = 3.0;    // amplitude of the smooth position variation
  std::uint64_t seed = 1;
  void Validate() const;  // ConfigError naming the option
};

struct LineSimulation {
  calib::LineCamera truth, nominal;   // truth: polynomial calibration; nominal: none
  std::vector<PosRecord> pos_truth, pos;   // per line
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
