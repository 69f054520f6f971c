#include "calib/camera/camera.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"

namespace aerocal::calib {

Camera Camera::OfModel(CameraModelId model) {
  Camera camera;
  camera.model = model;
  camera.interior = InteriorParams::ForModel(model);
  camera.interior_sigma = InteriorSigmas::ForModel(model);
  return camera;
}

int Camera::ParamIndex(std::string_view name) const {
  return VisitCameraModel(model, [&](auto m) { return IndexOfParam(decltype(m)::kParams, name); });
}

double Camera::c_mm() const {
  return VisitCameraModel(
      model, [&](auto m) { return decltype(m)::PrincipalDistanceMm(interior.data(), frame()); });
}

void Camera::SetPrincipalDistanceMm(double c) {
  const double scale = c / c_mm();
  const std::vector<ParamInfo> table = Params();
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].group == ParamGroup::kPrincipalDistance)
      interior[i] = table[i].unit == "mm" ? c : interior[i] * scale;
}

Eigen::Vector2d Camera::PrincipalPointMm() const {
  const double ideal[2] = {0.0, 0.0};
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();
  const bool ok = VisitCameraModel(model, [&](auto m) {
    return decltype(m)::MeasuredFromIdeal(interior.data(), frame(), ideal, xy.data());
  });
  AEROCAL_CHECK(ok) << "principal point of camera " << name << " not found";
  return xy;
}

bool Camera::IdealFromPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* ideal_mm) const {
  const Eigen::Vector2d xy = PhotoFromPixel(pixel);
  return VisitCameraModel(model, [&](auto m) {
    return decltype(m)::IdealFromMeasured(interior.data(), frame(), xy.data(), ideal_mm->data());
  });
}

bool Camera::PixelFromIdeal(const Eigen::Vector2d& ideal_mm, Eigen::Vector2d* pixel) const {
  Eigen::Vector2d measured;
  const bool ok = VisitCameraModel(model, [&](auto m) {
    return decltype(m)::MeasuredFromIdeal(
        interior.data(), frame(), ideal_mm.data(), measured.data());
  });
  if (ok) *pixel = PixelFromPhoto(measured);
  return ok;
}

ModelCamera Camera::AsModelCamera() const { return {model, interior.values(), frame()}; }

Camera Camera::WithModelCamera(const ModelCamera& camera) const {
  AEROCAL_CHECK(static_cast<int>(camera.params.size()) == CameraModelParamCount(camera.model))
      << "camera " << name << ": " << camera.params.size() << " parameters for model "
      << CameraModelName(camera.model);
  Camera out = *this;
  if (camera.model != model) out.interior_sigma = InteriorSigmas::ForModel(camera.model);
  out.model = camera.model;
  out.interior = InteriorParams(camera.params);
  out.pixel_size_mm = camera.frame.pixel_size_mm;
  out.width_px = camera.frame.width_px;
  out.height_px = camera.frame.height_px;
  return out;
}

bool Camera::ProjectToPixel(const Eigen::Vector3d& opk_rad,
                            const Eigen::Vector3d& center_m,
                            const Eigen::Vector3d& point_m,
                            Eigen::Vector2d* pixel) const {
  double uvw[3];
  ImageSpaceFromObject(opk_rad.data(), center_m.data(), point_m.data(), uvw);
  if (!(uvw[2] < 0)) return false;  // the camera looks along -W
  const double c = c_mm();
  // The models' inversions converge to 1e-10 px (brown_fraser_10) or 1e-13 in normalised
  // coordinates (forward models: closed form).
  return PixelFromIdeal({-c * uvw[0] / uvw[2], -c * uvw[1] / uvw[2]}, pixel);
}

int Camera::SubimageIndex(const std::string& id) const {
  for (size_t i = 0; i < subimages.size(); ++i)
    if (subimages[i].id == id) return static_cast<int>(i);
  return -1;
}

Camera PinholeCamera(double c_mm, double x0_mm, double y0_mm, const PixelFrame& frame) {
  using Model = AdjustmentCameraModel;
  Camera camera = Camera::OfModel(Model::kId);
  camera.pixel_size_mm = frame.pixel_size_mm;
  camera.width_px = frame.width_px;
  camera.height_px = frame.height_px;
  camera.interior[Model::kC] = c_mm;
  camera.interior[Model::kX0] = x0_mm;
  camera.interior[Model::kY0] = y0_mm;
  return camera;
}

}  // namespace aerocal::calib
