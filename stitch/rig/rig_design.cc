#include "stitch/rig/rig_design.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/core/svg.h"
#include "stitch/rig/rig_conversion.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <bitset>
#include <cmath>
#include <map>
#include <sstream>

namespace aerocal::stitch {
namespace {

constexpr double kRadToDeg = 180.0 / M_PI;

int PopCount(unsigned mask) { return static_cast<int>(std::bitset<32>(mask).count()); }

// The nadir exposure: rig attitude 0, virtual centre at the origin, plane Z = -H.
RigConverter NadirConverter(const calib::Rig& rig, double height_m) {
  const RigExposure nadir;
  return RigConverter(rig, nadir, MakeRectificationPlane(rig, nadir, height_m));
}

// Pixels around a head's format outline, `per_side` per side, clockwise from the top left.
std::vector<Eigen::Vector2d> FormatOutline(const calib::Camera& camera, int per_side) {
  const double w = camera.width_px - 1, h = camera.height_px - 1;
  const Eigen::Vector2d corners[4] = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  std::vector<Eigen::Vector2d> outline;
  for (int side = 0; side < 4; ++side)
    for (int i = 0; i < per_side; ++i)
      outline.push_back(corners[side] +
                        (corners[(side + 1) % 4] - corners[side]) * double(i) / per_side);
  return outline;
}

HeadDesign DesignHead(const RigConverter& converter, int k, double height_m) {
  const calib::RigHead& head = converter.rig().heads[k];
  const calib::Camera& camera = head.camera;
  HeadDesign design;
  design.id = head.id;
  // Nadir in head coordinates; the photo direction toward it is "along the tilt".
  const Eigen::Vector3d nadir = converter.ObjectFromHead(k).transpose() * Eigen::Vector3d(0, 0, -1);
  design.tilt_deg = std::acos(std::clamp(-nadir.z(), -1.0, 1.0)) * kRadToDeg;
  Eigen::Vector2d along(1.0, 0.0);
  if (nadir.head<2>().norm() > 1e-12) along = nadir.head<2>().normalized();
  const Eigen::Vector2d across(-along.y(), along.x());
  const double head_height_m = converter.HeadCenter(k).z() + height_m;  // above Z = -H
  design.nadir_gsd_m = camera.pixel_size_mm * head_height_m / camera.c_mm();
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  const double w = camera.width_px - 1, h = camera.height_px - 1;
  const std::vector<std::pair<std::string, Eigen::Vector2d>> points = {
      {"principal_point", camera.PixelFromPhoto(principal)},
      {"edge_top", {w / 2, 0}},
      {"edge_bottom", {w / 2, h}},
      {"edge_left", {0, h / 2}},
      {"edge_right", {w, h / 2}},
      {"corner_top_left", {0, 0}},
      {"corner_top_right", {w, 0}},
      {"corner_bottom_left", {0, h}},
      {"corner_bottom_right", {w, h}}};
  // Photo direction -> pixel step (rows grow downwards).
  const auto pixel_step = [](const Eigen::Vector2d& photo) {
    return Eigen::Vector2d(0.5 * photo.x(), -0.5 * photo.y());
  };
  for (const auto& [where, pixel] : points) {
    GsdSample s;
    s.where = where;
    s.pixel = pixel;
    const Eigen::Vector2d offset_mm = camera.PhotoFromPixel(pixel) - principal;
    s.off_axis_deg = std::atan2(-offset_mm.dot(along), camera.c_mm()) * kRadToDeg;
    for (int axis = 0; axis < 2; ++axis) {
      const Eigen::Vector2d step = pixel_step(axis == 0 ? along : across);
      const auto plus = converter.PlanePointOfHeadPixel(k, pixel + step);
      const auto minus = converter.PlanePointOfHeadPixel(k, pixel - step);
      s.ratio[axis] = plus && minus ? (*plus - *minus).norm() / design.nadir_gsd_m : NAN;
    }
    s.on_tilt_line = std::abs(offset_mm.dot(across)) < 1e-6;
    if (s.on_tilt_line)
      s.closed_form = ClosedFormGsdRatio(design.tilt_deg / kRadToDeg, s.off_axis_deg / kRadToDeg);
    design.samples.push_back(s);
  }
  for (const Eigen::Vector2d& pixel : FormatOutline(camera, 40)) {
    const auto ground = converter.PlanePointOfHeadPixel(k, pixel);
    if (!ground) continue;
    design.footprint_m.push_back(ground->head<2>());
    if (const auto v = converter.VirtualPixelOfPoint(*ground)) design.outline_px.push_back(*v);
  }
  if (!design.footprint_m.empty()) design.footprint_m.push_back(design.footprint_m.front());
  if (!design.outline_px.empty()) design.outline_px.push_back(design.outline_px.front());
  return design;
}

// Largest rectangle of cells with a non-zero mask (histogram method), as cell index bounds.
void LargestCoveredRectangle(const RigCoverage& c, int* c0, int* r0, int* c1, int* r1) {
  std::vector<int> height(c.cols, 0);
  long best = 0;
  *c0 = *r0 = *c1 = *r1 = 0;
  for (int row = 0; row < c.rows; ++row) {
    for (int col = 0; col < c.cols; ++col)
      height[col] = c.mask[row * c.cols + col] != 0 ? height[col] + 1 : 0;
    std::vector<int> stack;
    for (int col = 0; col <= c.cols; ++col) {
      const int hgt = col < c.cols ? height[col] : 0;
      while (!stack.empty() && height[stack.back()] >= hgt) {
        const int top = stack.back();
        stack.pop_back();
        const int left = stack.empty() ? 0 : stack.back() + 1;
        const long area = static_cast<long>(height[top]) * (col - left);
        if (area > best) {
          best = area;
          *c0 = left;
          *c1 = col - 1;
          *r1 = row;
          *r0 = row - height[top] + 1;
        }
      }
      stack.push_back(col);
    }
  }
}

}  // namespace

Eigen::Vector2d ClosedFormGsdRatio(double tilt_rad, double off_axis_rad) {
  const double ca = std::cos(off_axis_rad), cta = std::cos(tilt_rad + off_axis_rad);
  return {ca * ca / (cta * cta), ca / cta};
}

std::string ZoneName(const calib::Rig& rig, unsigned mask) {
  if (PopCount(mask) < 2) return "";
  std::string name;
  for (size_t k = 0; k < rig.heads.size(); ++k)
    if (mask & (1u << k)) name += rig.heads[k].id;
  return name;
}

RigCoverage ComputeRigCoverage(const calib::Rig& rig, double height_m, double cell_px) {
  AEROCAL_CHECK(cell_px > 0 && rig.heads.size() <= calib::kMaxRigHeads)
      << "cell size > 0, at most 32 heads";
  const RigConverter converter = NadirConverter(rig, height_m);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k)
    for (const Eigen::Vector2d& pixel : FormatOutline(rig.heads[k].camera, 40))
      if (const auto v = converter.VirtualFromHead(k, pixel)) {
        lo = lo.cwiseMin(*v);
        hi = hi.cwiseMax(*v);
      }
  AEROCAL_CHECK(lo.x() <= hi.x()) << "no head reaches the rectification plane";
  RigCoverage c;
  c.cell_px = cell_px;
  c.origin_px = lo;
  c.cols = static_cast<int>(std::floor((hi.x() - lo.x()) / cell_px)) + 1;
  c.rows = static_cast<int>(std::floor((hi.y() - lo.y()) / cell_px)) + 1;
  c.mask.assign(static_cast<size_t>(c.cols) * c.rows, 0u);
  for (int row = 0; row < c.rows; ++row)
    for (int col = 0; col < c.cols; ++col)
      for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
        const auto p = converter.HeadFromVirtual(k, c.CellCenter(col, row));
        if (p && converter.InHeadFormat(k, *p)) c.mask[row * c.cols + col] |= 1u << k;
      }
  return c;
}

