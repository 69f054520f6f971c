#include "stitch/layout/grid_layout.h"

#include "calib/core/error.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch {

std::string RomanNumeral(int n) {
  static const std::pair<int, const char*> kTable[] = {{1000, "M"},
                                                       {900, "CM"},
                                                       {500, "D"},
                                                       {400, "CD"},
                                                       {100, "C"},
                                                       {90, "XC"},
                                                       {50, "L"},
                                                       {40, "XL"},
                                                       {10, "X"},
                                                       {9, "IX"},
                                                       {5, "V"},
                                                       {4, "IV"},
                                                       {1, "I"}};
  std::string out;
  for (const auto& [value, symbol] : kTable)
    while (n >= value) {
      out += symbol;
      n -= value;
    }
  return out;
}

calib::Camera MakeGridCamera(const GridLayoutOptions& o) {
  if (o.rows < 1 || o.cols < 1 || o.rows * o.cols < 2)
    throw ConfigError("grid layout needs at least two sub-images (got " + std::to_string(o.rows) +
                      " x " + std::to_string(o.cols) + ")");
  if (o.overlap_px < 0) throw ConfigError("overlap_px must be >= 0");
  // Sub-image size so that cols sub-images with (cols-1) overlaps span the virtual width.
  const int w = (o.virtual_width_px + (o.cols - 1) * o.overlap_px + o.cols - 1) / o.cols;
  const int h = (o.virtual_height_px + (o.rows - 1) * o.overlap_px + o.rows - 1) / o.rows;
  calib::Camera camera;
  camera.name = o.name;
  camera.pixel_size_mm = o.pixel_size_mm;
  camera.width_px = o.virtual_width_px;
  camera.height_px = o.virtual_height_px;
  camera.interior[calib::Camera::Model::kC] = o.c_mm;
  int n = 0;
  for (int r = 0; r < o.rows; ++r) {
    for (int c = 0; c < o.cols; ++c) {
      calib::SubimageMapping s;
      s.id = RomanNumeral(++n);
      s.width_px = w;
      s.height_px = h;
      s.model = o.model;
      // The last column/row ends exactly at the virtual format's far edge.
      const double tx =
          o.cols > 1 ? static_cast<double>(c) * (o.virtual_width_px - w) / (o.cols - 1) : 0.0;
      const double ty =
          o.rows > 1 ? static_cast<double>(r) * (o.virtual_height_px - h) / (o.rows - 1) : 0.0;
      Eigen::Matrix3d shift = Eigen::Matrix3d::Identity();
      shift(0, 2) = std::round(tx);
      shift(1, 2) = std::round(ty);
      s.params = calib::ParamsFromHomography(o.model, shift);
      camera.subimages.push_back(s);
    }
  }
  for (const auto& id : o.base_ids)
    if (camera.SubimageIndex(id) < 0)
      throw ConfigError("base sub-image '" + id + "' is not in the layout");

  auto add_reference = [&](const calib::SubimageMapping& s, double u, double v) {
    const Eigen::Vector2d virtual_px = s.VirtualFromSub({u, v});
    calib::ReferencePoint p;
    p.id = "R" + std::to_string(camera.reference_points.size() + 1);
    p.subimage = s.id;
    p.u = u;
    p.v = v;
    p.U = virtual_px.x();
    p.V = virtual_px.y();
    p.sigma_px = o.reference_sigma_px;
    camera.reference_points.push_back(p);
  };
  const double d = o.reference_inset_px;
  for (const auto& s : camera.subimages) {
    const double u0 = d, u1 = s.width_px - 1 - d, v0 = d, v1 = s.height_px - 1 - d;
    if (o.reference_placement == ReferencePlacement::kBaseCorners) {
      if (std::find(o.base_ids.begin(), o.base_ids.end(), s.id) == o.base_ids.end()) continue;
      for (double u : {u0, u1})
        for (double v : {v0, v1}) add_reference(s, u, v);
    } else {
      // Corners of this sub-image that are corners of the virtual format.
      for (double u : {u0, u1})
        for (double v : {v0, v1}) {
          const Eigen::Vector2d p = s.VirtualFromSub({u, v});
          const bool outer_u = p.x() < d + 1 || p.x() > camera.width_px - d - 2;
          const bool outer_v = p.y() < d + 1 || p.y() > camera.height_px - d - 2;
          if (outer_u || outer_v) add_reference(s, u, v);
        }
    }
  }
  return camera;
}

}  // namespace aerocal::stitch
