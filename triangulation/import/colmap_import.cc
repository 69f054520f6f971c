#include "triangulation/import/colmap_import.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/import/text_rows.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

using internal::NumberField;
using internal::StringField;
using internal::TextRow;
using Model = calib::BrownFraser10Model;

struct ModelInfo {
  const char* name;
  size_t num_params;
};
constexpr ModelInfo kModels[] = {{"SIMPLE_PINHOLE", 3},
                                 {"PINHOLE", 4},
                                 {"SIMPLE_RADIAL", 4},
                                 {"RADIAL", 5},
                                 {"OPENCV", 8},
                                 {"FULL_OPENCV", 12}};

// fx, fy, cx, cy of any supported model.
Eigen::Vector4d Pinhole(const std::string& model, const std::vector<double>& p) {
  if (model == "PINHOLE" || model == "OPENCV" || model == "FULL_OPENCV")
    return {p[0], p[1], p[2], p[3]};
  return {p[0], p[0], p[1], p[2]};
}

// Forward distortion of normalized coordinates (COLMAP's models).
Eigen::Vector2d Distort(const std::string& model,
                        const std::vector<double>& p,
                        const Eigen::Vector2d& n) {
  const double u = n.x(), v = n.y(), u2 = u * u, v2 = v * v, uv = u * v, r2 = u2 + v2;
  if (model == "SIMPLE_RADIAL") return n * (1 + p[3] * r2);
  if (model == "RADIAL") return n * (1 + p[3] * r2 + p[4] * r2 * r2);
  if (model == "OPENCV" || model == "FULL_OPENCV") {
    const double k1 = p[4], k2 = p[5], p1 = p[6], p2 = p[7];
    double radial = 1 + k1 * r2 + k2 * r2 * r2;
    if (model == "FULL_OPENCV") {
      const double r6 = r2 * r2 * r2;
      radial =
          (1 + k1 * r2 + k2 * r2 * r2 + p[8] * r6) / (1 + p[9] * r2 + p[10] * r2 * r2 + p[11] * r6);
    }
    return {u * radial + 2 * p1 * uv + p2 * (r2 + 2 * u2),
            v * radial + 2 * p2 * uv + p1 * (r2 + 2 * v2)};
  }
  return n;
}

// The 10-parameter camera closest to a COLMAP camera; returns the fit RMS in pixels.
double FitCamera(const std::string& model,
                 const std::vector<double>& p,
                 int width,
                 int height,
                 double pixel_size_mm,
                 calib::Camera* camera) {
  const Eigen::Vector4d k = Pinhole(model, p);
  camera->width_px = width;
  camera->height_px = height;
  camera->pixel_size_mm = pixel_size_mm;
  camera->interior.fill(0.0);
  const double c = k[1] * pixel_size_mm;
  camera->interior[Model::kC] = c;
  camera->interior[Model::kX0] = (k[2] - 0.5 * width) * pixel_size_mm;
  camera->interior[Model::kY0] = -(k[3] - 0.5 * height) * pixel_size_mm;
  // Grid of ideal directions whose distorted images cover the format; the correction
  //   ideal - xb = dx(xb) is linear in K1, K2, K3, P1, P2, B1, B2.
  const int n = 40;
  std::vector<Eigen::Matrix<double, 2, 7>> rows;
  std::vector<Eigen::Vector2d> rhs;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const Eigen::Vector2d pixel(width * double(i) / n, height * double(j) / n);  // COLMAP px
      // Undistort by fixed-point iteration (COLMAP's own approach).
      Eigen::Vector2d undistorted((pixel.x() - k[2]) / k[0], (pixel.y() - k[3]) / k[1]);
      const Eigen::Vector2d target = undistorted;
      for (int it = 0; it < 100; ++it) undistorted += target - Distort(model, p, undistorted);
      // A distortion that folds over (k1 = -1) or explodes (k1 = 10) within the format has no
      // inverse there: no 10-parameter camera can stand for it.
      if (!undistorted.allFinite() || (Distort(model, p, undistorted) - target).norm() * k[1] > 1e-3)
        return std::numeric_limits<double>::quiet_NaN();
      const Eigen::Vector2d measured =
          Eigen::Vector2d(k[0], k[1]).cwiseProduct(Distort(model, p, undistorted)) +
          Eigen::Vector2d(k[2], k[3]);
      const Eigen::Vector2d xb((measured.x() - k[2]) * pixel_size_mm,
                               -(measured.y() - k[3]) * pixel_size_mm);
      const Eigen::Vector2d ideal(c * undistorted.x(), -c * undistorted.y());
      const double r2 = xb.squaredNorm();
      Eigen::Matrix<double, 2, 7> a;
      a << xb.x() * r2, xb.x() * r2 * r2, xb.x() * r2 * r2 * r2, r2 + 2 * xb.x() * xb.x(),
          2 * xb.x() * xb.y(), xb.x(), xb.y(), xb.y() * r2, xb.y() * r2 * r2, xb.y() * r2 * r2 * r2,
          2 * xb.x() * xb.y(), r2 + 2 * xb.y() * xb.y(), 0, 0;
      rows.push_back(a);
      rhs.push_back(ideal - xb);
    }
  Eigen::MatrixXd a(2 * rows.size(), 7);
  Eigen::VectorXd b(2 * rows.size());
  for (size_t i = 0; i < rows.size(); ++i) {
    a.block<2, 7>(2 * i, 0) = rows[i];
    b.segment<2>(2 * i) = rhs[i];
  }
  // Column scaling: the radial terms span many orders of magnitude.
  const Eigen::VectorXd scale = a.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::VectorXd x =
      scale.asDiagonal() * (a * scale.asDiagonal()).colPivHouseholderQr().solve(b);
  for (int i = 0; i < 7; ++i) camera->interior[Model::kK1 + i] = x(i);
  return std::sqrt((a * x - b).squaredNorm() / rows.size()) / pixel_size_mm;
}

}  // namespace

