#include "triangulation/block/block_io.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/log.h"
#include "calib/core/string_printf.h"
#include "calib/core/yaml_util.h"
#include "triangulation/block/value_bounds.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

using namespace bounds;  // block/value_bounds.h

// An optional positive sigma column: empty is "not given", otherwise within (0, hi].
std::optional<double> Sigma(const CsvTable& t,
                            const CsvTable::Row& row,
                            const std::string& column,
                            double hi) {
  const auto value = t.OptionalNumber(row, column);
  if (value && !(*value > 0 && *value <= hi))
    ThrowInputError(
        t.Where(row),
        column + " must be > 0 and <= " + FormatNumber(hi) + " (got " + FormatNumber(*value) + ")");
  return value;
}

std::string Num(double value, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, value);
  return buffer;
}

// Object coordinates: 12 significant digits keep 0.1 mm on a UTM northing and 1e-9 deg (0.1 mm)
// on geodetic longitude/latitude; a fixed number of decimals cannot serve both.
std::string Coordinate(double value) { return FormatNumber(value, 12); }

std::string ResolvePath(const std::string& base_dir, const std::string& file) {
  if (file.empty() || std::filesystem::path(file).is_absolute()) return file;
  return (std::filesystem::path(base_dir) / file).string();
}

}  // namespace

std::vector<Exposure> ReadExposures(const std::string& path) {
  const CsvTable t = CsvTable::Read(path);
  t.RequireColumns({"image", "X", "Y", "Z", "omega", "phi", "kappa"});
  t.RejectUnknownColumns({"image",
                          "camera",
                          "X",
                          "Y",
                          "Z",
                          "omega",
                          "phi",
                          "kappa",
                          "sX",
                          "sY",
                          "sZ",
                          "somega",
                          "sphi",
                          "skappa",
                          "vX",
                          "vY",
                          "vZ",
                          "z_ref"});
  std::vector<Exposure> out;
  std::set<std::string> seen;
  for (const auto& row : t.rows()) {
    Exposure e;
    e.line = row.line;
    e.image = t.String(row, "image");
    if (e.image.empty()) ThrowInputError(t.Where(row), "image id must not be empty");
    if (!seen.insert(e.image).second)
      ThrowInputError(t.Where(row), "duplicate image '" + e.image + "'");
    e.camera = t.String(row, "camera");
    e.center_m = {t.Bounded(row, "X", -kMaxCoordinateM, kMaxCoordinateM),
                  t.Bounded(row, "Y", -kMaxCoordinateM, kMaxCoordinateM),
                  t.Bounded(row, "Z", -kMaxCoordinateM, kMaxCoordinateM)};
    e.opk_rad = {t.Bounded(row, "omega", -kMaxAngleDeg, kMaxAngleDeg) * kDegToRad,
                 t.Bounded(row, "phi", -kMaxAngleDeg, kMaxAngleDeg) * kDegToRad,
                 t.Bounded(row, "kappa", -kMaxAngleDeg, kMaxAngleDeg) * kDegToRad};
    const auto sx = Sigma(t, row, "sX", kMaxSigmaM), sy = Sigma(t, row, "sY", kMaxSigmaM),
               sz = Sigma(t, row, "sZ", kMaxSigmaM);
    if (sx || sy || sz) {
      if (!(sx && sy && sz))
        ThrowInputError(t.Where(row), "sX, sY, sZ must all be given or none (m)");
      e.center_sigma_m = Eigen::Vector3d(*sx, *sy, *sz);
    }
    const auto vx = t.OptionalNumber(row, "vX"), vy = t.OptionalNumber(row, "vY"),
               vz = t.OptionalNumber(row, "vZ");
    if (vx || vy || vz) {
      if (!(vx && vy && vz))
        ThrowInputError(t.Where(row), "vX, vY, vZ must all be given or none (m/s)");
      e.velocity_mps = Eigen::Vector3d(*vx, *vy, *vz);
      if (!(e.velocity_mps->cwiseAbs().maxCoeff() <= kMaxVelocityMps))
        ThrowInputError(t.Where(row),
                        "vX, vY, vZ must be within +-" + FormatNumber(kMaxVelocityMps) + " m/s");
    }
    if (const auto z_ref = t.OptionalBounded(row, "z_ref", -kMaxCoordinateM, kMaxCoordinateM))
      e.z_ref_m = *z_ref;
    const auto so = Sigma(t, row, "somega", kMaxSigmaDeg), sp = Sigma(t, row, "sphi", kMaxSigmaDeg),
               sk = Sigma(t, row, "skappa", kMaxSigmaDeg);
    if (so || sp || sk) {
      if (!(so && sp && sk))
        ThrowInputError(t.Where(row), "somega, sphi, skappa must all be given or none (deg)");
      e.opk_sigma_rad = Eigen::Vector3d(*so, *sp, *sk) * kDegToRad;
    }
    out.push_back(e);
  }
  return out;
}

