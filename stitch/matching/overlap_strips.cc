#include "stitch/matching/overlap_strips.h"

#include <algorithm>

namespace aerocal::stitch {
namespace {

Eigen::Vector2d MaxCorner(const calib::SubimageMapping& s) {
  return {s.width_px - 1.0, s.height_px - 1.0};
}

// Bounding box of a box's corners mapped by `map`.
template <typename Map>
Eigen::AlignedBox2d MapBox(const Eigen::AlignedBox2d& box, Map map) {
  Eigen::AlignedBox2d out;
  for (int c = 0; c < 4; ++c)
    out.extend(map(box.corner(static_cast<Eigen::AlignedBox2d::CornerType>(c))));
  return out;
}

Eigen::AlignedBox2d Footprint(const calib::SubimageMapping& s) {
  return MapBox(Eigen::AlignedBox2d(Eigen::Vector2d::Zero(), MaxCorner(s)),
                [&](const Eigen::Vector2d& uv) { return s.VirtualFromSub(uv); });
}

Eigen::AlignedBox2d WindowIn(const calib::SubimageMapping& s, const Eigen::AlignedBox2d& grown) {
  const Eigen::AlignedBox2d window =
      MapBox(grown, [&](const Eigen::Vector2d& p) { return s.SubFromVirtual(p); });
  return window.intersection(Eigen::AlignedBox2d(Eigen::Vector2d::Zero(), MaxCorner(s)));
}

}  // namespace

std::vector<OverlapStrip> PredictOverlapStrips(const calib::Camera& camera,
                                               double margin_px,
                                               double min_width_px) {
  std::vector<OverlapStrip> strips;
  const int n = static_cast<int>(camera.subimages.size());
  for (int a = 0; a < n; ++a) {
    for (int b = a + 1; b < n; ++b) {
      const calib::SubimageMapping& sa = camera.subimages[a];
      const calib::SubimageMapping& sb = camera.subimages[b];
      const Eigen::AlignedBox2d overlap = Footprint(sa).intersection(Footprint(sb));
      if (overlap.isEmpty() || overlap.sizes().minCoeff() < min_width_px) continue;
      Eigen::AlignedBox2d grown = overlap;
      grown.min().array() -= margin_px;
      grown.max().array() += margin_px;
      strips.push_back(
          {a, b, sa.id + "-" + sb.id, overlap, WindowIn(sa, grown), WindowIn(sb, grown)});
    }
  }
  return strips;
}

}  // namespace aerocal::stitch
