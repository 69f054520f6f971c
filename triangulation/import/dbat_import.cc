#include "triangulation/import/dbat_import.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/import/text_rows.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include <tinyxml2.h>
#include <set>

namespace aerocal::triangulation {
namespace {

using internal::BoundedField;
using internal::NumberField;
using internal::ReadTextRows;
using internal::StringField;
using Model = calib::Camera::Model;
constexpr double kDegToRad = M_PI / 180.0;

// The DBAT camera XML, read with an XML parser (tinyxml2: comments, CDATA and nesting handled):
// document/cameras/camera, its DIRECT children only (a <pp> inside <std> is a sigma, not the
// principal point).
struct XmlCamera {
  std::string path;
  const tinyxml2::XMLElement* camera = nullptr;

  const tinyxml2::XMLElement* Child(const char* tag) const { return camera->FirstChildElement(tag); }
  SourceRef Where(const tinyxml2::XMLElement* e) const {
    return {path, e ? e->GetLineNum() : camera->GetLineNum()};
  }
  // Text of <tag> split on commas, trimmed; empty when the tag is absent.
  std::vector<std::string> List(const char* tag) const {
    const tinyxml2::XMLElement* e = Child(tag);
    if (!e || !e->GetText()) return {};
    return SplitCommaList(e->GetText(), {true, true});
  }
  // Numbers of <tag> within [-bound, bound]; at least min_size of them when the tag is required.
  std::vector<double> Numbers(const char* tag, size_t min_size, double bound) const {
    std::vector<double> out;
    for (const auto& s : List(tag)) {
      const auto v = ParseDouble(s);
      if (!v || !(std::abs(*v) <= bound))
        ThrowInputError(Where(Child(tag)), std::string("<") + tag + "> must hold numbers within +-" +
                                               FormatNumber(bound) + " (got '" + s + "')");
      out.push_back(*v);
    }
    if (out.size() < min_size)
      ThrowInputError(Where(Child(tag)), std::string("<") + tag + "> needs " +
                                             std::to_string(min_size) + " values");
    return out;
  }
};

std::string Stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

}  // namespace

calib::Camera ReadDbatCamera(const std::string& path) {
  const std::string text = ReadTextFile(path);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    ThrowInputError({path, doc.ErrorLineNum()},
                    std::string("invalid XML: ") + doc.ErrorName());
  const tinyxml2::XMLElement* root = doc.RootElement();
  const tinyxml2::XMLElement* cameras = root ? root->FirstChildElement("cameras") : nullptr;
  XmlCamera xml{path, cameras ? cameras->FirstChildElement("camera") : nullptr};
  if (!xml.camera)
    ThrowInputError({path, root ? root->GetLineNum() : 0},
                    "no <document><cameras><camera> element (not a DBAT camera file)");
  calib::Camera camera;
  const auto name = xml.List("name");
  camera.name = name.empty() ? Stem(path) : name.front();
  const auto image = xml.Numbers("image", 2, 1e6);
  if (!(image[0] >= 1 && image[1] >= 1) || image[0] != std::floor(image[0]) ||
      image[1] != std::floor(image[1]))
    ThrowInputError(xml.Where(xml.Child("image")),
                    "<image> must be two positive integers W,H (px), at most 1e6");
  camera.width_px = static_cast<int>(image[0]);
  camera.height_px = static_cast<int>(image[1]);
  const auto sensor = xml.List("sensor");
  if (sensor.size() < 2) ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> must be W,H or auto,H (mm)");
  const auto height_mm = ParseDouble(sensor[1]);
  if (!height_mm || !(*height_mm > 0 && *height_mm <= 1000))
    ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> height must be > 0 and <= 1000 mm");
  camera.pixel_size_mm = *height_mm / camera.height_px;  // square pixels; "auto" width
  const double w_mm = camera.width_px * camera.pixel_size_mm, h_mm = *height_mm;
  double c = xml.Child("cc") ? xml.Numbers("cc", 1, 1e4)[0] : 0.0;
  if (c == 0) c = xml.Numbers("focal", 1, 1e4)[0];
  if (!(c > 0)) ThrowInputError(xml.Where(xml.Child(xml.Child("cc") ? "cc" : "focal")), "<cc>/<focal> must be > 0 mm");
  auto pp = xml.Child("pp") ? xml.Numbers("pp", 2, 1e4) : std::vector<double>{0, 0};
  if (pp[0] == 0 && pp[1] == 0) pp = {w_mm / 2, h_mm / 2};
  camera.interior[Model::kC] = c;
  camera.interior[Model::kX0] = pp[0] - w_mm / 2;
  camera.interior[Model::kY0] = h_mm / 2 - pp[1];
  const auto k = xml.Numbers("K", 0, 1.0);
  for (size_t i = 0; i < k.size() && i < 3; ++i) camera.interior[Model::kK1 + i] = k[i];
  const auto p = xml.Numbers("P", 0, 1.0);
  for (size_t i = 0; i < p.size() && i < 2; ++i) camera.interior[Model::kP1 + i] = p[i];
  return camera;
}

Project ImportDbat(const DbatImportOptions& o) {
  if (!(o.default_sigma_px > 0)) throw ConfigError("default sigma must be > 0 px");
  Project project;
  project.path = o.marks;
  project.cameras["cam1"] = ReadDbatCamera(o.camera_xml);
  project.camera_files["cam1"] = o.camera_xml;
  project.frame.description = "DBAT object frame as given";

  // Image ids -> names (file stems).
  std::map<std::string, std::string> image_name;
  std::map<std::string, int> stem_line;
  for (const auto& row : ReadTextRows(o.images)) {
    const std::string id = StringField(row, 0, o.images, "image id");
    const std::string stem = Stem(StringField(row, 1, o.images, "path"));
    if (stem.empty()) ThrowInputError({o.images, row.line}, "image " + id + ": empty file name");
    if (!image_name.emplace(id, stem).second)
      ThrowInputError({o.images, row.line}, "image id '" + id + "' listed twice");
    const auto [it, fresh] = stem_line.emplace(stem, row.line);
    if (!fresh)
      ThrowInputError({o.images, row.line},
                      "image " + id + " has the file name '" + stem + "' of line " +
                          std::to_string(it->second) + ": two images would merge into one exposure");
  }
  if (image_name.empty()) ThrowInputError({o.images, 0}, "no images listed");
  auto name_of = [&](const std::string& id, const std::string& file, int line) {
    const auto it = image_name.find(id);
    if (it == image_name.end()) ThrowInputError({file, line}, "unknown image id '" + id + "'");
    return it->second;
  };

  // Exterior orientation starting values.
  std::map<std::string, Exposure> exposures;
  if (!o.initial_eo.empty()) {
    for (const auto& row : ReadTextRows(o.initial_eo)) {
      Exposure e;
      e.line = row.line;
      e.image = name_of(StringField(row, 0, o.initial_eo, "image id"), o.initial_eo, row.line);
      e.camera = "cam1";
      for (int k = 0; k < 3; ++k)
        e.center_m[k] = BoundedField(row, 1 + k, o.initial_eo, "X, Y, Z", -1e8, 1e8);
      for (int k = 0; k < 3; ++k)
        e.opk_rad[k] = BoundedField(row, 4 + k, o.initial_eo, "omega, phi, kappa", -360, 360) * kDegToRad;
      if (!exposures.emplace(e.image, e).second)
        ThrowInputError({o.initial_eo, row.line}, "image " + e.image + " given twice");
    }
  } else if (!o.photomodeler_export.empty()) {
    const auto rows = ReadTextRows(o.photomodeler_export, false);
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
        e.center_m[k] = BoundedField(s, 1 + k, o.photomodeler_export, "X, Y, Z", -1e8, 1e8);
      e.opk_rad = {BoundedField(s, 6, o.photomodeler_export, "omega", -360, 360) * kDegToRad,
                   BoundedField(s, 5, o.photomodeler_export, "phi", -360, 360) * kDegToRad,
                   BoundedField(s, 4, o.photomodeler_export, "kappa", -360, 360) * kDegToRad};
      if (!exposures.count(e.image)) exposures[e.image] = e;
    }
  } else {
    throw ConfigError("a DBAT import needs initial EO (initial_eo or photomodeler_export)");
  }