std::vector<ImageObservation> ReadObservations(const std::string& path, double default_sigma_px) {
  const CsvTable t = CsvTable::Read(path);
  const bool sub = t.HasColumn("subimage");
  const bool head = t.HasColumn("head");
  if (sub && head)
    ThrowInputError({path, 1}, "an observations table has a subimage or a head column, not both");
  // (`group`: the test-field groups of `calibrate`, read by tools/cmd_calibrate.cc)
  if (sub) {
    t.RequireColumns({"image", "subimage", "point", "u", "v"});
    t.RejectUnknownColumns({"image", "subimage", "point", "u", "v", "sigma_px", "group"});
  } else {
    t.RequireColumns({"image", "point", "col", "row"});
    t.RejectUnknownColumns({"image", "head", "point", "col", "row", "sigma_px", "group"});
  }
  std::vector<ImageObservation> out;
  out.reserve(t.rows().size());
  for (const auto& row : t.rows()) {
    ImageObservation o;
    o.line = row.line;
    o.image = t.String(row, "image");
    o.point = t.String(row, "point");
    if (o.image.empty() || o.point.empty())
      ThrowInputError(t.Where(row), "image and point must not be empty");
    if (head) {
      o.head = t.String(row, "head");
      if (o.head.empty()) ThrowInputError(t.Where(row), "head must not be empty");
    }
    if (sub) {
      o.subimage = t.String(row, "subimage");
      if (o.subimage.empty()) ThrowInputError(t.Where(row), "subimage must not be empty");
      o.pixel = {t.Bounded(row, "u", -kMaxPixel, kMaxPixel),
                 t.Bounded(row, "v", -kMaxPixel, kMaxPixel)};
    } else {
      o.pixel = {t.Bounded(row, "col", -kMaxPixel, kMaxPixel),
                 t.Bounded(row, "row", -kMaxPixel, kMaxPixel)};
    }
    o.sigma_px = Sigma(t, row, "sigma_px", kMaxSigmaPx).value_or(default_sigma_px);
    if (!(o.sigma_px > 0 && o.sigma_px <= kMaxSigmaPx))
      ThrowInputError(t.Where(row),
                      "sigma_px must be > 0 and <= " + FormatNumber(kMaxSigmaPx) + " (got " +
                          FormatNumber(o.sigma_px) + ")");
    out.push_back(o);
  }
  return out;
}

