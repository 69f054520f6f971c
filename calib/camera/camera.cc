#include "calib/camera/camera.h"

#include "calib/camera/rotation.h"

namespace aerocal::calib {

bool Camera::ProjectToPixel(const Eigen::Vector3d& opk_rad, const Eigen::Vector3d& center_m,
                            const Eigen::Vector3d& point_m, Eigen::Vector2d* pixel) const {
  double uvw[3];
  ImageSpaceFromObject(opk_rad.data(), center_m.data(), point_m.data(), uvw);
  if (!(uvw[2] < 0)) return false;  // the camera looks along -W
  const double c = interior[Model::kC];
  const Eigen::Vector2d ideal(-c * uvw[0] / uvw[2], -c * uvw[1] / uvw[2]);
  Eigen::Vector2d measured;
  // 1e-6 px in photo units, with margin: iterate to 1e-4 of that.
  if (!Model::MeasuredFromIdeal(interior.data(), ideal, &measured,
                                             1e-10 * pixel_size_mm))
    return false;
  *pixel = PixelFromPhoto(measured);
  return true;
}

int Camera::SubimageIndex(const std::string& id) const {
  for (size_t i = 0; i < subimages.size(); ++i)
    if (subimages[i].id == id) return static_cast<int>(i);
  return -1;
}

}  // namespace aerocal::calib