std::vector<StandardPosition> StandardTiePositions(const calib::Rig& rig, const RigCoverage& c) {
  std::map<unsigned, std::vector<Eigen::Vector2d>> cells;
  for (int row = 0; row < c.rows; ++row)
    for (int col = 0; col < c.cols; ++col) {
      const unsigned mask = c.mask[row * c.cols + col];
      if (PopCount(mask) >= 2) cells[mask].push_back(c.CellCenter(col, row));
    }
  std::vector<std::pair<unsigned, std::vector<Eigen::Vector2d>>> zones(cells.begin(), cells.end());
  std::sort(zones.begin(), zones.end(), [&](const auto& a, const auto& b) {
    const int pa = PopCount(a.first), pb = PopCount(b.first);
    return pa != pb ? pa < pb : ZoneName(rig, a.first) < ZoneName(rig, b.first);
  });
  std::vector<StandardPosition> positions;
  for (const auto& zone_cells : zones) {
    // (named copies: a lambda may not capture a structured binding in C++17; clang refuses it)
    const unsigned mask = zone_cells.first;
    const std::vector<Eigen::Vector2d>& points = zone_cells.second;
    const std::string zone = ZoneName(rig, mask);
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& p : points) mean += p;
    mean /= points.size();
    const auto nearest = [&](const Eigen::Vector2d& target) {
      return *std::min_element(points.begin(), points.end(), [&](const auto& a, const auto& b) {
        return (a - target).squaredNorm() < (b - target).squaredNorm();
      });
    };
    if (PopCount(mask) >= 3 || points.size() < 2) {
      positions.push_back({zone, zone, nearest(mean)});
      continue;
    }
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const auto& p : points) scatter += (p - mean) * (p - mean).transpose();
    const Eigen::Vector2d axis =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvectors().col(1);
    std::vector<double> along;
    for (const auto& p : points) along.push_back((p - mean).dot(axis));
    std::sort(along.begin(), along.end());
    for (int i = 0; i < 2; ++i) {
      const double q = along[static_cast<size_t>((i == 0 ? 0.2 : 0.8) * (along.size() - 1))];
      // The zone cells across the band at that place; their middle one.
      std::vector<std::pair<double, Eigen::Vector2d>> band;
      for (const auto& p : points)
        if (std::abs((p - mean).dot(axis) - q) <= 1.01 * c.cell_px)
          band.push_back({(p - mean).dot(Eigen::Vector2d(-axis.y(), axis.x())), p});
      std::sort(
          band.begin(), band.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      positions.push_back({zone + "-" + std::to_string(i + 1), zone, band[band.size() / 2].second});
    }
  }
  return positions;
}