std::vector<GroundPoint> ReadPoints(const std::string& path) {
  const CsvTable t = CsvTable::Read(path);
  t.RequireColumns({"point", "X", "Y", "Z"});
  t.RejectUnknownColumns({"point", "X", "Y", "Z", "sX", "sY", "sZ", "role"});
  std::vector<GroundPoint> out;
  std::set<std::string> seen;
  for (const auto& row : t.rows()) {
    GroundPoint p;
    p.line = row.line;
    p.id = t.String(row, "point");
    if (p.id.empty()) ThrowInputError(t.Where(row), "point id must not be empty");
    if (!seen.insert(p.id).second) ThrowInputError(t.Where(row), "duplicate point '" + p.id + "'");
    const std::string role = t.String(row, "role");
    if (role == "control")
      p.role = PointRole::kControl;
    else if (role == "check")
      p.role = PointRole::kCheck;
    else if (role == "tie" || role.empty())
      p.role = PointRole::kTie;
    else
      ThrowInputError(t.Where(row), "role must be control, check or tie (got '" + role + "')");
    const auto x = t.OptionalBounded(row, "X", -kMaxCoordinateM, kMaxCoordinateM),
               y = t.OptionalBounded(row, "Y", -kMaxCoordinateM, kMaxCoordinateM),
               z = t.OptionalBounded(row, "Z", -kMaxCoordinateM, kMaxCoordinateM);
    if (x && y && z)
      p.xyz_m = Eigen::Vector3d(*x, *y, *z);
    else if (x || y || z)
      ThrowInputError(t.Where(row), "give all of X, Y, Z or none");
    // A check point without coordinates is a check tie (rig stitch: measured, never adjusted).
    if (p.role == PointRole::kControl && !p.xyz_m)
      ThrowInputError(t.Where(row), PointRoleName(p.role) + " point '" + p.id + "' needs X, Y, Z");
    // A surveyed point's sigmas weight (control) or judge (check) its survey: they are required,
    // never a silent default (FORMATS.md: an unknown sigma is never 0 nor made up).
    const auto sx = Sigma(t, row, "sX", kMaxSigmaM), sy = Sigma(t, row, "sY", kMaxSigmaM),
               sz = Sigma(t, row, "sZ", kMaxSigmaM);
    if (p.role != PointRole::kTie && p.xyz_m) {
      if (!(sx && sy && sz))
        ThrowInputError(t.Where(row),
                        PointRoleName(p.role) + " point '" + p.id +
                            "' needs sX, sY, sZ > 0 (m): a survey sigma is required");
      p.sigma_m = Eigen::Vector3d(*sx, *sy, *sz);
    }
    out.push_back(p);
  }
  return out;
}

namespace {

// An image observation lies on its format: pixel centres 0 .. W-1, 0 .. H-1, half a pixel to the
// edge, plus a pixel of measuring tolerance. Coordinates beyond are no measurement of that
// camera; the usual cause is a list measured on a resized copy of the images.
void CheckOnFormat(const Project& project,
                   const ImageObservation& o,
                   const std::string& camera_id,
                   int width_px,
                   int height_px,
                   const std::string& what) {
  constexpr double kTolerancePx = 1.5;
  if (width_px <= 0 || height_px <= 0) return;  // a format the camera file does not give
  const double outside = std::max(
      {-o.pixel.x(), o.pixel.x() - (width_px - 1), -o.pixel.y(), o.pixel.y() - (height_px - 1)});
  if (outside <= kTolerancePx) return;
  ThrowInputError({project.observations_file, o.line},
                  StringPrintf("image %s point %s at pixel (%.2f, %.2f) lies %.1f px outside "
                               "the %d x %d px format of %s of camera '%s': measured on a "
                               "resized copy of the images? (`import odm --pixel-scale` scales "
                               "such a list)",
                               o.image.c_str(),
                               o.point.c_str(),
                               o.pixel.x(),
                               o.pixel.y(),
                               outside,
                               width_px,
                               height_px,
                               what.c_str(),
                               camera_id.c_str()));
}

}  // namespace

