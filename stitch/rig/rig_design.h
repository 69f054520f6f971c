// Design figures of a multi-head rig (issue 16, "Design figures"; CONVENTIONS.md "Multi-head
// rigs"): for the rig level at nadir (rig attitude 0, virtual centre at height H above the plane
// Z = 0), the ground sampling distance of each head against the nadir GSD, the virtual image's
// coverage, its overlap zones (the sets of heads that see a virtual pixel), the largest fully
// covered rectangle (the "effective format") and the standard tie positions of the stitching.
//
// GSD change ratio of a tilted head: the ground footprint of one head pixel (its two sides, along
// and across the tilt) divided by the nadir GSD p H / c of that head (H of the head centre above
// the plane). Measured by intersecting the rays through the pixel +- 0.5 px with the plane (with
// the head's distortion). For a distortion-free head with tilt t and a point on the principal line
// of the tilt at off-axis angle a (positive away from nadir) the closed form is
//   along the tilt  cos^2 a / cos^2 (t + a),   across  cos a / cos (t + a)
// (ClosedFormGsdRatio); the design reports it beside the measured figure where it applies.
//
// Zones: the virtual image is sampled on a grid of cells (`cell_px` virtual pixels); each cell
// centre is carried into every head (RigConverter::HeadFromVirtual) and marked with the heads
// whose format holds it. A zone is a set of two or more heads ("AB", "ABC": head ids in rig
// order). Standard tie positions (the layout the self-calibrating stitching relies on): two per
// two-fold zone, at 20 % and 80 % along the zone's principal axis (the zone cell nearest to
// each), and one per triple zone (its cell nearest the centroid) -- 12 for the four-head uav4 rig
// (five two-fold zones AB, AC, AD, BC, CD and the two triple zones ABC, ACD).
//
// Units: virtual pixels (CONVENTIONS.md pixel frame of the virtual image), metres on the ground
// (object frame of the nadir exposure: X along the rig x, Y along the rig y).
#pragma once

#include "calib/camera/rig.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::stitch {

/// The closed form of the GSD change ratio (see above): along = cos^2 a / cos^2 (t + a),
/// across = cos a / cos (t + a); tilt and off-axis angle in rad.
Eigen::Vector2d ClosedFormGsdRatio(double tilt_rad, double off_axis_rad);

/// One sample point of a head: its pixel, the measured GSD ratios (along, across the tilt) and,
/// when the point lies on the principal line of the tilt, the closed form.
struct GsdSample {
  std::string where;  // "principal_point", "edge_top", ..., "corner_top_left", ...
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
  double off_axis_deg = 0.0;  // angle from the head axis in the tilt plane (+ away from nadir)
  Eigen::Vector2d ratio = Eigen::Vector2d::Zero();  // measured: along, across the tilt
  bool on_tilt_line = false;                        // closed form applies
  Eigen::Vector2d closed_form = Eigen::Vector2d::Zero();
};

struct HeadDesign {
  std::string id;
  double tilt_deg = 0.0;                     // angle between the head axis and the nadir
  double nadir_gsd_m = 0.0;                  // p H / c of this head
  std::vector<GsdSample> samples;            // principal point, 4 edge midpoints, 4 corners
  std::vector<Eigen::Vector2d> footprint_m;  // ground outline (X, Y), closed polygon
  std::vector<Eigen::Vector2d> outline_px;   // the same outline in virtual pixels
};

struct StandardPosition {
  std::string name;  // "AB-1", "AB-2", "ABC"
  std::string zone;  // "AB", "ABC"
  Eigen::Vector2d virtual_px = Eigen::Vector2d::Zero();
};

/// Coverage of the virtual image on a grid of cells.
struct RigCoverage {
  double cell_px = 0.0;                                 // cell side in virtual pixels
  Eigen::Vector2d origin_px = Eigen::Vector2d::Zero();  // centre of cell (0, 0)
  int cols = 0, rows = 0;
  std::vector<unsigned> mask;  // per cell (row-major): bit k = head k sees it
  /// Virtual pixel of a cell centre.
  Eigen::Vector2d CellCenter(int col, int row) const {
    return origin_px + cell_px * Eigen::Vector2d(col, row);
  }
};

/// The coverage of the rig's virtual image at height H over the bounding box of the heads'
/// outlines (not only the file's format), with cells of `cell_px` virtual pixels.
RigCoverage ComputeRigCoverage(const calib::Rig& rig, double height_m, double cell_px);

/// Zone name of a head mask ("AB"; head ids in rig order; "" for fewer than two heads).
std::string ZoneName(const calib::Rig& rig, unsigned mask);

/// Standard tie positions from the coverage (see above).
std::vector<StandardPosition> StandardTiePositions(const calib::Rig& rig,
                                                   const RigCoverage& coverage);

/// An axis-aligned rectangle of virtual pixels [min, max].
struct PixelRectangle {
  Eigen::Vector2d min_px = Eigen::Vector2d::Zero(), max_px = Eigen::Vector2d::Zero();
  double Width() const { return max_px.x() - min_px.x(); }
  double Height() const { return max_px.y() - min_px.y(); }
};

struct RigDesign {
  double height_m = 0.0;
  std::vector<HeadDesign> heads;
  RigCoverage coverage;
  PixelRectangle covered_box_px;  // bounding box of the heads' outlines (the format needed)
  PixelRectangle effective_px;    // largest fully covered rectangle (cell resolution)
  double covered_area_m2 = 0.0;   // union of the footprints on the ground
  double effective_area_m2 = 0.0;
  std::vector<std::pair<std::string, double>> zone_area_m2;  // per zone ("AB", ...)
  std::vector<StandardPosition> standard_positions;
  double virtual_gsd_m = 0.0;  // p_v H / c_v
};

/// The design figures of a rig at relative flying height `height_m` (> 0); the coverage grid has
/// about `grid_cells` cells along its longer side (>= 10).
RigDesign DesignRig(const calib::Rig& rig, double height_m, int grid_cells = 400);

/// The footprints as an SVG plot (ground metres; heads, virtual format, effective format, standard
/// positions).
std::string RigDesignSvg(const calib::Rig& rig, const RigDesign& design);

}  // namespace aerocal::stitch
