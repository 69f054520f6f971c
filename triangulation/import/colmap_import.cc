#include "triangulation/import/colmap_import.h"

#include "calib/camera/convert_camera.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/georef/crs.h"
#include "triangulation/import/text_rows.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

using internal::NumberField;
using internal::StringField;
using internal::TextRow;

// A COLMAP camera in the registry's COLMAP model (calib/camera/models/colmap.h: OpenCV's formula,
// COLMAP's pixel origin): the camera-format reader's row conversion (camera_formats.h).
calib::ModelCamera ReadColmapCamera(const TextRow& row,
                                    const std::string& file,
                                    double pixel_size_mm) {
  return calib::ColmapCameraFromFields(row.fields, {file, row.line}, pixel_size_mm);
}

}  // namespace

Eigen::Vector2d ColmapProject(const std::string& model,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& q) {
  const auto id = calib::CameraModelFromColmapName(model);
  AEROCAL_CHECK(id && static_cast<int>(params.size()) == calib::CameraModelParamCount(*id))
      << model;
  // Any format serves: COLMAP's parameters are in pixels. COLMAP's camera frame is OpenCV's
  // (x right, y down, z forward); aerocal's ideal photo coordinates have y up.
  const calib::ModelCamera camera{*id, params, calib::PixelFrame{1.0, 2, 2}};
  const double c = camera.PrincipalDistanceMm();
  Eigen::Vector2d pixel;
  AEROCAL_CHECK(
      camera.PixelFromIdeal(Eigen::Vector2d(c * q.x() / q.z(), -c * q.y() / q.z()), &pixel));
  return pixel + Eigen::Vector2d::Constant(calib::kColmapPixelOffset);  // COLMAP's pixel origin
}

