#include "calib/camera/rig.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <cmath>
#include <set>

namespace aerocal::calib {

Eigen::Vector2d VirtualCamera::PhotoFromPixel(const Eigen::Vector2d& pixel) const {
  return {(pixel.x() - 0.5 * (width_px - 1)) * pixel_size_mm,
          -(pixel.y() - 0.5 * (height_px - 1)) * pixel_size_mm};
}

Eigen::Vector2d VirtualCamera::PixelFromPhoto(const Eigen::Vector2d& xy_mm) const {
  return {xy_mm.x() / pixel_size_mm + 0.5 * (width_px - 1),
          -xy_mm.y() / pixel_size_mm + 0.5 * (height_px - 1)};
}

Eigen::Vector3d VirtualCamera::RayFromPixel(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d xy = PhotoFromPixel(pixel);
  return {xy.x() - x0_mm, xy.y() - y0_mm, -c_mm};
}

bool VirtualCamera::PixelFromRay(const Eigen::Vector3d& ray, Eigen::Vector2d* pixel) const {
  if (!(ray.z() < 0)) return false;
  *pixel = PixelFromPhoto({x0_mm - c_mm * ray.x() / ray.z(), y0_mm - c_mm * ray.y() / ray.z()});
  return true;
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
  const VirtualCamera& v = virtual_camera;
  if (!(v.c_mm > 0) || !(v.pixel_size_mm > 0) || v.width_px <= 0 || v.height_px <= 0)
    ThrowInputError(at, "virtual camera: c, pixel size and format must be positive");
  if (!std::isfinite(v.x0_mm) || !std::isfinite(v.y0_mm) || !std::isfinite(v.c_mm) ||
      !std::isfinite(v.pixel_size_mm))
    ThrowInputError(at, "virtual camera: every value must be finite");
  if (v.height_m && !(*v.height_m > 0 && std::isfinite(*v.height_m)))
    ThrowInputError(
        at, "virtual camera: height_m must be > 0 m (got " + FormatNumber(*v.height_m) + ")");
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
  VirtualCamera& v = rig.virtual_camera;
  v.orientation = VirtualOrientation::kRig;
  v.c_mm = camera.c_mm();
  v.pixel_size_mm = camera.pixel_size_mm;
  v.width_px = camera.width_px;
  v.height_px = camera.height_px;
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  v.x0_mm = principal.x();
  v.y0_mm = principal.y();
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
