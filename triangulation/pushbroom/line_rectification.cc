#include "triangulation/pushbroom/line_rectification.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "triangulation/pushbroom/line_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace aerocal::triangulation {

bool SubcameraPixelOfPoint(const calib::LineCamera& cam,
                           const PosTrajectory& pos,
                           int s,
                           double line_guess,
                           const Eigen::Vector3d& point,
                           double* detector,
                           double* line,
                           bool strict) {
  const auto ranges = cam.Ranges();
  const int first = ranges[s].first, last = ranges[s].second;
  double t = std::max(pos.first_line(), std::min(pos.last_line(), line_guess));
  Eigen::Vector2d xy;
  if (!ProjectAtLine(cam, pos, t, point, &xy)) return false;
  // Start: the design detector nearest in x (design x is monotonic across a sub-camera: bisection).
  const bool increasing = cam.DesignPosition(last).x() >= cam.DesignPosition(first).x();
  int lo = first, hi = last;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    ((cam.DesignPosition(mid).x() < xy.x()) == increasing ? lo : hi) = mid;
  }
  double i =
      std::abs(cam.DesignPosition(lo).x() - xy.x()) <= std::abs(cam.DesignPosition(hi).x() - xy.x())
          ? lo
          : hi;
  auto detector_at = [&](double di) {
    // The position within the sub-camera (its polynomial, its design), also just beyond its ends.
    const double clamped = std::max<double>(first, std::min<double>(last, di));
    const Eigen::Vector2d at_clamped = cam.DetectorPosition(clamped);
    if (clamped == di) return at_clamped;
    const double h = di > clamped ? -1e-3 : 1e-3;
    const Eigen::Vector2d slope = (cam.DetectorPosition(clamped + h) - at_clamped) / h;
    return Eigen::Vector2d(at_clamped + slope * (di - clamped));
  };
  for (int iteration = 0; iteration < 50; ++iteration) {
    if (!pos.CoversLine(t) || !pos.CoversLine(t + 1e-3) || !pos.CoversLine(t - 1e-3)) return false;
    Eigen::Vector2d p0, pt;
    if (!ProjectAtLine(cam, pos, t, point, &p0)) return false;
    const Eigen::Vector2d f = p0 - detector_at(i);
    if (!ProjectAtLine(cam, pos, t + 1e-3, point, &pt)) return false;
    Eigen::Matrix2d j;
    j.col(0) = -(detector_at(i + 1e-3) - detector_at(i - 1e-3)) / 2e-3;
    j.col(1) = (pt - p0) / 1e-3;
    const Eigen::Vector2d step = j.fullPivLu().solve(-f);
    if (!step.allFinite()) return false;
    i += step.x();
    t += step.y();
    if (step.norm() < 1e-12) break;
    // Finite-difference noise can keep the last steps above 1e-12 (points of the L1 plane).
    if (iteration == 49 && (strict || !(step.norm() < 1e-8))) return false;
  }
  *detector = i;
  *line = t;
  return true;
}

bool LinePixelOfPoint(const calib::LineCamera& cam,
                      const PosTrajectory& pos,
                      double line_guess,
                      const Eigen::Vector3d& point,
                      double* detector,
                      double* line) {
  const auto ranges = cam.Ranges();
  for (size_t s = 0; s < ranges.size(); ++s) {
    double i = 0, t = 0;
    if (!SubcameraPixelOfPoint(cam, pos, int(s), line_guess, point, &i, &t, false)) continue;
    if (i >= ranges[s].first - 0.5 && i <= ranges[s].second + 0.5) {
      *detector = i;
      *line = t;
      return true;
    }
  }
  return false;
}

std::optional<Eigen::Vector3d> GroundOfDetector(
    const calib::LineCamera& cam,
    const PosTrajectory& pos,
    double detector,
    double line,
    const std::function<double(double, double)>& height) {
  Eigen::Vector3d center, opk;
  pos.PoseAtLine(line, &center, &opk);
  const Eigen::Matrix3d body = calib::RotationFromOpk(opk);
  const Eigen::Vector2d xy = cam.DetectorPosition(detector);
  const Eigen::Vector3d origin = center + body * cam.lever_arm_m;
  const Eigen::Vector3d d =
      body * calib::RotationFromOpk(cam.mount_rad) * Eigen::Vector3d(xy.x(), xy.y(), -cam.c_mm);
  return IntersectSurface(origin, d, height);
}

