// Deterministic (seeded) simulation of a photogrammetric flight with a multi-CCD camera: the
// embedded example data of aerocal and the truth behind its synthetic tests.
//
// Defaults follow the project's reference case: a 2x3-CCD camera (virtual format 14000 x 12000 px
// of 9 um, c = 170 mm, ~200 px overlaps, small affine misplacements of the non-base CCDs),
// 37 exposures in 3 east-west strips at 4500 m above ground with 60 % forward and 30 % side
// overlap, terrain with 300 m relief, 329 surveyed ground points (5 control points at the block
// corners and centre, the rest check points) plus tie points. The nominal camera differs from the
// true one by corrections of the size reported for such cameras (c 0.038 mm, x0/y0 -2.4/+1.5 um,
// radial distortion of a few pixels at the format corner).
#pragma once

#include "calib/camera/camera.h"
#include "stitch/layout/grid_layout.h"
#include "stitch/simulation/stitch_simulator.h"
#include "triangulation/block/block.h"

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// Bounds of option products checked by SimulateFlight (ConfigError naming the options):
/// exposures x stitching ties per exposure, and exposures x (ground points + tie points).
inline constexpr double kMaxSimulatedStitchTies = 2e6;
inline constexpr double kMaxSimulatedPointExposurePairs = 1e9;

struct FlightSimulationOptions {
  std::uint64_t seed = 1;
  int exposures = 37;  // total, spread evenly over the strips
  int strips = 3;
  double flying_height_m = 4500.0;  // above the mean terrain
  double forward_overlap = 0.60;
  double side_overlap = 0.30;
  double terrain_relief_m = 300.0;       // peak-to-peak
  double terrain_base_m = 200.0;         // lowest terrain height
  int ground_points = 329;               // surveyed: control + check
  int control_points = 5;                // at the block corners and centre (4 corners + centre)
  int tie_points = 600;                  // unsurveyed points measured in >= 2 images
  double image_noise_px = 0.2;           // Gaussian noise of image measurements
  double image_sigma_px = 0.2;           // a-priori sigma written to observations.csv
  double survey_sigma_m = 0.02;          // noise and sigma of control/check coordinates
  double attitude_sigma_deg = 0.5;       // spread of the true omega/phi
  double start_position_error_m = 20.0;  // approximate EO in exposures.csv (no GNSS)
  double start_angle_error_deg = 1.0;
  double gnss_sigma_m = 0.0;   // > 0: exposures.csv carries GNSS centres with this sigma
  double imu_sigma_deg = 0.0;  // > 0: exposures.csv carries IMU angles with this sigma
  /// The GNSS/IMU platform (triangulation/README.md "GNSS/IMU priors on the platform"): the GNSS
  /// records the antenna at X0 + R a + v dt, the IMU the attitude R M^T. Zero by default.
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();    // a, camera frame (m)
  Eigen::Vector3d boresight_rad = Eigen::Vector3d::Zero();  // M = imu_from_image, omega-phi-kappa
  double gnss_time_offset_s = 0.0;                          // dt (s), needs speed_mps > 0
  double speed_mps = 0.0;  // > 0: exposures.csv carries the velocity vX, vY, vZ along the strips
  stitch::GridLayoutOptions layout = DefaultLayout();
  stitch::MisplacementOptions misplacement = DefaultMisplacement();
  stitch::FrameSimulationOptions stitching;  // per-exposure stitching measurements
  calib::InteriorParams interior_correction = DefaultInteriorCorrection();  // truth - nominal

  static stitch::GridLayoutOptions DefaultLayout();
  static stitch::MisplacementOptions DefaultMisplacement();
  static calib::InteriorParams DefaultInteriorCorrection();
};

struct SimulatedFlight {
  FlightSimulationOptions options;
  calib::Camera nominal, truth;
  std::vector<Exposure> exposures_truth,
      exposures_file;                                   // exposures_file: what exposures.csv holds
  std::vector<GroundPoint> points_truth, points_file;   // points_file: what points.csv holds
  std::vector<ImageObservation> observations;           // virtual-image pixels
  std::vector<ImageObservation> subimage_observations;  // raw sub-image pixels
  std::vector<stitch::StitchObservation> stitching;     // per-exposure stitching measurements
};

/// Terrain height (m) of the simulated block at (X, Y).
double SimulatedTerrainHeight(const FlightSimulationOptions& options, double x_m, double y_m);

SimulatedFlight SimulateFlight(const FlightSimulationOptions& options);

/// Writes the FORMATS.md files into `folder`: camera_nominal.yaml, camera_truth.yaml,
/// exposures.csv, observations.csv, observations_subimage.csv, points.csv, stitch_obs.csv,
/// project.yaml (virtual observations), project_subimage.yaml (raw sub-image observations), and
/// truth/exposures.csv, truth/points.csv. Every file is written atomically.
void WriteSimulatedFlight(const SimulatedFlight& flight, const std::string& folder);

namespace internal {

/// The seeded random streams of one simulation (shared by the frame and rig simulators so both
/// plan the same flight from the same seed).
struct SimulationRandom {
  explicit SimulationRandom(std::uint64_t seed) : rng(seed) {}
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};
};

/// The true exposures: east-west strips with alternate flight directions (kappa 0 / 180 deg),
/// bases and strip spacing from the overlaps and the ground footprint (m, x along the strip).
std::vector<Exposure> PlanStrips(const FlightSimulationOptions& options,
                                 const Eigen::Vector2d& footprint_m,
                                 const std::string& camera,
                                 SimulationRandom& random);

/// What exposures.csv holds: GNSS/IMU-measured (with their sigmas) or approximate EO.
std::vector<Exposure> ExposuresAsMeasured(const FlightSimulationOptions& options,
                                          const std::vector<Exposure>& truth,
                                          SimulationRandom& random);

/// Ground points over the block: control walked from the corners and centre inward until
/// `seen_by` (the number of exposures measuring a point) is >= 3, check and tie points where it
/// is >= 2; the file copies carry survey noise (control/check) or no coordinates (tie).
void PlacePoints(const FlightSimulationOptions& options,
                 const std::vector<Exposure>& exposures,
                 const Eigen::Vector2d& footprint_m,
                 const std::function<int(const Eigen::Vector3d&)>& seen_by,
                 SimulationRandom& random,
                 std::vector<GroundPoint>* points_truth,
                 std::vector<GroundPoint>* points_file);

}  // namespace internal

}  // namespace aerocal::triangulation
