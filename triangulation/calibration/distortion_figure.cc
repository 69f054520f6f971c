#include "triangulation/calibration/distortion_figure.h"

#include "calib/camera/brown_fraser10.h"

#include <cmath>
#include <optional>

namespace aerocal::triangulation {
namespace {

using Model = calib::BrownFraser10Model;

// ideal - reduced measured (mm) at a photo point, or nothing where the model does not invert.
std::optional<Eigen::Vector2d> CorrectionMm(const calib::ModelCamera& camera,
                                            const Eigen::Vector2d& principal_mm,
                                            const Eigen::Vector2d& photo_mm) {
  Eigen::Vector2d ideal;
  if (!camera.IdealFromPixel(camera.frame.PixelFromPhoto(photo_mm), &ideal)) return std::nullopt;
  return ideal - (photo_mm - principal_mm);
}

}  // namespace

double RadialDistortionUm(const calib::InteriorParams& p, double r) {
  return Model::RadialDistortionUm(p.data(), r);
}

double DecentringDistortionUm(const calib::InteriorParams& p, double r) {
  return Model::DecentringDistortionUm(p.data(), r);
}

DistortionFigure DistortionOverFormat(const calib::ModelCamera& camera,
                                      int profile_samples,
                                      int columns,
                                      int rows) {
  DistortionFigure out;
  Eigen::Vector2d principal_px;
  if (!camera.PixelFromIdeal(Eigen::Vector2d::Zero(), &principal_px)) return out;
  const Eigen::Vector2d principal_mm = camera.frame.PhotoFromPixel(principal_px);
  const double p = camera.frame.pixel_size_mm;
  const double half_w = 0.5 * p * camera.frame.width_px, half_h = 0.5 * p * camera.frame.height_px;
  const double r_max = std::hypot(half_w, half_h);

  // A model with its own profile at a radius (its struct's terms) gives it; any other is measured
  // over the format as the mean over directions.
  const bool own = calib::HasDistortionAtRadius(camera.model);
  out.profile_kind = own ? "10-parameter terms" : "mean over directions";
  constexpr int kDirections = 72;
  for (int i = 0; i <= profile_samples; ++i) {
    const double r = r_max * i / profile_samples;
    if (own) {
      const auto d = calib::ModelDistortionAtRadius(camera.model, camera.params.data(), r);
      out.profile.push_back({r, d->radial_um, d->decentring_um});
      continue;
    }
    double radial = 0, tangential2 = 0;
    int n = 0;
    for (int d = 0; d < kDirections; ++d) {
      const double a = 2 * M_PI * d / kDirections;
      const Eigen::Vector2d u(std::cos(a), std::sin(a));
      const auto c = CorrectionMm(camera, principal_mm, principal_mm + r * u);
      if (!c) continue;
      radial += 1e3 * c->dot(u);
      tangential2 += std::pow(1e3 * (u.x() * c->y() - u.y() * c->x()), 2);
      ++n;
    }
    if (n == kDirections) out.profile.push_back({r, radial / n, std::sqrt(tangential2 / n)});
  }
  for (int i = 0; i < columns; ++i)
    for (int j = 0; j < rows; ++j) {
      const Eigen::Vector2d x(-half_w + 2 * half_w * i / (columns - 1),
                              -half_h + 2 * half_h * j / (rows - 1));
      if (const auto c = CorrectionMm(camera, principal_mm, x))
        out.grid.push_back({x.x(), x.y(), 1e3 * c->x(), 1e3 * c->y()});
    }
  return out;
}

}  // namespace aerocal::triangulation