std::optional<Eigen::Vector3d> IntersectSurface(
    const Eigen::Vector3d& origin,
    const Eigen::Vector3d& direction,
    const std::function<double(double, double)>& height) {
  if (!(direction.z() < 0)) return std::nullopt;
  double z = height(origin.x(), origin.y());
  for (int iteration = 0; iteration < 100; ++iteration) {
    const Eigen::Vector3d p = origin + (z - origin.z()) / direction.z() * direction;
    const double z_new = height(p.x(), p.y());
    if (std::abs(z_new - z) < 1e-6) return Eigen::Vector3d(p.x(), p.y(), z_new);
    z = z_new;
  }
  return std::nullopt;
}

L1Grid MakeL1Grid(const calib::LineCamera& cam,
                  const PosTrajectory& pos,
                  double z_m,
                  double gsd_m) {
  const double first = std::ceil(pos.first_line()), last = std::floor(pos.last_line());
  if (!(last > first)) throw InputError("pos.csv: the L1 image needs at least two lines");
  if (!(gsd_m > 0)) {
    Eigen::Vector3d a, b, opk;
    pos.PoseAtLine(first, &a, &opk);
    pos.PoseAtLine(last, &b, &opk);
    gsd_m = (b - a).head<2>().norm() / (last - first);
    if (!(gsd_m > 0)) throw InputError("pos.csv: the lines do not move (no L1 cell size)");
  }
  const auto flat = [z_m](double, double) { return z_m; };
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  const int steps = 64;
  for (int k = 0; k <= steps; ++k) {
    const double line = first + (last - first) * k / steps;
    for (double detector : {0.0, cam.detectors - 1.0, 0.5 * (cam.detectors - 1.0)}) {
      const auto g = GroundOfDetector(cam, pos, detector, line, flat);
      if (!g) continue;
      lo = lo.cwiseMin(g->head<2>());
      hi = hi.cwiseMax(g->head<2>());
    }
  }
  if (!(hi.x() > lo.x() && hi.y() > lo.y()))
    throw InputError("the line camera does not see the plane Z = " + std::to_string(z_m) + " m");
  L1Grid grid;
  grid.gsd_m = gsd_m;
  grid.z_m = z_m;
  grid.x0_m = lo.x();
  grid.y0_m = lo.y();
  const double cells = (hi.x() - lo.x()) / gsd_m * ((hi.y() - lo.y()) / gsd_m);
  if (!(cells < 2e9)) throw InputError("the L1 image would have more than 2e9 cells (--gsd-m)");
  grid.width = int(std::ceil((hi.x() - lo.x()) / gsd_m)) + 1;
  grid.height = int(std::ceil((hi.y() - lo.y()) / gsd_m)) + 1;
  return grid;
}

void ComputeL1Maps(const calib::LineCamera& cam,
                   const PosTrajectory& pos,
                   const L1Grid& grid,
                   int step,
                   Eigen::MatrixXf* detector_map,
                   Eigen::MatrixXf* line_map) {
  AEROCAL_CHECK(step >= 1) << "map step " << step;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const int nodes_x = (grid.width - 1 + step - 1) / step + 1;
  const int nodes_y = (grid.height - 1 + step - 1) / step + 1;
  Eigen::MatrixXd node_detector(nodes_y, nodes_x), node_line(nodes_y, nodes_x);
  // Exact inverse at the nodes; the start line follows the previous row (the flight is along the
  // rows), the first of a row from the POS line nearest in Y.
  const double first = pos.first_line(), last = pos.last_line();
  double row_guess = first;
  for (int ny = 0; ny < nodes_y; ++ny) {
    double guess = row_guess;
    bool first_found = false;
    for (int nx = 0; nx < nodes_x; ++nx) {
      const Eigen::Vector3d g = grid.Ground(nx * step, ny * step);
      double i = 0, t = 0;
      bool ok = LinePixelOfPoint(cam, pos, guess, g, &i, &t);
      if (!ok) ok = LinePixelOfPoint(cam, pos, 0.5 * (first + last), g, &i, &t);
      const bool inside = ok && t >= first - 0.5 && t <= last + 0.5;
      node_detector(ny, nx) = inside ? i : std::nan("");
      node_line(ny, nx) = inside ? t : std::nan("");
      if (inside) {
        guess = t;
        if (!first_found) row_guess = t, first_found = true;
      }
    }
  }
  const auto SubcameraOfNode = [&cam](double detector) {
    return std::isnan(detector) ? -1 : cam.SubcameraOf(detector);
  };
  detector_map->resize(grid.height, grid.width);
  line_map->resize(grid.height, grid.width);
  for (int row = 0; row < grid.height; ++row) {
    const int ny = std::min(row / step, nodes_y - 2 < 0 ? 0 : nodes_y - 2);
    const double fy = nodes_y > 1 ? (row - ny * step) / double(step) : 0.0;
    for (int col = 0; col < grid.width; ++col) {
      const int nx = std::min(col / step, nodes_x - 2 < 0 ? 0 : nodes_x - 2);
      const double fx = nodes_x > 1 ? (col - nx * step) / double(step) : 0.0;
      const int nx1 = std::min(nx + 1, nodes_x - 1), ny1 = std::min(ny + 1, nodes_y - 1);
      auto lerp = [&](const Eigen::MatrixXd& m) {
        return (1 - fy) * ((1 - fx) * m(ny, nx) + fx * m(ny, nx1)) +
               fy * ((1 - fx) * m(ny1, nx) + fx * m(ny1, nx1));
      };
      double i = lerp(node_detector), t = lerp(node_line);  // NaN when a node is invalid
      // Exact where the four nodes do not lie in one sub-camera (a seam: the map jumps there) or
      // not all are valid (the swath's edge).
      const int s00 = SubcameraOfNode(node_detector(ny, nx)),
                s01 = SubcameraOfNode(node_detector(ny, nx1));
      const int s10 = SubcameraOfNode(node_detector(ny1, nx)),
                s11 = SubcameraOfNode(node_detector(ny1, nx1));
      if (s00 < 0 || s00 != s01 || s00 != s10 || s00 != s11) {
        double guess = 0.5 * (first + last);
        for (double node_t :
             {node_line(ny, nx), node_line(ny, nx1), node_line(ny1, nx), node_line(ny1, nx1)})
          if (!std::isnan(node_t)) guess = node_t;
        const bool ok = LinePixelOfPoint(cam, pos, guess, grid.Ground(col, row), &i, &t) &&
                        t >= first - 0.5 && t <= last + 0.5;
        if (!ok) i = t = std::nan("");
      }
      (*detector_map)(row, col) = std::isnan(i) || std::isnan(t) ? nan : float(i);
      (*line_map)(row, col) = std::isnan(i) || std::isnan(t) ? nan : float(t);
    }
  }
}