void ValidateProject(const Project& project) {
  std::set<std::string> images, points;
  std::map<std::string, std::string> camera_of_image;  // Project::FindExposure's first match
  for (const auto& e : project.exposures) {
    images.insert(e.image);
    camera_of_image.emplace(e.image, e.camera);
    if (!project.cameras.count(e.camera))
      ThrowInputError({project.exposures_file, e.line},
                      "image " + e.image + " uses unknown camera '" + e.camera + "'");
  }
  for (const auto& p : project.points) points.insert(p.id);
  for (const auto& o : project.observations) {
    if (!images.count(o.image))
      ThrowInputError({project.observations_file, o.line}, "unknown image '" + o.image + "'");
    const std::string& camera_id = camera_of_image.at(o.image);
    const auto rig = project.rigs.find(camera_id);
    if (!o.head.empty() && rig == project.rigs.end())
      ThrowInputError({project.observations_file, o.line},
                      "head '" + o.head + "' of image " + o.image + ": camera '" + camera_id +
                          "' is not a rig (a head observation needs a camera file with a rig "
                          "section)");
    if (rig != project.rigs.end() && o.head.empty())
      ThrowInputError({project.observations_file, o.line},
                      "image " + o.image + " is taken by rig '" + camera_id +
                          "': its observations need a head (observations.csv `head` column)");
    if (rig != project.rigs.end() && rig->second.HeadIndex(o.head) < 0)
      ThrowInputError({project.observations_file, o.line},
                      "rig '" + camera_id + "' has no head '" + o.head + "'");
    const auto& camera = project.cameras.at(camera_id);
    if (!o.subimage.empty()) {
      const int k = camera.SubimageIndex(o.subimage);
      if (k < 0)
        ThrowInputError({project.observations_file, o.line},
                        "camera of image " + o.image + " has no sub-image '" + o.subimage + "'");
      const auto& sub = camera.subimages[k];
      CheckOnFormat(project, o, camera_id, sub.width_px, sub.height_px, "sub-image " + sub.id);
    } else if (rig != project.rigs.end()) {
      const auto& head = rig->second.heads[rig->second.HeadIndex(o.head)].camera;
      CheckOnFormat(project, o, camera_id, head.width_px, head.height_px, "head " + o.head);
    } else {
      CheckOnFormat(project, o, camera_id, camera.width_px, camera.height_px, "the image");
    }
  }
}

std::vector<std::pair<std::string, std::string>> ProjectFiles(const Project& project) {
  std::vector<std::pair<std::string, std::string>> files = {{"project", project.path}};
  for (const auto& [id, file] : project.camera_files) files.push_back({"camera " + id, file});
  files.push_back({"exposures", project.exposures_file});
  files.push_back({"observations", project.observations_file});
  files.push_back({"points", project.points_file});
  if (!project.stitching_file.empty()) files.push_back({"stitching", project.stitching_file});
  return files;
}

