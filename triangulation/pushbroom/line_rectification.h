// Geometry of a line (pushbroom) image on the ground (issue 17, module README "Image mode"):
// - the image position (detector, line) of an object point: Newton on the focal-plane misclosure
//   of ProjectAtLine (line_calibration.h) in the detector index and the fractional line;
// - the ray of a detector position on a line and its intersection with a height function;
// - the "L1" image: the line image rectified onto a horizontal plane Z = mean terrain height with
//   the POS and the nominal camera. Its grid: cell (col, row) is the ground point
//   (x0 + col gsd, y0 + row gsd, z) (rows run with +Y, i.e. with the flight of the simulation, so
//   the L1 image looks like the line image and is not a north-up map). The inverse map (cell ->
//   detector, line) is solved exactly at every `map_step_px`-th cell and bilinear in between; the
//   grey values are bilinear in the line image (pixel centre (col = detector, row = line)).
#pragma once

#include "calib/camera/line_camera.h"
#include "stitch/image_io/gray_image.h"
#include "triangulation/pushbroom/pos_trajectory.h"

#include <Eigen/Core>

#include <cmath>
#include <functional>
#include <optional>

namespace aerocal::triangulation {

/// Detector position and line of `point` in sub-camera `subcamera`, starting the search at
/// `line_guess`; false when the Newton iteration leaves the trajectory or does not converge. The
/// detector may lie up to half a detector beyond the sub-camera's range (callers check). `strict`:
/// the steps must fall below 1e-12 within 50 iterations; otherwise below 1e-8 is accepted.
bool SubcameraPixelOfPoint(const calib::LineCamera& camera,
                           const PosTrajectory& pos,
                           int subcamera,
                           double line_guess,
                           const Eigen::Vector3d& point,
                           double* detector,
                           double* line,
                           bool strict = true);

/// The same (not strict) over the sub-cameras in detector order: the first whose detector lies
/// within its range (+- 0.5) wins (overlapping fields: the lower detector index).
bool LinePixelOfPoint(const calib::LineCamera& camera,
                      const PosTrajectory& pos,
                      double line_guess,
                      const Eigen::Vector3d& point,
                      double* detector,
                      double* line);

/// Object point where the ray of detector position `detector` on `line` meets the surface
/// Z = height(X, Y) (fixed-point iteration in Z, to 1e-6 m); nullopt when it does not converge or
/// the ray does not point down.
std::optional<Eigen::Vector3d> GroundOfDetector(
    const calib::LineCamera& camera,
    const PosTrajectory& pos,
    double detector,
    double line,
    const std::function<double(double, double)>& height);

/// Where the ray origin + s direction (s > 0) meets Z = height(X, Y): fixed-point iteration in Z
/// to 1e-6 m; nullopt when the ray does not point down or the iteration does not converge.
std::optional<Eigen::Vector3d> IntersectSurface(
    const Eigen::Vector3d& origin,
    const Eigen::Vector3d& direction,
    const std::function<double(double, double)>& height);

struct L1Grid {
  double x0_m = 0, y0_m = 0;  // ground point of cell (0, 0)
  double gsd_m = 1;           // cell size, > 0
  double z_m = 0;             // height of the rectification plane
  int width = 0, height = 0;  // cells
  Eigen::Vector3d Ground(double col, double row) const {
    return {x0_m + col * gsd_m, y0_m + row * gsd_m, z_m};
  }
};

/// The grid covering the footprint of lines first .. last of the POS on Z = z_m, cell `gsd_m`
/// (<= 0: the mean distance between the POS positions of consecutive lines).
L1Grid MakeL1Grid(const calib::LineCamera& camera,
                  const PosTrajectory& pos,
                  double z_m,
                  double gsd_m);

struct L1Image {
  L1Grid grid;
  stitch::GrayImage image;                 // grey values; 0 where invalid
  Eigen::MatrixXf detector_map, line_map;  // line-image position per cell; NaN where invalid
  bool Valid(int col, int row) const { return !std::isnan(detector_map(row, col)); }
};

/// The inverse map of the grid (cell -> line-image position), exact at every `map_step_px`-th
/// cell (>= 1) and bilinear in between; NaN where no sub-camera sees the cell.
void ComputeL1Maps(const calib::LineCamera& camera,
                   const PosTrajectory& pos,
                   const L1Grid& grid,
                   int map_step_px,
                   Eigen::MatrixXf* detector_map,
                   Eigen::MatrixXf* line_map);

/// Bilinear resampling of `line_image` (rows = lines, cols = detectors) through the maps.
stitch::GrayImage ResampleThroughMaps(const stitch::GrayImage& line_image,
                                      const Eigen::MatrixXf& detector_map,
                                      const Eigen::MatrixXf& line_map);

/// The L1 image: MakeL1Grid + ComputeL1Maps + ResampleThroughMaps.
L1Image RectifyLineImage(const calib::LineCamera& camera,
                         const PosTrajectory& pos,
                         const stitch::GrayImage& line_image,
                         double z_m,
                         double gsd_m,
                         int map_step_px);

/// Bilinear grey value at (col, row); NaN outside the image.
float SampleBilinear(const stitch::GrayImage& image, double col, double row);

}  // namespace aerocal::triangulation