float SampleBilinear(const stitch::GrayImage& image, double col, double row) {
  if (!(col >= 0 && row >= 0 && col <= image.cols() - 1 && row <= image.rows() - 1))
    return std::numeric_limits<float>::quiet_NaN();
  const int c0 = std::min(int(col), int(image.cols()) - 2 < 0 ? 0 : int(image.cols()) - 2);
  const int r0 = std::min(int(row), int(image.rows()) - 2 < 0 ? 0 : int(image.rows()) - 2);
  const int c1 = std::min(c0 + 1, int(image.cols()) - 1),
            r1 = std::min(r0 + 1, int(image.rows()) - 1);
  const float fc = float(col - c0), fr = float(row - r0);
  return (1 - fr) * ((1 - fc) * image(r0, c0) + fc * image(r0, c1)) +
         fr * ((1 - fc) * image(r1, c0) + fc * image(r1, c1));
}

stitch::GrayImage ResampleThroughMaps(const stitch::GrayImage& line_image,
                                      const Eigen::MatrixXf& detector_map,
                                      const Eigen::MatrixXf& line_map) {
  stitch::GrayImage out(detector_map.rows(), detector_map.cols());
  for (int row = 0; row < out.rows(); ++row)
    for (int col = 0; col < out.cols(); ++col) {
      const float i = detector_map(row, col), t = line_map(row, col);
      const float v = std::isnan(i) ? std::nanf("") : SampleBilinear(line_image, i, t);
      out(row, col) = std::isnan(v) ? 0.0f : v;
    }
  return out;
}

L1Image RectifyLineImage(const calib::LineCamera& cam,
                         const PosTrajectory& pos,
                         const stitch::GrayImage& line_image,
                         double z_m,
                         double gsd_m,
                         int map_step_px) {
  L1Image l1;
  l1.grid = MakeL1Grid(cam, pos, z_m, gsd_m);
  ComputeL1Maps(cam, pos, l1.grid, map_step_px, &l1.detector_map, &l1.line_map);
  // Cells whose line-image position lies outside the image are invalid too.
  for (int row = 0; row < l1.grid.height; ++row)
    for (int col = 0; col < l1.grid.width; ++col) {
      const float i = l1.detector_map(row, col), t = l1.line_map(row, col);
      if (!(i >= 0 && t >= 0 && i <= line_image.cols() - 1 && t <= line_image.rows() - 1))
        l1.detector_map(row, col) = l1.line_map(row, col) = std::nanf("");
    }
  l1.image = ResampleThroughMaps(line_image, l1.detector_map, l1.line_map);
  return l1;
}

}  // namespace aerocal::triangulation