RigDesign DesignRig(const calib::Rig& rig, double height_m, int grid_cells) {
  AEROCAL_CHECK(height_m > 0 && grid_cells >= 10) << "height > 0 m, grid >= 10 cells";
  RigDesign d;
  d.height_m = height_m;
  const RigConverter converter = NadirConverter(rig, height_m);
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k)
    d.heads.push_back(DesignHead(converter, k, height_m));
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const HeadDesign& head : d.heads)
    for (const auto& v : head.outline_px) {
      lo = lo.cwiseMin(v);
      hi = hi.cwiseMax(v);
    }
  d.coverage = ComputeRigCoverage(rig, height_m, (hi - lo).maxCoeff() / grid_cells);
  const RigCoverage& c = d.coverage;
  const calib::Camera& v = rig.virtual_camera.camera;
  d.virtual_gsd_m = v.pixel_size_mm * height_m / v.c_mm();  // at the principal point
  const double cell_area_m2 = std::pow(c.cell_px * d.virtual_gsd_m, 2);
  std::map<std::string, int> zone_cells;
  int covered = 0;
  for (int row = 0; row < c.rows; ++row)
    for (int col = 0; col < c.cols; ++col) {
      const unsigned mask = c.mask[row * c.cols + col];
      if (mask == 0) continue;
      ++covered;
      if (PopCount(mask) >= 2) ++zone_cells[ZoneName(rig, mask)];
    }
  d.covered_box_px = {lo, hi};  // of the outlines: exact, not of cell resolution
  d.covered_area_m2 = covered * cell_area_m2;
  for (const auto& [zone, n] : zone_cells) d.zone_area_m2.push_back({zone, n * cell_area_m2});
  int c0, r0, c1, r1;
  LargestCoveredRectangle(c, &c0, &r0, &c1, &r1);
  // Conservative: the rectangle spanned by the covered cell centres.
  d.effective_px = {c.CellCenter(c0, r0), c.CellCenter(c1, r1)};
  d.effective_area_m2 =
      d.effective_px.Width() * d.effective_px.Height() * std::pow(d.virtual_gsd_m, 2);
  d.standard_positions = StandardTiePositions(rig, c);
  return d;
}

namespace {

// The footprints' panel: ground metres (X right, Y up) on axes, 800 SVG pixels along the longer
// side of the footprints' extent plus a 5 % margin, room for the axes' labels.
SvgPanel FootprintPanel(const RigDesign& d) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const auto& head : d.heads)
    for (const auto& p : head.footprint_m) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  const double margin = 0.05 * (hi - lo).maxCoeff();
  lo -= Eigen::Vector2d::Constant(margin);
  hi += Eigen::Vector2d::Constant(margin);
  const double scale = 800.0 / (hi - lo).maxCoeff();
  SvgPanel panel;
  panel.left = 80, panel.width = (hi.x() - lo.x()) * scale,
  panel.height = (hi.y() - lo.y()) * scale;
  panel.bottom = 40 + panel.height;
  panel.x_lo = lo.x(), panel.x_hi = hi.x(), panel.y_lo = lo.y(), panel.y_hi = hi.y();
  return panel;
}