namespace {

// The `cameras:` map (id: file): a camera file, or a rig file whose reference head is the camera.
void ReadProjectCameras(const YAML::Node& cameras,
                        const std::string& path,
                        const std::string& dir,
                        Project* project) {
  if (!cameras.IsMap()) ThrowInputError(WhereIs(cameras, path), "cameras must be a map id: file");
  if (cameras.size() == 0) ThrowInputError(WhereIs(cameras, path), "no cameras");
  for (const auto& entry : cameras) {
    const std::string id = entry.first.Scalar();
    const std::string file = ResolvePath(dir, YamlString(entry.second, path, "camera file"));
    project->camera_files[id] = file;
    try {
      const YAML::Node camera = LoadYamlFile(file);
      if (camera.IsMap() && camera["rig"]) {
        // A rig camera file: the rig, and its reference head as the camera of that id.
        const calib::Rig rig = calib::ParseRig(camera, file);
        project->cameras[id] = rig.heads[rig.ReferenceIndex()].camera;
        project->rigs[id] = rig;
      } else {
        project->cameras[id] = calib::ParseCamera(camera, file, calib::CameraModels::kAny);
      }
    } catch (const InputError& e) {
      throw InputError(e.what() + calib::ForeignCameraHint(file));  // another tool's file
    }
  }
}

// `frame: {crs: ...}`: a CRS through PROJ (triangulation/georef/crs.h), optionally per file,
// with heights.
void ReadCrsFrame(const YAML::Node& f,
                  const std::string& path,
                  const std::string& dir,
                  FrameSpec* frame) {
  RejectUnknownKeys(
      f, {"crs", "vertical", "geoid_grid", "points_crs", "exposures_crs", "origin"}, path);
  FrameSpec& s = *frame;
  s.kind = FrameSpec::Kind::kCrs;
  s.crs = YamlString(f["crs"], path, "frame: crs");
  if (f["vertical"]) s.vertical = YamlString(f["vertical"], path, "frame: vertical");
  if (f["geoid_grid"])
    s.geoid_grid = ResolvePath(dir, YamlString(f["geoid_grid"], path, "frame: geoid_grid"));
  if (f["points_crs"]) s.points_crs = YamlString(f["points_crs"], path, "frame: points_crs");
  if (f["exposures_crs"])
    s.exposures_crs = YamlString(f["exposures_crs"], path, "frame: exposures_crs");
  if (f["origin"]) {
    const YAML::Node& origin = f["origin"];
    if (!origin.IsMap() || !origin["lat"] || !origin["lon"])
      ThrowInputError(WhereIs(origin, path), "frame: origin needs {lat: DEG, lon: DEG[, h: M]}");
    RejectUnknownKeys(origin, {"lat", "lon", "h"}, path);
    s.lat_deg = YamlBounded(origin["lat"], path, "frame: origin lat", -90, 90);
    s.lon_deg = YamlBounded(origin["lon"], path, "frame: origin lon", -180, 360);
    s.h_m = origin["h"] ? YamlBounded(origin["h"], path, "frame: origin h", -1e5, 1e5) : 0.0;
    s.has_origin = true;
  }
  s.description = "crs " + s.crs;
}

// `frame: {local: {lat, lon, h}}`: the local tangent plane at that origin.
void ReadLocalFrame(const YAML::Node& local, const std::string& path, FrameSpec* frame) {
  if (!local.IsMap())
    ThrowInputError(WhereIs(local, path), "frame: local needs {lat: DEG, lon: DEG[, h: M]}");
  RejectUnknownKeys(local, {"lat", "lon", "h"}, path);
  for (const char* key : {"lat", "lon"})
    if (!local[key])
      ThrowInputError(WhereIs(local, path), std::string("frame: local needs '") + key + "' (deg)");
  frame->kind = FrameSpec::Kind::kLocal;
  frame->lat_deg = YamlBounded(local["lat"], path, "frame: local lat", -90, 90);
  frame->lon_deg = YamlBounded(local["lon"], path, "frame: local lon", -180, 360);
  frame->h_m = local["h"] ? YamlBounded(local["h"], path, "frame: local h", -1e5, 1e5) : 0.0;
  frame->description = "local tangent plane";
}

// Geodetic input without a stated origin: the local tangent plane about the block's centre
// (mean of the surveyed points, else of the exposure centres), so that no curvature is lost.
void SetGeodeticFrameOrigin(const SourceRef& where, Project* project) {
  FrameSpec& frame = project->frame;
  frame.kind = FrameSpec::Kind::kGeodeticToLocal;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& p : project->points)
    if (p.xyz_m && p.role != PointRole::kTie) {
      sum += *p.xyz_m;
      ++n;
    }
  if (n == 0)
    for (const auto& e : project->exposures) {
      sum += e.center_m;
      ++n;
    }
  if (n == 0) ThrowInputError(where, "frame: geodetic needs surveyed points or exposures");
  const Eigen::Vector3d origin = sum / n;  // X = longitude, Y = latitude (deg), Z = height (m)
  if (!(std::abs(origin.y()) <= 90 && std::abs(origin.x()) <= 540 && std::abs(origin.z()) <= 1e5))
    ThrowInputError(where,
                    "frame: geodetic, but the block's mean X, Y, Z (" + FormatNumber(origin.x()) +
                        ", " + FormatNumber(origin.y()) + ", " + FormatNumber(origin.z()) +
                        ") is no longitude/latitude/height: metre coordinates need "
                        "frame: {projected: ...}");
  frame.lon_deg = origin.x();
  frame.lat_deg = origin.y();
  frame.h_m = origin.z();
  frame.description = "local tangent plane about the block centre";
}

