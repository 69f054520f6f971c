// A simulated camera-calibration test field (issue 14): targets of surveyed XYZ on several depth
// layers (a facade with balcony fronts and pillars in front of the wall), or one plane, and a
// convergent image network from several positions, heights and roll angles in image groups.
// Truth and files as FORMATS.md: `calibrate --observations --points [--groups]` takes them.
//
// Object frame: X along the facade (m), Y away from the cameras (the wall at Y = 0, the layers in
// front of it at negative Y), Z up. Each station looks at the facade centre (plus a seeded
// jitter) from Y = -distance; roll steps 0, 90, 180, 270 deg through the stations of a group, so
// every group alone determines the interior orientation (Fraser 1997: roll diversity and depth).
// Groups repeat the same network with their own jitter; `group_camera_change` perturbs one group's
// true camera (the negative case of the stability test).
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/block/block.h"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct TestFieldOptions {
  std::uint64_t seed = 1;
  bool planar = false;             // one plane (Y = 0) instead of the depth layers
  double width_m = 20.0;           // facade extent along X, > 0
  double height_m = 12.0;          // facade extent along Z, > 0
  double target_spacing_m = 1.0;   // grid spacing of the wall targets, > 0
  int groups = 3;                  // image groups, 1..26
  int images_per_group = 24;       // stations per group, 4..1000
  double distance_m = 16.0;        // camera distance from the wall, > 0
  double survey_sigma_m = 0.0005;  // target survey noise and the sigma written, > 0
  double image_noise_px = 0.1;     // image measurement noise, >= 0
  double image_sigma_px = 0.1;     // a-priori image sigma written, > 0
  int check_every = 8;             // every n-th target is a check point (0: none)
  /// Added to the true interior of group index `changed_group` (0-based; -1: none), table order.
  int changed_group = -1;
  calib::InteriorParams group_camera_change{};
  void Validate() const;  // throws ConfigError naming the field
};

struct SimulatedTestField {
  TestFieldOptions options;
  calib::Camera truth, nominal;  // nominal: c rounded to the lens's 24 mm, no distortion
  std::vector<Exposure> exposures_truth;
  std::vector<GroundPoint> points_truth, points_file;
  std::vector<ImageObservation> observations;
  std::map<std::string, std::string> group_of_image;
};

SimulatedTestField SimulateTestField(const TestFieldOptions& options);

/// The field's files as a project for `Calibrate`: the nominal camera (id cam1), the points with
/// their survey noise, the observations; no exposures (calibrate starts from resections).
Project TestFieldProject(const SimulatedTestField& field);

/// Writes camera_nominal.yaml, camera_truth.yaml, observations.csv, points.csv, groups.csv and
/// truth/exposures.csv, truth/points.csv into `folder` (atomically each).
void WriteSimulatedTestField(const SimulatedTestField& field, const std::string& folder);

}  // namespace aerocal::triangulation