Eigen::Vector2d ColmapProject(const std::string& model,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& q) {
  const Eigen::Vector4d k = Pinhole(model, params);
  const Eigen::Vector2d d = Distort(model, params, q.head<2>() / q.z());
  return {k[0] * d.x() + k[2], k[1] * d.y() + k[3]};
}

ColmapImportReport ImportColmapModel(const ColmapImportOptions& o) {
  if (!(o.pixel_size_mm > 0) || !(o.sigma_px > 0))
    throw ConfigError("COLMAP import: pixel_size_mm and sigma_px must be > 0");
  ColmapImportReport report;
  Project& project = report.project;
  project.path = o.folder;
  project.frame.description = "COLMAP model frame as given";
  const std::string cameras_file = o.folder + "/cameras.txt",
                    images_file = o.folder + "/images.txt",
                    points_file = o.folder + "/points3D.txt";
  std::map<std::string, std::string> camera_model;
  for (const auto& row : internal::ReadTextRows(cameras_file, false)) {
    const std::string id = StringField(row, 0, cameras_file, "CAMERA_ID");
    const std::string model = StringField(row, 1, cameras_file, "MODEL");
    const ModelInfo* info = nullptr;
    for (const auto& m : kModels)
      if (model == m.name) info = &m;
    if (!info)
      ThrowInputError({cameras_file, row.line},
                      "camera model " + model +
                          " is not supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, "
                          "RADIAL, OPENCV, FULL_OPENCV)");
    if (row.fields.size() != 4 + info->num_params)
      ThrowInputError({cameras_file, row.line},
                      model + " needs " + std::to_string(info->num_params) + " parameters");
    if (project.cameras.count(id))
      ThrowInputError({cameras_file, row.line}, "camera " + id + " defined twice");
    const int width = internal::IntegerField(row, 2, cameras_file, "WIDTH", 1, 1000000);
    const int height = internal::IntegerField(row, 3, cameras_file, "HEIGHT", 1, 1000000);
    std::vector<double> params;
    for (size_t k = 0; k < info->num_params; ++k)
      params.push_back(internal::BoundedField(row, 4 + k, cameras_file, "PARAMS", -1e7, 1e7));
    const Eigen::Vector4d pinhole = Pinhole(model, params);
    if (!(pinhole[0] > 0 && pinhole[1] > 0))
      ThrowInputError({cameras_file, row.line}, "focal length must be > 0 px (got " +
                                                    FormatNumber(pinhole[0]) + ", " +
                                                    FormatNumber(pinhole[1]) + ")");
    if (!(pinhole[0] * o.pixel_size_mm <= 1e4 && pinhole[1] * o.pixel_size_mm <= 1e4))
      ThrowInputError({cameras_file, row.line}, "focal length beyond 10 m at this pixel size");
    calib::Camera camera;
    camera.name = "COLMAP camera " + id + " (" + model + ")";
    const double rms = FitCamera(model, params, width, height, o.pixel_size_mm, &camera);
    bool finite = std::isfinite(rms);
    for (double v : camera.interior) finite = finite && std::isfinite(v);
    if (!finite)
      ThrowInputError({cameras_file, row.line},
                      model + " distortion cannot be inverted over the " + std::to_string(width) +
                          " x " + std::to_string(height) +
                          " px image (it folds over or diverges): not a usable camera");
    project.cameras[id] = camera;
    camera_model[id] = model;
    report.notes.push_back("camera " + id + ": " + model + " -> 10-parameter model, fit RMS " +
                           FormatNumber(rms, 3) + " px");
  }
  // images.txt: per image a pose line, then a points2D line (which may be empty).
  auto image_rows = internal::ReadTextRows(images_file, false, true);
  std::set<std::string> image_names;
  while (!image_rows.empty() && image_rows.back().fields.empty()) image_rows.pop_back();
  for (size_t i = 0; i < image_rows.size(); i += 2) {
    const TextRow& row = image_rows[i];
    if (row.fields.size() != 10)
      ThrowInputError({images_file, row.line},
                      "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    Exposure e;
    e.line = row.line;
    e.image = std::filesystem::path(row.fields[9]).stem().string();
    e.camera = row.fields[8];
    if (e.image.empty()) ThrowInputError({images_file, row.line}, "empty image name");
    if (!image_names.insert(e.image).second)
      ThrowInputError({images_file, row.line},
                      "image name '" + e.image + "' given twice (two images would merge)");
    if (!project.cameras.count(e.camera))
      ThrowInputError({images_file, row.line}, "unknown camera " + e.camera);
    const Eigen::Quaterniond q(NumberField(row, 1, images_file, "QW"),
                               NumberField(row, 2, images_file, "QX"),
                               NumberField(row, 3, images_file, "QY"),
                               NumberField(row, 4, images_file, "QZ"));
    const Eigen::Vector3d t(NumberField(row, 5, images_file, "TX"),
                            NumberField(row, 6, images_file, "TY"),
                            NumberField(row, 7, images_file, "TZ"));
    // COLMAP writes unit quaternions; anything else (0,0,0,0 above all) is no rotation.
    if (!(std::abs(q.norm() - 1.0) <= 1e-3))
      ThrowInputError({images_file, row.line}, "QW QX QY QZ is not a unit quaternion (norm " +
                                                   FormatNumber(q.norm()) + ")");
    if (!(t.cwiseAbs().maxCoeff() <= 1e8))
      ThrowInputError({images_file, row.line}, "TX TY TZ beyond 1e8");
    const Eigen::Matrix3d camera_from_world = q.normalized().toRotationMatrix();
    e.center_m = -camera_from_world.transpose() * t;
    const Eigen::Matrix3d object_from_image =
        camera_from_world.transpose() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    e.opk_rad = calib::OpkFromRotation(object_from_image);
    project.exposures.push_back(e);
    if (i + 1 >= image_rows.size()) break;
    const TextRow& points = image_rows[i + 1];
    if (points.fields.size() % 3 != 0)
      ThrowInputError({images_file, points.line}, "points2D line must hold X Y POINT3D_ID triples");
    for (size_t k = 0; k < points.fields.size(); k += 3) {
      if (points.fields[k + 2] == "-1") continue;
      ImageObservation obs;
      obs.line = points.line;
      obs.image = e.image;
      obs.point = points.fields[k + 2];
      obs.pixel = {internal::BoundedField(points, k, images_file, "X", -1e7, 1e7) - 0.5,
                   internal::BoundedField(points, k + 1, images_file, "Y", -1e7, 1e7) - 0.5};
      obs.sigma_px = o.sigma_px;
      project.observations.push_back(obs);
    }
  }
  for (const auto& row : internal::ReadTextRows(points_file, false)) {
    GroundPoint p;
    p.line = row.line;
    p.id = StringField(row, 0, points_file, "POINT3D_ID");
    p.xyz_m = Eigen::Vector3d(internal::BoundedField(row, 1, points_file, "X", -1e8, 1e8),
                              internal::BoundedField(row, 2, points_file, "Y", -1e8, 1e8),
                              internal::BoundedField(row, 3, points_file, "Z", -1e8, 1e8));
    project.points.push_back(p);
  }
  return report;
}

}  // namespace aerocal::triangulation
