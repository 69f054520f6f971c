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
  const double r2 = r * r;
  return 1e3 * r * (p[Model::kK1] * r2 + p[Model::kK2] * r2 * r2 + p[Model::kK3] * r2 * r2 * r2);
}

double DecentringDistortionUm(const calib::InteriorParams& p, double r) {
  return 1e3 * r * r * std::hypot(p[Model::kP1], p[Model::kP2]);
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

  const bool ours = camera.model == Model::kId;
  out.profile_kind = ours ? "10-parameter terms" : "mean over directions";
  calib::InteriorParams params{};
  if (ours)
    for (int k = 0; k < Model::kNumParams; ++k) params[k] = camera.params[k];
  constexpr int kDirections = 72;
  for (int i = 0; i <= profile_samples; ++i) {
    const double r = r_max * i / profile_samples;
    if (ours) {
      out.profile.push_back({r, RadialDistortionUm(params, r), DecentringDistortionUm(params, r)});
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