  // Marks.
  std::set<std::string> points;
  for (const auto& row : ReadTextRows(o.marks)) {
    ImageObservation obs;
    obs.line = row.line;
    obs.image = name_of(StringField(row, 0, o.marks, "image id"), o.marks, row.line);
    if (!exposures.count(obs.image))
      ThrowInputError({o.marks, row.line}, "image " + obs.image + " has no initial orientation");
    obs.point = StringField(row, 1, o.marks, "point id");
    if (row.fields.size() > 5)
      ThrowInputError({o.marks, row.line}, "too many fields (expected image id, point id, x, y[, sxy])");
    obs.pixel = {BoundedField(row, 2, o.marks, "x", -1e7, 1e7) - 0.5,
                 BoundedField(row, 3, o.marks, "y", -1e7, 1e7) - 0.5};
    obs.sigma_px = row.fields.size() > 4 ? NumberField(row, 4, o.marks, "sxy") : o.default_sigma_px;
    if (!(obs.sigma_px > 0 && obs.sigma_px <= 1e4))
      ThrowInputError({o.marks, row.line}, "sxy must be > 0 and <= 1e4 px");
    points.insert(obs.point);
    project.observations.push_back(obs);
  }
  for (auto& [name, e] : exposures) project.exposures.push_back(e);

  // Control points, then tie points.
  std::set<std::string> control;
  if (!o.control.empty()) {
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
      if (!(s > 0 && s <= 1e6)) ThrowInputError({o.control, row.line}, "sxyz must be > 0 and <= 1e6 m");
      if (control.count(p.id)) ThrowInputError({o.control, row.line}, "point " + p.id + " given twice");
      p.sigma_m = Eigen::Vector3d::Constant(s);
      control.insert(p.id);
      project.points.push_back(p);
    }
  }
  for (const auto& id : points)
    if (!control.count(id)) {
      GroundPoint p;
      p.id = id;
      project.points.push_back(p);
    }
  return project;
}

}  // namespace aerocal::triangulation
