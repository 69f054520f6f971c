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
// - {crs: ..., [vertical, geoid_grid, points_crs, exposures_crs, origin]}: points.csv and
//   exposures.csv hold coordinates in CRSs PROJ reads (georef/crs.h), in PROJ's normalised axis
//   order; they are converted through the geographic 3D CRS of `crs`'s datum into the local
//   tangent plane (east, north, up; GeographicLib LocalCartesian on that datum's ellipsoid) about
//   `origin` or, without one, the block centre (mean of the surveyed points, else of the exposure
//   centres, taken in geographic 3D coordinates when the first project is converted). Sigmas
//   (sX, sY, sZ along the file's metric axes: grid east/north/up for a projected CRS, east/north/
//   up at the point for a geographic one, X/Y/Z for a geocentric one) are propagated with the
//   conversion's Jacobian J (the diagonal of J diag(s^2) J^T: exact for equal horizontal sigmas,
//   the correlation of unequal ones is dropped). Attitudes are relative to those same axes at the
//   exposure and are turned by the rotation nearest J; velocities are multiplied by J.
// Angles of the legacy kinds are taken as given, relative to the axes of the adjustment frame.
// Check and control differences are reported in metres of the adjustment frame; adjusted
// coordinates are written back in the input frame (geodetic for geodetic input, each file's CRS
// for crs:).
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

  /// Which file's CRS a coordinate is in (they differ with points_crs / exposures_crs).
  enum class File { kPoints, kExposures };

  /// True when the block's files hold geodetic coordinates.
  bool geodetic_input() const;
  /// True for a `crs:` frame (converted through PROJ).
  bool crs_input() const;
  /// crs: without `origin`: fixes the tangent plane's origin at the block centre (the first call
  /// wins; ToAdjustmentFrame calls it). InputError when the block has no usable coordinate.
  void FixOrigin(const Project& project) const;
  /// The origin (lon deg, lat deg, ellipsoidal h m) of a tangent-plane frame.
  Eigen::Vector3d Origin() const;
  /// Geoid undulation N (m) at the origin for orthometric points (crs:), else 0.
  double GeoidUndulationAtOrigin() const;
  /// Geodetic (lon deg, lat deg, h m) or the file's CRS -> adjustment frame (m); identity for
  /// projected input.
  Eigen::Vector3d ToAdjustment(const Eigen::Vector3d& input, File file = File::kPoints) const;
  /// Adjustment frame (m) -> input frame.
  Eigen::Vector3d ToInput(const Eigen::Vector3d& adjustment_m, File file = File::kPoints) const;
  /// crs: the derivative of the adjustment coordinates by metric displacements along the file's
  /// axes at `input` (see above); identity for the other kinds.
  Eigen::Matrix3d MetricJacobian(const Eigen::Vector3d& input, File file) const;
  /// Human statement of the adjustment frame and of the input frame.
  std::string Description() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  friend Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame);
  friend void ToInputFrame(const ObjectFrame& frame, AdjustmentResult* result);
  friend Project FromAdjustmentFrame(const Project& project, const ObjectFrame& frame);
};

/// The project with points and exposure centres (and their sigmas, unchanged in metres) in the
/// adjustment frame. Geodetic sigmas are read as metres (sX east, sY north, sZ up). Exposure
/// velocities of geodetic input are east, north, up (m/s) at the exposure; they are turned into
/// the adjustment frame's axes (meridian convergence and point scale for UTM, the tangent-plane
/// rotation for local).
Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame);

/// The inverse of ToAdjustmentFrame for a crs: frame whose origin is fixed: a project in the
/// adjustment frame (points, centres, attitudes, sigmas, velocities) written in the files' CRSs,
/// with `frame:` the frame's spec (importers; the tests' conversions between CRSs).
Project FromAdjustmentFrame(const Project& project, const ObjectFrame& frame);

/// Adjusted coordinates (points, exposure centres, point tables) back into the input frame;
/// differences and statistics stay in metres of the adjustment frame. Sets result->frame.
void ToInputFrame(const ObjectFrame& frame, AdjustmentResult* result);

}  // namespace aerocal::triangulation
