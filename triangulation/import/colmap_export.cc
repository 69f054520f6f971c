#include "triangulation/import/colmap_export.h"

#include "calib/camera/convert_camera.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"

#include <Eigen/Geometry>

#include <cstdio>
#include <sstream>

namespace aerocal::triangulation {

std::vector<std::string> WriteColmapModel(const Project& project,
                                          const std::map<std::string, Eigen::Vector3d>& points_m,
                                          const std::string& folder) {
  std::vector<std::string> notes;
  std::map<std::string, int> camera_id, image_id, point_id;
  std::ostringstream cameras, images, points;
  cameras.precision(17);
  images.precision(17);
  points.precision(17);
  cameras << "# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n";
  for (const auto& [id, c] : project.cameras) {
    const int n = static_cast<int>(camera_id.size()) + 1;
    camera_id[id] = n;
    const calib::ConversionResult opencv =
        calib::ConvertCamera(c.AsModelCamera(), calib::CameraModelId::kColmapOpenCv);
    cameras << n << " " << calib::ColmapName(opencv.camera.model) << " " << c.width_px << " "
            << c.height_px;
    for (double p : opencv.camera.params) cameras << " " << p;
    cameras << "\n";
    notes.push_back("camera " + id + " -> COLMAP " + opencv.Summary());
  }
  for (const auto& [id, xyz] : points_m) point_id[id] = static_cast<int>(point_id.size()) + 1;
  std::map<std::string, std::vector<const ImageObservation*>> by_image;
  for (const auto& o : project.observations)
    if (o.subimage.empty() && point_id.count(o.point)) by_image[o.image].push_back(&o);
  // points3D tracks: (IMAGE_ID, POINT2D_IDX).
  std::map<std::string, std::vector<std::pair<int, int>>> tracks;
  images << "# IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n# POINTS2D[] as (X, Y, "
            "POINT3D_ID)\n";
  for (const auto& e : project.exposures) {
    const int n = static_cast<int>(image_id.size()) + 1;
    image_id[e.image] = n;
    const Eigen::Matrix3d camera_from_world =
        Eigen::Vector3d(1, -1, -1).asDiagonal() * calib::RotationFromOpk(e.opk_rad).transpose();
    const Eigen::Quaterniond q(camera_from_world);
    const Eigen::Vector3d t = -camera_from_world * e.center_m;
    images << n << " " << q.w() << " " << q.x() << " " << q.y() << " " << q.z() << " " << t.x()
           << " " << t.y() << " " << t.z() << " " << camera_id.at(e.camera) << " " << e.image
           << "\n";
    int k = 0;
    for (const auto* o : by_image[e.image]) {
      images << (k ? " " : "") << o->pixel.x() + 0.5 << " " << o->pixel.y() + 0.5 << " "
             << point_id.at(o->point);
      tracks[o->point].emplace_back(n, k++);
    }
    images << "\n";
  }
  points << "# POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n";
  for (const auto& [id, xyz] : points_m) {
    points << point_id.at(id) << " " << xyz.x() << " " << xyz.y() << " " << xyz.z()
           << " 128 128 128 0";
    for (const auto& [image, index] : tracks[id]) points << " " << image << " " << index;
    points << "\n";
  }
  WriteFileAtomically(folder + "/cameras.txt", cameras.str());
  WriteFileAtomically(folder + "/images.txt", images.str());
  WriteFileAtomically(folder + "/points3D.txt", points.str());
  return notes;
}

}  // namespace aerocal::triangulation
