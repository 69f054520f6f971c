// Edge targets on the ground (issue 36 item 1): where a target's edge lies in an image, from the
// adjusted orientation of the exposure and the target's ground coordinates, so that the slanted
// edge is measured in a region found rather than given.
//
// A target's edge is the segment between two ground points (object frame, m). Both ends are
// projected into the (virtual) image with the camera and the exposure's orientation
// (calib::Camera::ProjectToPixel: collinearity and the camera's distortion). The region spans the
// central `used_fraction` of the projected edge (at most `max_length_px`) along it and
// `half_width_px` to both sides across it, as a pixel-axis rectangle; the local GSD is the edge's
// ground length over its image length.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/quality/slanted_edge.h"

#include <Eigen/Core>

#include <string>

namespace aerocal::stitch {

struct EdgeTarget {
  std::string id;
  Eigen::Vector3d start_m = Eigen::Vector3d::Zero();  // one end of the edge, object frame (m)
  Eigen::Vector3d end_m = Eigen::Vector3d::Zero();    // the other end
};

struct EdgeTargetRegionOptions {
  double half_width_px = 32.0;  // across the edge, each side (>= 8)
  double used_fraction = 0.8;   // of the edge's length, centred (0 < f <= 1; the ends are corners)
  double max_length_px = 0.0;  // and at most this long along the edge (px, 0: no limit, else >= 16)
};

struct EdgeTargetRegion {
  std::string id;
  bool usable = false;  // both ends project in front of the camera and the region is inside
  std::string reason;   // why not, when !usable
  PixelRegion region;
  Eigen::Vector2d start_px = Eigen::Vector2d::Zero(), end_px = Eigen::Vector2d::Zero();
  MtfAxis axis = MtfAxis::kX;  // the image axis nearer the edge normal
  double slant_deg = 0.0;      // the edge's angle to the nearer pixel axis (unsigned)
  double gsd_m = 0.0;          // ground length per image pixel along the edge
};

/// The region of an edge whose ends lie at `start_px`, `end_px` in an image of `width_px` x
/// `height_px` (the ends may lie outside it: only the region must be inside), `ground_length_m` its
/// length on the ground (for gsd_m). The edge is straight between the ends in that image: true of
/// a projected target's edge to the distortion's curvature over the edge (far below 0.01 px over a
/// region), and kept by a sub-image mapping, a projectivity (`quality mtf --sub-image`).
EdgeTargetRegion RegionOfImageEdge(const std::string& id,
                                   const Eigen::Vector2d& start_px,
                                   const Eigen::Vector2d& end_px,
                                   double ground_length_m,
                                   int width_px,
                                   int height_px,
                                   const EdgeTargetRegionOptions& options = {});

/// The region of `target` in the image of `camera` seen from (opk_rad, center_m).
EdgeTargetRegion RegionOfEdgeTarget(const calib::Camera& camera,
                                    const Eigen::Vector3d& opk_rad,
                                    const Eigen::Vector3d& center_m,
                                    const EdgeTarget& target,
                                    const EdgeTargetRegionOptions& options = {});

}  // namespace aerocal::stitch
