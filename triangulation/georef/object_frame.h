// The object frame of a block and its conversion from and to geodetic coordinates (the only
// place in aerocal that uses GeographicLib; CONVENTIONS.md "Object frame and georeferencing").
//
// The project's `frame:` (FORMATS.md "Block") decides:
// - {projected: "..."}: coordinates are used as given (a projected or local metric frame; the
//   text is stated in the output);
// - {local: {lat, lon, h}}: points.csv and exposures.csv hold GEODETIC coordinates (WGS84,
//   X = longitude [deg], Y = latitude [deg], Z = ellipsoidal height [m], X/Y ordered like
//   east/north); the adjustment runs in the local tangent plane (east, north, up) about the origin
//   (GeographicLib::LocalCartesian, exact, Earth curvature included);
// - {utm: "33N"}: geodetic input as above; the adjustment runs in that UTM zone (easting,
//   northing, ellipsoidal height). A map projection is not a Cartesian frame: heights are not
//   projected and scale varies with easting, so the output states the frame.
// Angles (omega, phi, kappa) are taken as given, relative to the axes of the adjustment frame.
// Check and control differences are reported in metres of the adjustment frame; adjusted
// coordinates are written back in the input frame (geodetic for geodetic input).
#pragma once

#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <memory>
#include <string>

namespace aerocal::triangulation {

class ObjectFrame {
 public:
  /// Throws InputError for an unknown UTM zone or an origin outside [-90, 90] / [-180, 360].
  explicit ObjectFrame(const FrameSpec& spec);
  ~ObjectFrame();
  ObjectFrame(ObjectFrame&&) noexcept;
  ObjectFrame& operator=(ObjectFrame&&) noexcept;

  /// True when the block's files hold geodetic coordinates.
  bool geodetic_input() const;
  /// Geodetic (lon deg, lat deg, h m) -> adjustment frame (m); identity for projected input.
  Eigen::Vector3d ToAdjustment(const Eigen::Vector3d& input) const;
  /// Adjustment frame (m) -> input frame.
  Eigen::Vector3d ToInput(const Eigen::Vector3d& adjustment_m) const;
  /// Human statement of the adjustment frame and of the input frame.
  std::string Description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  friend Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame);
};

/// The project with points and exposure centres (and their sigmas, unchanged in metres) in the
/// adjustment frame. Geodetic sigmas are read as metres (sX east, sY north, sZ up). Exposure
/// velocities of geodetic input are east, north, up (m/s) at the exposure; they are turned into
/// the adjustment frame's axes (meridian convergence and point scale for UTM, the tangent-plane
/// rotation for local).
Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame);

/// Adjusted coordinates (points, exposure centres, point tables) back into the input frame;
/// differences and statistics stay in metres of the adjustment frame. Sets result->frame.
void ToInputFrame(const ObjectFrame& frame, AdjustmentResult* result);

}  // namespace aerocal::triangulation