// The `frame:` entry (after the points and exposures: a geodetic frame is centred on them).
void ReadProjectFrame(const YAML::Node& f,
                      const std::string& path,
                      const std::string& dir,
                      Project* project) {
  const SourceRef where = WhereIs(f, path);
  project->frame.source = where.ToString();
  if (f.IsMap() && f["crs"]) {
    ReadCrsFrame(f, path, dir, &project->frame);
  } else {
    if (!f.IsMap() || f.size() != 1)
      ThrowInputError(where,
                      "frame must be one of {crs: CRS, ...}, {local: {lat, lon, h}}, "
                      "{utm: ZONE}, {projected: TEXT}, {geodetic: ...}");
    RejectUnknownKeys(f, {"local", "utm", "projected", "geodetic"}, path);
  }
  if (f["local"]) {
    ReadLocalFrame(f["local"], path, &project->frame);
  } else if (f["utm"]) {
    project->frame.kind = FrameSpec::Kind::kUtm;
    project->frame.utm_zone = YamlString(f["utm"], path, "frame: utm zone");
    project->frame.description = "UTM " + project->frame.utm_zone;
  } else if (f["projected"]) {
    project->frame.description = YamlString(f["projected"], path, "frame: projected");
  } else if (f["geodetic"]) {
    SetGeodeticFrameOrigin(where, project);
  }
}

// What was read (--verbose): a wrong file named in the project shows here first.
void LogProjectRead(const Project& project) {
  LogInfo(
      StringPrintf("read %s: %zu camera(s), %zu exposures (%s), %zu points (%s), "
                   "%zu image observations (%s), frame: %s",
                   project.path.c_str(),
                   project.cameras.size(),
                   project.exposures.size(),
                   project.exposures_file.c_str(),
                   project.points.size(),
                   project.points_file.c_str(),
                   project.observations.size(),
                   project.observations_file.c_str(),
                   project.frame.description.c_str()));
}

}  // namespace

Project ReadProject(const std::string& path_in, double default_sigma_px) {
  std::string path = path_in;
  std::error_code ec;  // the error_code form: a symbolic-link loop is then reported by the reader
  if (std::filesystem::is_directory(path, ec))
    path = (std::filesystem::path(path) / "project.yaml").string();
  const YAML::Node root = LoadYamlFile(path);
  RejectUnknownKeys(
      root,
      {"cameras", "exposures", "observations", "points", "stitching", "frame", "name", "platform"},
      path);
  const std::string dir = std::filesystem::path(path).parent_path().string();
  Project project;
  project.path = path;
  for (const char* key : {"cameras", "exposures", "observations", "points"})
    if (!root[key]) ThrowInputError({path, 0}, std::string("missing '") + key + "'");
  ReadProjectCameras(root["cameras"], path, dir, &project);
  project.exposures_file = ResolvePath(dir, YamlString(root["exposures"], path, "exposures"));
  project.observations_file =
      ResolvePath(dir, YamlString(root["observations"], path, "observations"));
  project.points_file = ResolvePath(dir, YamlString(root["points"], path, "points"));
  if (root["stitching"])
    project.stitching_file = ResolvePath(dir, YamlString(root["stitching"], path, "stitching"));
  project.exposures = ReadExposures(project.exposures_file);
  // An exposure without a camera column uses the only camera of the project.
  for (auto& e : project.exposures)
    if (e.camera.empty() && project.cameras.size() == 1) e.camera = project.cameras.begin()->first;
  project.observations = ReadObservations(project.observations_file, default_sigma_px);
  project.points = ReadPoints(project.points_file);
  if (root["frame"]) ReadProjectFrame(root["frame"], path, dir, &project);
  if (root["platform"]) project.platform = ReadPlatform(root["platform"], path);
  ValidateProject(project);
  LogProjectRead(project);
  return project;
}