namespace {

// --crs: the model's frame as a CRS; a COLMAP model is Cartesian, so no geographic one.
void SetColmapFrame(const ColmapImportOptions& o, Project* project) {
  project->frame.description = "COLMAP model frame as given";
  if (o.crs.empty()) return;
  const CrsConverter crs(CrsOptions{o.crs, "", "", "--crs"});
  if (crs.axes() == CrsConverter::Axes::kGeographic)
    throw InputError("--crs " + o.crs +
                     ": a COLMAP model is Cartesian; give its geocentric (e.g. "
                     "EPSG:4978 after model_aligner --ref_is_gps) or projected CRS");
  project->frame.kind = FrameSpec::Kind::kCrs;
  project->frame.crs = o.crs;
  project->frame.description = "crs " + o.crs;
  project->frame.source = "--crs";
}

// A COLMAP camera (of cameras.txt row `row`) as a 10-parameter camera; `note` tells how exact
// the conversion is.
calib::Camera CameraFromColmap(const calib::ModelCamera& colmap,
                               const TextRow& row,
                               const std::string& cameras_file,
                               const std::string& id,
                               const ColmapImportOptions& o,
                               std::string* note) {
  const std::string model(calib::ColmapName(colmap.model));
  const std::string unusable = model + " distortion cannot be represented over the " +
                               std::to_string(colmap.frame.width_px) + " x " +
                               std::to_string(colmap.frame.height_px) +
                               " px image (it folds over or diverges): not a usable camera";
  calib::ConversionResult fit;
  try {
    fit = calib::ConvertCamera(colmap, calib::CameraModelId::kBrownFraser10);
  } catch (const LogicError& e) {
    ThrowInputError({cameras_file, row.line}, unusable + " (" + e.what() + ")");
  }
  bool finite = std::isfinite(fit.residual.rms_px) && std::isfinite(fit.residual.max_px);
  for (double v : fit.camera.params) finite = finite && std::isfinite(v);
  // A conversion missing by more than 10 px somewhere in the format is no usable camera (the
  // test cameras convert to 0.016 px; OPENCV k1 = -1 or 10 miss by thousands of pixels).
  if (!finite || !(fit.residual.max_px <= 10.0))
    ThrowInputError(
        {cameras_file, row.line},
        unusable + " (conversion misses by up to " + FormatNumber(fit.residual.max_px, 3) + " px)");
  calib::Camera camera;
  camera.name = "COLMAP camera " + id + " (" + model + ")";
  camera.width_px = colmap.frame.width_px;
  camera.height_px = colmap.frame.height_px;
  camera.pixel_size_mm = o.pixel_size_mm;
  std::copy(fit.camera.params.begin(), fit.camera.params.end(), camera.interior.begin());
  *note = "camera " + id + ": " + model + " -> 10-parameter model, fit RMS " +
          FormatNumber(fit.residual.rms_px, 3) + " px, max " +
          FormatNumber(fit.residual.max_px, 3) + " px" + (fit.exact ? " (exact)" : "");
  return camera;
}

void ReadColmapCameras(const std::string& cameras_file,
                       const ColmapImportOptions& o,
                       ColmapImportReport* report) {
  Project& project = report->project;
  for (const auto& row : internal::ReadTextRows(cameras_file, false)) {
    const std::string id = StringField(row, 0, cameras_file, "CAMERA_ID");
    const calib::ModelCamera colmap = ReadColmapCamera(row, cameras_file, o.pixel_size_mm);
    if (project.cameras.count(id))
      ThrowInputError({cameras_file, row.line}, "camera " + id + " defined twice");
    std::string note;
    project.cameras[id] = CameraFromColmap(colmap, row, cameras_file, id, o, &note);
    report->notes.push_back(note);
  }
}

// The pose line of an image: IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME (world -> camera).
Exposure ColmapExposure(const TextRow& row,
                        const std::string& images_file,
                        const Project& project,
                        std::set<std::string>* image_names) {
  if (row.fields.size() != 10)
    ThrowInputError({images_file, row.line},
                    "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
  Exposure e;
  e.line = row.line;
  e.image = std::filesystem::path(row.fields[9]).stem().string();
  e.camera = row.fields[8];
  if (e.image.empty()) ThrowInputError({images_file, row.line}, "empty image name");
  if (!image_names->insert(e.image).second)
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
    ThrowInputError({images_file, row.line},
                    "QW QX QY QZ is not a unit quaternion (norm " + FormatNumber(q.norm()) + ")");
  if (!(t.cwiseAbs().maxCoeff() <= 1e8))
    ThrowInputError({images_file, row.line}, "TX TY TZ beyond 1e8");
  const Eigen::Matrix3d camera_from_world = q.normalized().toRotationMatrix();
  e.center_m = -camera_from_world.transpose() * t;
  const Eigen::Matrix3d object_from_image =
      camera_from_world.transpose() * Eigen::Vector3d(1, -1, -1).asDiagonal();
  e.opk_rad = calib::OpkFromRotation(object_from_image);
  return e;
}

// The points2D line of an image: X Y POINT3D_ID triples (-1: no 3D point), COLMAP's pixel origin.
void AddColmapObservations(const TextRow& points,
                           const std::string& images_file,
                           const std::string& image,
                           double sigma_px,
                           Project* project) {
  if (points.fields.size() % 3 != 0)
    ThrowInputError({images_file, points.line}, "points2D line must hold X Y POINT3D_ID triples");
  for (size_t k = 0; k < points.fields.size(); k += 3) {
    if (points.fields[k + 2] == "-1") continue;
    ImageObservation obs;
    obs.line = points.line;
    obs.image = image;
    obs.point = points.fields[k + 2];
    obs.pixel = {internal::BoundedField(points, k, images_file, "X", -1e7, 1e7) - 0.5,
                 internal::BoundedField(points, k + 1, images_file, "Y", -1e7, 1e7) - 0.5};
    obs.sigma_px = sigma_px;
    project->observations.push_back(obs);
  }
}

// images.txt: per image a pose line, then a points2D line (which may be empty).
void ReadColmapImages(const std::string& images_file, double sigma_px, Project* project) {
  auto image_rows = internal::ReadTextRows(images_file, false, true);
  std::set<std::string> image_names;
  while (!image_rows.empty() && image_rows.back().fields.empty()) image_rows.pop_back();
  for (size_t i = 0; i < image_rows.size(); i += 2) {
    project->exposures.push_back(
        ColmapExposure(image_rows[i], images_file, *project, &image_names));
    if (i + 1 >= image_rows.size()) break;
    AddColmapObservations(
        image_rows[i + 1], images_file, project->exposures.back().image, sigma_px, project);
  }
}

void ReadColmapPoints(const std::string& points_file, Project* project) {
  for (const auto& row : internal::ReadTextRows(points_file, false)) {
    GroundPoint p;
    p.line = row.line;
    p.id = StringField(row, 0, points_file, "POINT3D_ID");
    p.xyz_m = Eigen::Vector3d(internal::BoundedField(row, 1, points_file, "X", -1e8, 1e8),
                              internal::BoundedField(row, 2, points_file, "Y", -1e8, 1e8),
                              internal::BoundedField(row, 3, points_file, "Z", -1e8, 1e8));
    project->points.push_back(p);
  }
}

}  // namespace

ColmapImportReport ImportColmapModel(const ColmapImportOptions& o) {
  if (!(o.pixel_size_mm > 0) || !(o.sigma_px > 0))
    throw ConfigError("COLMAP import: pixel_size_mm and sigma_px must be > 0");
  ColmapImportReport report;
  Project& project = report.project;
  project.path = o.folder;
  SetColmapFrame(o, &project);
  ReadColmapCameras(o.folder + "/cameras.txt", o, &report);
  ReadColmapImages(o.folder + "/images.txt", o.sigma_px, &project);
  ReadColmapPoints(o.folder + "/points3D.txt", &project);
  return report;
}

}  // namespace aerocal::triangulation
