#include "triangulation/import/dbat_import.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/import/text_rows.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <set>

namespace aerocal::triangulation {
namespace {

using internal::NumberField;
using internal::ReadTextRows;
using internal::StringField;
using Model = calib::Camera::Model;
constexpr double kDegToRad = M_PI / 180.0;

// Text of <tag>...</tag> split on commas; empty when the tag is absent.
std::vector<std::string> XmlList(const std::string& xml, const std::string& tag) {
  const std::regex re("<" + tag + ">([^<]*)</" + tag + ">");
  std::smatch m;
  if (!std::regex_search(xml, m, re)) return {};
  return SplitCommaList(m[1].str(), {false, true});
}

std::vector<double> XmlNumbers(const std::string& xml,
                               const std::string& tag,
                               const std::string& path,
                               size_t min_size) {
  std::vector<double> out;
  for (const auto& s : XmlList(xml, tag)) {
    const auto begin = s.find_first_not_of(" \t\n"), end = s.find_last_not_of(" \t\n");
    const auto v =
        begin == std::string::npos ? std::nullopt : ParseDouble(s.substr(begin, end - begin + 1));
    if (!v) ThrowInputError({path, 0}, "<" + tag + "> must hold numbers (got '" + s + "')");
    out.push_back(*v);
  }
  if (out.size() < min_size)
    ThrowInputError({path, 0}, "<" + tag + "> needs " + std::to_string(min_size) + " values");
  return out;
}

std::string Stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

}  // namespace

calib::Camera ReadDbatCamera(const std::string& path) {
  const std::string xml = ReadTextFile(path);
  calib::Camera camera;
  const auto name = XmlList(xml, "name");
  camera.name = name.empty() ? Stem(path) : name.front();
  const auto image = XmlNumbers(xml, "image", path, 2);
  camera.width_px = static_cast<int>(image[0]);
  camera.height_px = static_cast<int>(image[1]);
  const auto sensor = XmlList(xml, "sensor");
  if (sensor.size() < 2) ThrowInputError({path, 0}, "<sensor> must be W,H or auto,H (mm)");
  const auto height_mm = ParseDouble(sensor[1]);
  if (!height_mm || !(*height_mm > 0)) ThrowInputError({path, 0}, "<sensor> height must be > 0 mm");
  camera.pixel_size_mm = *height_mm / camera.height_px;  // square pixels; "auto" width
  const double w_mm = camera.width_px * camera.pixel_size_mm, h_mm = *height_mm;
  double c = XmlNumbers(xml, "cc", path, 1)[0];
  if (c == 0) c = XmlNumbers(xml, "focal", path, 1)[0];
  if (!(c > 0)) ThrowInputError({path, 0}, "<cc>/<focal> must be > 0 mm");
  auto pp = XmlNumbers(xml, "pp", path, 2);
  if (pp[0] == 0 && pp[1] == 0) pp = {w_mm / 2, h_mm / 2};
  camera.interior[Model::kC] = c;
  camera.interior[Model::kX0] = pp[0] - w_mm / 2;
  camera.interior[Model::kY0] = h_mm / 2 - pp[1];
  const auto k = XmlNumbers(xml, "K", path, 0);
  for (size_t i = 0; i < k.size() && i < 3; ++i) camera.interior[Model::kK1 + i] = k[i];
  const auto p = XmlNumbers(xml, "P", path, 0);
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
  for (const auto& row : ReadTextRows(o.images))
    image_name[StringField(row, 0, o.images, "image id")] =
        Stem(StringField(row, 1, o.images, "path"));
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
      for (int k = 0; k < 3; ++k) e.center_m[k] = NumberField(row, 1 + k, o.initial_eo, "X, Y, Z");
      for (int k = 0; k < 3; ++k)
        e.opk_rad[k] = NumberField(row, 4 + k, o.initial_eo, "omega, phi, kappa") * kDegToRad;
      exposures[e.image] = e;
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
        e.center_m[k] = NumberField(s, 1 + k, o.photomodeler_export, "X, Y, Z");
      e.opk_rad = {NumberField(s, 6, o.photomodeler_export, "omega") * kDegToRad,
                   NumberField(s, 5, o.photomodeler_export, "phi") * kDegToRad,
                   NumberField(s, 4, o.photomodeler_export, "kappa") * kDegToRad};
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
    obs.pixel = {NumberField(row, 2, o.marks, "x") - 0.5, NumberField(row, 3, o.marks, "y") - 0.5};
    obs.sigma_px = row.fields.size() > 4 ? NumberField(row, 4, o.marks, "sxy") : o.default_sigma_px;
    if (!(obs.sigma_px > 0)) ThrowInputError({o.marks, row.line}, "sxy must be > 0 px");
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
      p.xyz_m = Eigen::Vector3d(NumberField(row, 2, o.control, "X"),
                                NumberField(row, 3, o.control, "Y"),
                                NumberField(row, 4, o.control, "Z"));
      const double s =
          row.fields.size() > 5 ? NumberField(row, 5, o.control, "sxyz") : o.control_sigma_m;
      if (!(s > 0)) ThrowInputError({o.control, row.line}, "sxyz must be > 0 m");
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
