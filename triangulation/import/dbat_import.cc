#include "triangulation/import/dbat_import.h"

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/import/text_rows.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

namespace aerocal::triangulation {
namespace {

using internal::BoundedField;
using internal::NumberField;
using internal::ReadTextRows;
using internal::StringField;
using Model = calib::Camera::Model;
constexpr double kDegToRad = M_PI / 180.0;

std::string Stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

using ImageNames = std::map<std::string, std::string>;

// Image ids -> names (file stems), from the image list: ids and stems unique (two images with
// one stem would merge into one exposure).
ImageNames ReadImageNames(const std::string& images) {
  ImageNames image_name;
  std::map<std::string, int> stem_line;
  for (const auto& row : ReadTextRows(images)) {
    const std::string id = StringField(row, 0, images, "image id");
    const std::string stem = Stem(StringField(row, 1, images, "path"));
    if (stem.empty()) ThrowInputError({images, row.line}, "image " + id + ": empty file name");
    if (!image_name.emplace(id, stem).second)
      ThrowInputError({images, row.line}, "image id '" + id + "' listed twice");
    const auto [it, fresh] = stem_line.emplace(stem, row.line);
    if (!fresh)
      ThrowInputError({images, row.line},
                      "image " + id + " has the file name '" + stem + "' of line " +
                          std::to_string(it->second) +
                          ": two images would merge into one exposure");
  }
  if (image_name.empty()) ThrowInputError({images, 0}, "no images listed");
  return image_name;
}

// The name of the image `id` that FILE:LINE refers to (exit 2 when the list has no such id).
std::string ImageNameOf(const ImageNames& image_name,
                        const std::string& id,
                        const std::string& file,
                        int line) {
  const auto it = image_name.find(id);
  if (it == image_name.end()) ThrowInputError({file, line}, "unknown image id '" + id + "'");
  return it->second;
}

// Starting exterior orientations from DBAT's initial EO: `id X Y Z omega phi kappa` (degrees),
// one row per image.
std::map<std::string, Exposure> ReadInitialEo(const std::string& initial_eo,
                                              const ImageNames& image_name) {
  std::map<std::string, Exposure> exposures;
  for (const auto& row : ReadTextRows(initial_eo)) {
    Exposure e;
    e.line = row.line;
    e.image =
        ImageNameOf(image_name, StringField(row, 0, initial_eo, "image id"), initial_eo, row.line);
    e.camera = "cam1";
    for (int k = 0; k < 3; ++k)
      e.center_m[k] = BoundedField(row, 1 + k, initial_eo, "X, Y, Z", -1e8, 1e8);
    for (int k = 0; k < 3; ++k)
      e.opk_rad[k] =
          BoundedField(row, 4 + k, initial_eo, "omega, phi, kappa", -360, 360) * kDegToRad;
    if (!exposures.emplace(e.image, e).second)
      ThrowInputError({initial_eo, row.line}, "image " + e.image + " given twice");
  }
  return exposures;
}

// Starting exterior orientations from a PhotoModeler export: a two-field row naming a listed
// image, then its row `_ X Y Z kappa phi omega` (degrees); the first one per image is kept.
std::map<std::string, Exposure> ReadPhotoModelerEo(const std::string& export_file,
                                                   const ImageNames& image_name) {
  std::map<std::string, Exposure> exposures;
  const auto rows = ReadTextRows(export_file, false);
  std::set<std::string> stems;
  for (const auto& [id, stem] : image_name) stems.insert(stem);
  for (size_t i = 0; i + 1 < rows.size(); ++i) {
    if (rows[i].fields.size() != 2 || !stems.count(Stem(rows[i].fields[1]))) continue;
    const auto& s = rows[i + 1];
    Exposure e;
    e.line = s.line;
    e.image = Stem(rows[i].fields[1]);
    e.camera = "cam1";
    for (int k = 0; k < 3; ++k)
      e.center_m[k] = BoundedField(s, 1 + k, export_file, "X, Y, Z", -1e8, 1e8);
    e.opk_rad = {BoundedField(s, 6, export_file, "omega", -360, 360) * kDegToRad,
                 BoundedField(s, 5, export_file, "phi", -360, 360) * kDegToRad,
                 BoundedField(s, 4, export_file, "kappa", -360, 360) * kDegToRad};
    if (!exposures.count(e.image)) exposures[e.image] = e;
  }
  return exposures;
}

// The marks `image_id point_id x y [sxy]` (DBAT pixel centres at .5: shifted to ours) of
// images with a starting orientation; the ids of the points marked go to `points`.
std::vector<ImageObservation> ReadMarks(const DbatImportOptions& o,
                                        const ImageNames& image_name,
                                        const std::map<std::string, Exposure>& exposures,
                                        std::set<std::string>* points) {
  std::vector<ImageObservation> observations;
  for (const auto& row : ReadTextRows(o.marks)) {
    ImageObservation obs;
    obs.line = row.line;
    obs.image =
        ImageNameOf(image_name, StringField(row, 0, o.marks, "image id"), o.marks, row.line);
    if (!exposures.count(obs.image))
      ThrowInputError({o.marks, row.line}, "image " + obs.image + " has no initial orientation");
    obs.point = StringField(row, 1, o.marks, "point id");
    if (row.fields.size() > 5)
      ThrowInputError({o.marks, row.line},
                      "too many fields (expected image id, point id, x, y[, sxy])");
    obs.pixel = {BoundedField(row, 2, o.marks, "x", -1e7, 1e7) - 0.5,
                 BoundedField(row, 3, o.marks, "y", -1e7, 1e7) - 0.5};
    obs.sigma_px = row.fields.size() > 4 ? NumberField(row, 4, o.marks, "sxy") : o.default_sigma_px;
    if (!(obs.sigma_px > 0 && obs.sigma_px <= 1e4))
      ThrowInputError({o.marks, row.line}, "sxy must be > 0 and <= 1e4 px");
    points->insert(obs.point);
    observations.push_back(obs);
  }
  return observations;
}

// Control points `id _ X Y Z [sxyz]` (each once), appended to `project_points`; their ids are
// returned.
std::set<std::string> ReadControl(const DbatImportOptions& o,
                                  std::vector<GroundPoint>* project_points) {
  std::set<std::string> control;
  for (const auto& row : ReadTextRows(o.control)) {
    GroundPoint p;
    p.line = row.line;
    p.id = StringField(row, 0, o.control, "point id");
    p.role = PointRole::kControl;
    p.xyz_m = Eigen::Vector3d(BoundedField(row, 2, o.control, "X", -1e8, 1e8),
                              BoundedField(row, 3, o.control, "Y", -1e8, 1e8),
                              BoundedField(row, 4, o.control, "Z", -1e8, 1e8));
    const double s =
        row.fields.size() > 5 ? NumberField(row, 5, o.control, "sxyz") : o.control_sigma_m;
    if (!(s > 0 && s <= 1e6))
      ThrowInputError({o.control, row.line}, "sxyz must be > 0 and <= 1e6 m");
    if (control.count(p.id))
      ThrowInputError({o.control, row.line}, "point " + p.id + " given twice");
    p.sigma_m = Eigen::Vector3d::Constant(s);
    control.insert(p.id);
    project_points->push_back(p);
  }
  return control;
}

}  // namespace

calib::Camera ReadDbatCamera(const std::string& path) {
  const calib::CameraFile file = calib::ReadDbatCameraXml(path, {});
  calib::Camera camera;
  camera.name = file.name;
  camera.pixel_size_mm = file.camera.frame.pixel_size_mm;
  camera.width_px = file.camera.frame.width_px;
  camera.height_px = file.camera.frame.height_px;
  for (int i = 0; i < Model::kNumParams; ++i) camera.interior[i] = file.camera.params.at(i);
  return camera;
}

Project ImportDbat(const DbatImportOptions& o) {
  if (!(o.default_sigma_px > 0)) throw ConfigError("default sigma must be > 0 px");
  Project project;
  project.path = o.marks;
  project.cameras["cam1"] = ReadDbatCamera(o.camera_xml);
  project.camera_files["cam1"] = o.camera_xml;
  project.frame.description = "DBAT object frame as given";
  const ImageNames image_name = ReadImageNames(o.images);
  std::map<std::string, Exposure> exposures;
  if (!o.initial_eo.empty())
    exposures = ReadInitialEo(o.initial_eo, image_name);
  else if (!o.photomodeler_export.empty())
    exposures = ReadPhotoModelerEo(o.photomodeler_export, image_name);
  else
    throw ConfigError("a DBAT import needs initial EO (initial_eo or photomodeler_export)");
  std::set<std::string> points;
  project.observations = ReadMarks(o, image_name, exposures, &points);
  for (auto& [name, e] : exposures) project.exposures.push_back(e);
  // Control points, then tie points (every other point marked).
  std::set<std::string> control;
  if (!o.control.empty()) control = ReadControl(o, &project.points);
  for (const auto& id : points)
    if (!control.count(id)) {
      GroundPoint p;
      p.id = id;
      project.points.push_back(p);
    }
  return project;
}

}  // namespace aerocal::triangulation