PlatformSpec ReadPlatform(const YAML::Node& node, const std::string& path) {
  const SourceRef where = WhereIs(node, path);
  if (!node.IsMap())
    ThrowInputError(where, "platform must be a map (lever_arm_m, lever_arm, boresight_deg, ...)");
  RejectUnknownKeys(node,
                    {"lever_arm_m",
                     "lever_arm",
                     "lever_arm_sigma_m",
                     "boresight_deg",
                     "boresight",
                     "boresight_sigma_deg",
                     "time_offset_ms",
                     "time_offset",
                     "time_offset_sigma_ms"},
                    path);
  PlatformSpec p;
  p.source = where.ToString();
  auto vector3 = [&](const char* key, double bound) {
    const YAML::Node& v = node[key];
    if (!v.IsSequence() || v.size() != 3)
      ThrowInputError(WhereIs(v, path), std::string("platform: ") + key + " must be [x, y, z]");
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i)
      out(i) = YamlBounded(v[i], path, std::string("platform: ") + key, -bound, bound);
    return out;
  };
  auto mode = [&](const char* key, PlatformParamMode* out) {
    if (!node[key]) return;
    const std::string text = YamlString(node[key], path, std::string("platform: ") + key);
    const auto m = calib::ParseBlockMode(text);
    if (!m)
      ThrowInputError(WhereIs(node[key], path),
                      std::string("platform: ") + key + " must be fixed, free or weighted (got '" +
                          text + "')");
    *out = *m;
  };
  // A sigma is > 0: an unknown one is left out, never 0 (FORMATS.md).
  auto sigma = [&](const char* key, double bound, double scale, double* out) {
    if (!node[key]) return;
    const double value = YamlBounded(node[key], path, std::string("platform: ") + key, 0.0, bound);
    if (!(value > 0))
      ThrowInputError(
          WhereIs(node[key], path),
          std::string("platform: ") + key + " must be > 0 (got 0; leave it out when unknown)");
    *out = scale * value;
  };
  constexpr double kDegToRad = M_PI / 180.0;
  if (node["lever_arm_m"]) p.lever_arm_m = vector3("lever_arm_m", 1000.0);
  if (node["boresight_deg"]) p.boresight_rad = vector3("boresight_deg", 180.0) * kDegToRad;
  if (node["time_offset_ms"])
    p.time_offset_s =
        1e-3 * YamlBounded(node["time_offset_ms"], path, "platform: time_offset_ms", -1e4, 1e4);
  mode("lever_arm", &p.lever_arm);
  mode("boresight", &p.boresight);
  mode("time_offset", &p.time_offset);
  sigma("lever_arm_sigma_m", 1000.0, 1.0, &p.lever_arm_sigma_m);
  sigma("boresight_sigma_deg", 180.0, kDegToRad, &p.boresight_sigma_rad);
  sigma("time_offset_sigma_ms", 1e4, 1e-3, &p.time_offset_sigma_s);
  ValidatePlatform(p);
  return p;
}

void ValidatePlatform(const PlatformSpec& p) {
  const std::pair<PlatformParamMode, double> weighted[] = {{p.lever_arm, p.lever_arm_sigma_m},
                                                           {p.boresight, p.boresight_sigma_rad},
                                                           {p.time_offset, p.time_offset_sigma_s}};
  const char* names[] = {"lever_arm_sigma_m", "boresight_sigma_deg", "time_offset_sigma_ms"};
  for (int k = 0; k < 3; ++k)
    if (weighted[k].first == PlatformParamMode::kWeighted && !(weighted[k].second > 0))
      throw InputError(p.source + ": platform: weighted needs " + names[k] + " > 0");
}

