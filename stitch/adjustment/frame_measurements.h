// Stitching measurements of one frame (exposure), resolved against the camera file:
// - a row whose point id equals a camera reference-point id is that reference point measured in
//   this frame (sub-image u, v); its virtual (U, V) comes from the camera file;
// - a reference point with no row in the frame uses the camera file's (u, v) as its measurement
//   (with the camera file's sigma_px);
// - any other point seen in two or more sub-images of the frame is a tie point (one ray per
//   sub-image); a point seen in one sub-image only carries no information and is counted, not used.
// Pixel frames per CONVENTIONS.md (sub-image (u, v), virtual (U, V), px).
#pragma once

#include "calib/camera/camera.h"
#include "stitch/simulation/stitch_simulator.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::stitch {

struct ReferenceMeasurement {
  std::string point;
  int subimage = -1;                 // index into Camera::subimages
  Eigen::Vector2d uv{0, 0};          // measured sub-image pixel
  Eigen::Vector2d virtual_px{0, 0};  // surveyed (U, V) from the camera file
  double sigma_px = 0.05;            // a-priori sigma of the measurement, px
  bool measured = false;             // false: camera file's (u, v) used
};

struct TieRay {
  int subimage = -1;
  Eigen::Vector2d uv{0, 0};
  double sigma_px = 0.1;
};

struct TieMeasurement {
  std::string point;
  std::vector<TieRay> rays;  // >= 2, distinct sub-images
};

struct FrameMeasurements {
  std::string frame;
  std::vector<ReferenceMeasurement> references;
  std::vector<TieMeasurement> ties;
  int single_ray_points = 0;  // points seen in one sub-image only (not used)
};

/// Groups rows by frame (in order of first appearance) and resolves them against `camera`.
/// Throws InputError("FILE: frame F, point P: ...") for an unknown sub-image or a point measured
/// twice in one sub-image of a frame. `file` names the measurement file in messages.
std::vector<FrameMeasurements> GroupByFrame(const calib::Camera& camera,
                                            const std::vector<StitchObservation>& rows,
                                            const std::string& file);

}  // namespace aerocal::stitch
