#include "stitch/rig/rig_convert.h"

#include <cmath>

#include <Eigen/LU>

#include "calib/core/csv.h"
#include "calib/core/error.h"

namespace aerocal::stitch {

Eigen::Matrix3d HeadFromVirtualHomography(const RigConverter& converter, int head) {
  const calib::Rig& rig = converter.rig();
  const calib::VirtualCamera& v = rig.virtual_camera;
  const calib::Camera& camera = rig.heads[head].camera;
  using Model = calib::BrownFraser10Model;
  // Virtual pixel -> ray in the virtual camera frame: (x - x0, y - y0, -c).
  Eigen::Matrix3d virtual_ray;
  virtual_ray << v.pixel_size_mm, 0, -0.5 * (v.width_px - 1) * v.pixel_size_mm - v.x0_mm,  //
      0, -v.pixel_size_mm, 0.5 * (v.height_px - 1) * v.pixel_size_mm - v.y0_mm,            //
      0, 0, -v.c_mm;
  // Ray d (object frame) from O -> G = O + (h / n.d) d; in head space
  // u = R_k^T (G - O_k) ~ R_k^T ((O - O_k) n^T + h I) d.
  const Eigen::Vector3d n = converter.Plane().normal;
  const double h = converter.Plane().offset - n.dot(converter.VirtualCenter());
  const Eigen::Matrix3d head_space =
      converter.ObjectFromHead(head).transpose() *
      ((converter.VirtualCenter() - converter.HeadCenter(head)) * n.transpose() +
       h * Eigen::Matrix3d::Identity()) *
      converter.ObjectFromVirtual() * virtual_ray;
  // Head space u -> measured pixel: x = -c u_x / u_z + x0 -> (c u_x - x0 u_z, c u_y - y0 u_z, -u_z),
  // then col = x / p + (W - 1) / 2, row = -y / p + (H - 1) / 2.
  const double c = camera.c_mm(), p = camera.pixel_size_mm;
  Eigen::Matrix3d photo;
  photo << c, 0, -camera.interior[Model::kX0],  //
      0, c, -camera.interior[Model::kY0],       //
      0, 0, -1;
  Eigen::Matrix3d pixel;
  pixel << 1 / p, 0, 0.5 * (camera.width_px - 1),  //
      0, -1 / p, 0.5 * (camera.height_px - 1),     //
      0, 0, 1;
  return pixel * photo * head_space;
}

calib::Camera RigExposureAsSubimageCamera(const RigConverter& converter) {
  const calib::Rig& rig = converter.rig();
  calib::Camera camera;
  camera.name = rig.name;
  camera.pixel_size_mm = rig.virtual_camera.pixel_size_mm;
  camera.width_px = rig.virtual_camera.width_px;
  camera.height_px = rig.virtual_camera.height_px;
  camera.interior[calib::BrownFraser10Model::kC] = rig.virtual_camera.c_mm;
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
    const calib::RigHead& head = rig.heads[k];
    for (int i = calib::BrownFraser10Model::kK1; i < calib::BrownFraser10Model::kNumParams; ++i)
      if (head.camera.interior[i] != 0.0)
        throw InputError("head " + head.id + ": " +
                         std::string(calib::BrownFraser10Model::kParams[i].name) + " = " +
                         FormatNumber(head.camera.interior[i]) +
                         ": rig convert maps distortion-free heads (the plane homography); "
                         "correct the head's distortion first");
    Eigen::Matrix3d virtual_from_head = HeadFromVirtualHomography(converter, k).inverse();
    if (!virtual_from_head.allFinite() || std::abs(virtual_from_head(2, 2)) < 1e-300)
      throw InputError("head " + head.id + ": its image does not map onto the rectification plane");
    virtual_from_head /= virtual_from_head(2, 2);
    calib::SubimageMapping mapping;
    mapping.id = head.id;
    mapping.width_px = head.camera.width_px;
    mapping.height_px = head.camera.height_px;
    mapping.model = calib::MappingModel::kProjective;
    mapping.params = calib::ParamsFromHomography(mapping.model, virtual_from_head);
    camera.subimages.push_back(mapping);
  }
  return camera;
}

ResampleReport ConvertRigExposure(const RigConverter& converter,
                                  const std::vector<RasterSource*>& sources, RasterSink* sink,
                                  const ResampleOptions& options) {
  return ResampleVirtualImage(RigExposureAsSubimageCamera(converter), sources, sink, options);
}

}  // namespace aerocal::stitch
