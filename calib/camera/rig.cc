#include "calib/camera/rig.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <cmath>
#include <set>

namespace aerocal::calib {

VirtualCamera VirtualCamera::Pinhole(VirtualOrientation orientation,
                                     double c_mm,
                                     double pixel_size_mm,
                                     int width_px,
                                     int height_px,
                                     double x0_mm,
                                     double y0_mm,
                                     std::optional<double> height_m) {
  return {orientation,
          PinholeCamera(c_mm, x0_mm, y0_mm, {pixel_size_mm, width_px, height_px}),
          height_m};
}

std::optional<Eigen::Vector3d> VirtualCamera::RayFromPixel(const Eigen::Vector2d& pixel) const {
  Eigen::Vector2d ideal;
  if (!camera.IdealFromPixel(pixel, &ideal)) return std::nullopt;
  return Eigen::Vector3d(ideal.x(), ideal.y(), -camera.c_mm());
}

bool VirtualCamera::PixelFromRay(const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) const {
  if (!(ray.z() < 0)) return false;
  const double c = camera.c_mm();
  return camera.PixelFromIdeal({-c * ray.x() / ray.z(), -c * ray.y() / ray.z()}, pixel);
}

int Rig::HeadIndex(const std::string& id) const {
  for (size_t k = 0; k < heads.size(); ++k)
    if (heads[k].id == id) return static_cast<int>(k);
  return -1;
}

int Rig::ReferenceIndex() const {
  const int k = HeadIndex(reference_head);
  AEROCAL_CHECK(k >= 0) << "rig '" << name << "' has no reference head '" << reference_head << "'";
  return k;
}

void Rig::Validate(const std::string& where) const {
  const SourceRef at{where, 0};
  if (heads.empty()) ThrowInputError(at, "a rig needs at least one head");
  if (heads.size() > kMaxRigHeads)
    ThrowInputError(
        at, std::to_string(heads.size()) + " rig heads, at most " + std::to_string(kMaxRigHeads));
  std::set<std::string> ids;
  for (const RigHead& head : heads) {
    if (head.id.empty()) ThrowInputError(at, "every rig head needs a non-empty id");
    if (!ids.insert(head.id).second) ThrowInputError(at, "duplicate head id '" + head.id + "'");
    const Camera& c = head.camera;
    if (!(c.pixel_size_mm > 0) || c.width_px <= 0 || c.height_px <= 0 || !(c.c_mm() > 0))
      ThrowInputError(at, "head " + head.id + ": pixel size, format and c must be positive");
    bool finite = head.mount_rad.allFinite() && head.lever_arm_m.allFinite() &&
                  std::isfinite(c.pixel_size_mm);
    for (double v : c.interior) finite &= std::isfinite(v);
    if (head.mount_sigma_rad) finite &= head.mount_sigma_rad->allFinite();
    if (head.lever_arm_sigma_m) finite &= head.lever_arm_sigma_m->allFinite();
    if (!finite) ThrowInputError(at, "head " + head.id + ": every value must be finite");
    for (const auto& sigma : {head.mount_sigma_rad, head.lever_arm_sigma_m})
      if (sigma && !(sigma->minCoeff() > 0))
        ThrowInputError(at, "head " + head.id + ": a-priori sigmas must be > 0");
  }
  if (HeadIndex(reference_head) < 0)
    ThrowInputError(at, "reference_head '" + reference_head + "' is not one of the heads");
  const Camera& v = virtual_camera.camera;
  if (!(v.pixel_size_mm > 0) || v.width_px <= 0 || v.height_px <= 0 || !(v.c_mm() > 0))
    ThrowInputError(at, "virtual camera: c, pixel size and format must be positive");
  bool finite = std::isfinite(v.pixel_size_mm);
  for (double value : v.interior) finite &= std::isfinite(value);
  if (!finite) ThrowInputError(at, "virtual camera: every value must be finite");
  if (!v.subimages.empty() || !v.reference_points.empty())
    ThrowInputError(at, "virtual camera: no sub-images or reference points");
  const std::optional<double>& height_m = virtual_camera.height_m;
  if (height_m && !(*height_m > 0 && std::isfinite(*height_m)))
    ThrowInputError(at,
                    "virtual camera: height_m must be > 0 m (got " + FormatNumber(*height_m) + ")");
}

Rig RigFromCamera(const Camera& camera, const std::string& head_id) {
  AEROCAL_CHECK(camera.subimages.empty() && camera.reference_points.empty())
      << "a rig head is a plain camera (camera '" << camera.name << "' has sub-images)";
  Rig rig;
  rig.name = camera.name;
  rig.reference_head = head_id;
  RigHead head;
  head.id = head_id;
  head.camera = camera;
  rig.heads.push_back(head);
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  rig.virtual_camera.camera =
      PinholeCamera(camera.c_mm(), principal.x(), principal.y(), camera.frame());
  return rig;
}

std::optional<Camera> CameraFromSingleHeadRig(const Rig& rig) {
  if (rig.heads.size() != 1) return std::nullopt;
  const RigHead& head = rig.heads.front();
  if (!head.mount_rad.isZero(0.0) || !head.lever_arm_m.isZero(0.0)) return std::nullopt;
  Camera camera = head.camera;
  if (!rig.name.empty()) camera.name = rig.name;
  return camera;
}

}  // namespace aerocal::calib