void WriteExposures(const std::string& path, const std::vector<Exposure>& exposures) {
  bool gnss = false, imu = false, velocity = false, z_ref = false;
  for (const auto& e : exposures) {
    z_ref |= e.z_ref_m.has_value();
    gnss |= e.center_sigma_m.has_value();
    imu |= e.opk_sigma_rad.has_value();
    velocity |= e.velocity_mps.has_value();
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "image,camera,X,Y,Z,omega,phi,kappa";
    if (gnss) out << ",sX,sY,sZ";
    if (imu) out << ",somega,sphi,skappa";
    if (velocity) out << ",vX,vY,vZ";
    if (z_ref) out << ",z_ref";
    out << "\n";
    for (const auto& e : exposures) {
      out << e.image << "," << e.camera << "," << Coordinate(e.center_m.x()) << ","
          << Coordinate(e.center_m.y()) << "," << Coordinate(e.center_m.z()) << ","
          << Num(e.opk_rad.x() / kDegToRad, 8) << "," << Num(e.opk_rad.y() / kDegToRad, 8) << ","
          << Num(e.opk_rad.z() / kDegToRad, 8);
      if (gnss) {
        if (e.center_sigma_m)
          out << "," << Num(e.center_sigma_m->x(), 4) << "," << Num(e.center_sigma_m->y(), 4) << ","
              << Num(e.center_sigma_m->z(), 4);
        else
          out << ",,,";
      }
      if (imu) {
        if (e.opk_sigma_rad)
          out << "," << Num(e.opk_sigma_rad->x() / kDegToRad, 6) << ","
              << Num(e.opk_sigma_rad->y() / kDegToRad, 6) << ","
              << Num(e.opk_sigma_rad->z() / kDegToRad, 6);
        else
          out << ",,,";
      }
      if (velocity) {
        if (e.velocity_mps)
          out << "," << Num(e.velocity_mps->x(), 4) << "," << Num(e.velocity_mps->y(), 4) << ","
              << Num(e.velocity_mps->z(), 4);
        else
          out << ",,,";
      }
      if (z_ref) out << "," << (e.z_ref_m ? Coordinate(*e.z_ref_m) : std::string());
      out << "\n";
    }
  });
}

void WriteObservations(const std::string& path, const std::vector<ImageObservation>& observations) {
  bool sub = false, head = false;
  for (const auto& o : observations) {
    sub |= !o.subimage.empty();
    head |= !o.head.empty();
  }
  AEROCAL_CHECK(!(sub && head)) << "observations with both sub-images and rig heads";
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << (sub    ? "image,subimage,point,u,v,sigma_px\n"
            : head ? "image,head,point,col,row,sigma_px\n"
                   : "image,point,col,row,sigma_px\n");
    for (const auto& o : observations) {
      out << o.image << ",";
      if (sub) out << o.subimage << ",";
      if (head) out << o.head << ",";
      out << o.point << "," << Num(o.pixel.x(), 4) << "," << Num(o.pixel.y(), 4) << ","
          << FormatNumber(o.sigma_px, 6) << "\n";
    }
  });
}

void WritePoints(const std::string& path, const std::vector<GroundPoint>& points) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "point,X,Y,Z,sX,sY,sZ,role\n";
    for (const auto& p : points) {
      out << p.id << ",";
      if (p.xyz_m)
        out << Coordinate(p.xyz_m->x()) << "," << Coordinate(p.xyz_m->y()) << ","
            << Coordinate(p.xyz_m->z());
      else
        out << ",,";
      if (p.role == PointRole::kTie || !p.xyz_m)
        out << ",,,";
      else
        out << "," << FormatNumber(p.sigma_m.x(), 6) << "," << FormatNumber(p.sigma_m.y(), 6) << ","
            << FormatNumber(p.sigma_m.z(), 6);
      out << "," << PointRoleName(p.role) << "\n";
    }
  });
}

}  // namespace aerocal::triangulation