// The SVG's opening, title, axes, scale bar and legend.
std::string FootprintSvgHead(const calib::Rig& rig, const RigDesign& d, const SvgPanel& panel) {
  const double metres_per_svg_px = (panel.x_hi - panel.x_lo) / panel.width;
  std::ostringstream out;
  out << StringPrintf(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n"
      "<title>%s: head footprints at H = %g m (ground metres, X right, Y up)</title>\n"
      "<text x=\"10\" y=\"18\">%s: head footprints at H = %g m</text>\n",
      panel.left + panel.width + 20,
      panel.bottom + 110,
      SvgEscape(rig.name).c_str(),
      d.height_m,
      SvgEscape(rig.name).c_str(),
      d.height_m);
  out << SvgAxes(panel, "X (m, from the nadir point)", "Y (m)")
      << SvgScaleBar(panel.left, panel.bottom + 70, metres_per_svg_px, 0.4 * panel.width, "m")
      << StringPrintf(
             "<text x=\"%.1f\" y=\"%.1f\">dashed: the virtual format; bold: the effective "
             "format; dots: standard tie positions</text>\n",
             panel.left,
             panel.bottom + 95);
  return out.str();
}

}  // namespace

std::string RigDesignSvg(const calib::Rig& rig, const RigDesign& d) {
  // Ground metres of a virtual pixel (level nadir virtual camera: x -> X, y up -> Y): its ray
  // (ideal x, ideal y, -c) scaled to the height; the pinhole part where the model's inversion
  // fails (a pixel far outside a strongly distorted format).
  const calib::Camera& v = rig.virtual_camera.camera;
  const auto ground = [&](const Eigen::Vector2d& px) {
    const std::optional<Eigen::Vector3d> ray = rig.virtual_camera.RayFromPixel(px);
    const Eigen::Vector3d r =
        ray ? *ray
            : (Eigen::Vector3d() << v.PhotoFromPixel(px) - v.PrincipalPointMm(), -v.c_mm())
                  .finished();
    return Eigen::Vector2d(r.head<2>() * d.height_m / -r.z());
  };
  const SvgPanel panel = FootprintPanel(d);
  const auto sx = [&](const Eigen::Vector2d& p) { return panel.X(p.x()); };
  const auto sy = [&](const Eigen::Vector2d& p) { return panel.Y(p.y()); };
  std::ostringstream out;
  out << FootprintSvgHead(rig, d, panel);
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b"};
  for (size_t k = 0; k < d.heads.size(); ++k) {
    out << "<polygon fill=\"" << colours[k % 6] << "\" fill-opacity=\"0.2\" stroke=\""
        << colours[k % 6] << "\" points=\"";
    for (const auto& p : d.heads[k].footprint_m) out << StringPrintf("%.1f,%.1f ", sx(p), sy(p));
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const auto& p : d.heads[k].footprint_m) centre += p;
    centre /= std::max<size_t>(1, d.heads[k].footprint_m.size());
    out << "\"/>\n"
        << StringPrintf("<text x=\"%.1f\" y=\"%.1f\" font-size=\"20\">%s</text>\n",
                        sx(centre),
                        sy(centre),
                        SvgEscape(d.heads[k].id).c_str());
  }
  const auto rectangle = [&](const PixelRectangle& r, const char* style) {
    const Eigen::Vector2d a = ground(r.min_px), b = ground(r.max_px);
    out << StringPrintf("<rect x=\"%.1f\" y=\"%.1f\" width=\"%.1f\" height=\"%.1f\" %s/>\n",
                        std::min(sx(a), sx(b)),
                        std::min(sy(a), sy(b)),
                        std::abs(sx(b) - sx(a)),
                        std::abs(sy(b) - sy(a)),
                        style);
  };
  rectangle({Eigen::Vector2d(-0.5, -0.5), Eigen::Vector2d(v.width_px - 0.5, v.height_px - 0.5)},
            "fill=\"none\" stroke=\"black\" stroke-dasharray=\"8,4\"");
  rectangle(d.effective_px, "fill=\"none\" stroke=\"black\" stroke-width=\"2\"");
  for (const auto& s : d.standard_positions) {
    const Eigen::Vector2d p = ground(s.virtual_px);
    out << StringPrintf(
        "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"4\"/><text x=\"%.1f\" y=\"%.1f\" "
        "font-size=\"11\">%s</text>\n",
        sx(p),
        sy(p),
        sx(p) + 5,
        sy(p) - 5,
        SvgEscape(s.name).c_str());
  }
  out << "</svg>\n";
  return out.str();
}

}  // namespace aerocal::stitch
