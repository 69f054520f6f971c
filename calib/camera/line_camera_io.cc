#include "calib/camera/line_camera_io.h"

#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/yaml_util.h"

#include <cmath>

namespace aerocal::calib {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;
// Physical bounds of the line-camera file (module README "Line camera file").
constexpr int kMaxDetectors = 1000000;
constexpr double kMinPitchMm = 1e-5, kMaxPitchMm = 1.0;
constexpr double kMaxCMm = 10000.0;
constexpr double kMaxAngleDeg = 360.0;
constexpr double kMaxLeverArmM = 1000.0;
constexpr double kMaxCorrectionMm = 1000.0;  // |dx|, |dy|, |polynomial coefficient|
constexpr int kMaxPolynomialTerms = 10;

double ReadPositive(const YAML::Node& node,
                    const std::string& file,
                    const std::string& what,
                    double lo,
                    double hi) {
  const double value = YamlDouble(node, file, what);
  if (!(value >= lo && value <= hi && value > 0))
    ThrowInputError(WhereIs(node, file),
                    what + " must be within (" + FormatNumber(lo) + ", " + FormatNumber(hi) +
                        "] (got " + node.Scalar() + ")");
  return value;
}

std::vector<double> ReadNumbers(const YAML::Node& node,
                                const std::string& file,
                                const std::string& what,
                                size_t max_size) {
  if (!node.IsSequence()) ThrowInputError(WhereIs(node, file), what + " must be a list of numbers");
  if (node.size() > max_size)
    ThrowInputError(WhereIs(node, file),
                    what + " holds at most " + std::to_string(max_size) + " values (got " +
                        std::to_string(node.size()) + ")");
  std::vector<double> values;
  values.reserve(node.size());
  for (const auto& v : node)
    values.push_back(YamlBounded(v, file, what, -kMaxCorrectionMm, kMaxCorrectionMm));
  return values;
}

// The patent's line camera frame (line along its y axis) from ours (line along x): a rotation
// by +90 deg about z, x_file = -y, y_file = x (a proper rotation: z and the focal plane stay).
Eigen::Matrix3d FileFromOurs() {
  Eigen::Matrix3d r;
  r << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  return r;
}

// Converts the camera between the file's frame (line along y) and ours: `to_ours` true at the
// reader. Mount: camera -> body, so M_ours = M_file R; a sub-camera's mount maps its frame into
// the virtual camera's, both rotated: R^T M R. Calibration: dx = dy_file, dy = -dx_file.
void ConvertLineAxis(LineCamera* camera, bool to_ours) {
  const Eigen::Matrix3d r = to_ours ? FileFromOurs() : Eigen::Matrix3d(FileFromOurs().transpose());
  camera->mount_rad = OpkFromRotation(RotationFromOpk(camera->mount_rad) * r);
  for (auto& s : camera->subcameras)
    s.mount_rad = OpkFromRotation(r.transpose() * RotationFromOpk(s.mount_rad) * r);
  const auto swap = [to_ours](std::vector<double>* x, std::vector<double>* y) {
    std::swap(*x, *y);                           // to ours: x = y_file, y = x_file ...
    for (double& v : to_ours ? *y : *x) v = -v;  // ... then y = -x_file (back: x_file = -y)
  };
  swap(&camera->dx_mm, &camera->dy_mm);
  for (auto& p : camera->calibration) swap(&p.dx, &p.dy);
}

void EmitVector3(YAML::Emitter& out, const std::string& key, const Eigen::Vector3d& v) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v[0] << v[1] << v[2]
      << YAML::EndSeq;
}

}  // namespace

bool IsLineCameraFile(const YAML::Node& root) { return root.IsMap() && root["line"]; }

namespace {

// line.subcameras: consecutive detector ranges covering line.detectors, each with its c, pitch
// and mount.
void ReadSubcameras(const YAML::Node& line, const std::string& file, LineCamera* camera) {
  if (const YAML::Node& subs = line["subcameras"]) {
    if (!subs.IsSequence() || subs.size() == 0)
      ThrowInputError(WhereIs(subs, file), "line.subcameras must be a non-empty list");
    int next = 0;
    for (const auto& node : subs) {
      if (!node.IsMap()) ThrowInputError(WhereIs(node, file), "a sub-camera is a map");
      RejectUnknownKeys(node, {"id", "detectors", "c", "pitch_mm", "mount_deg"}, file);
      for (const char* key : {"id", "detectors", "c", "pitch_mm"})
        if (!node[key])
          ThrowInputError(WhereIs(node, file), std::string("sub-camera: missing ") + key);
      LineSubcamera s;
      s.id = YamlString(node["id"], file, "id");
      if (s.id.empty())
        ThrowInputError(WhereIs(node["id"], file), "sub-camera id must not be empty");
      for (const auto& other : camera->subcameras)
        if (other.id == s.id)
          ThrowInputError(WhereIs(node["id"], file), "duplicate sub-camera id '" + s.id + "'");
      const int n = YamlInt(node["detectors"], file, "sub-camera detectors");
      if (n < 1 || n > camera->detectors - next)
        ThrowInputError(WhereIs(node["detectors"], file),
                        "sub-camera " + s.id + ": detectors must be within 1 .. " +
                            std::to_string(camera->detectors - next) +
                            " (the detectors line.detectors leaves; got " + std::to_string(n) +
                            ")");
      s.first = next;
      s.last = next + n - 1;
      next += n;
      s.c_mm = ReadPositive(node["c"], file, "sub-camera c", 0.0, kMaxCMm);
      s.pitch_mm =
          ReadPositive(node["pitch_mm"], file, "sub-camera pitch_mm", kMinPitchMm, kMaxPitchMm);
      if (node["mount_deg"])
        s.mount_rad =
            YamlVector3(
                node["mount_deg"], file, "sub-camera mount_deg", -kMaxAngleDeg, kMaxAngleDeg) *
            kRadPerDeg;
      camera->subcameras.push_back(s);
    }
    if (next != camera->detectors)
      ThrowInputError(WhereIs(subs, file),
                      "line.subcameras hold " + std::to_string(next) +
                          " detectors, line.detectors is " + std::to_string(camera->detectors));
  }
}

// line.dx_mm / line.dy_mm: a correction per detector, both tables or none, not beside
// line.calibration.
void ReadCorrectionTables(const YAML::Node& line, const std::string& file, LineCamera* camera) {
  const bool has_table = line["dx_mm"] || line["dy_mm"];
  if (has_table && line["calibration"])
    ThrowInputError(WhereIs(line["calibration"], file),
                    "give either dx_mm/dy_mm tables or calibration polynomials, not both");
  if (has_table) {
    for (const char* key : {"dx_mm", "dy_mm"}) {
      if (!line[key])
        ThrowInputError(WhereIs(line, file),
                        std::string("line: missing ") + key + " (the tables come in pairs)");
      std::vector<double> values =
          ReadNumbers(line[key], file, std::string("line.") + key, size_t(camera->detectors));
      if (int(values.size()) != camera->detectors)
        ThrowInputError(WhereIs(line[key], file),
                        std::string("line.") + key + " must hold line.detectors (" +
                            std::to_string(camera->detectors) + ") values (got " +
                            std::to_string(values.size()) + ")");
      (std::string(key) == "dx_mm" ? camera->dx_mm : camera->dy_mm) = std::move(values);
    }
  }
}

// line.calibration: polynomial ranges contiguous from detector 0 to the last, none across a
// sub-camera seam.
void ReadCalibrationRanges(const YAML::Node& line, const std::string& file, LineCamera* camera) {
  if (const YAML::Node& cal = line["calibration"]) {
    if (!cal.IsSequence() || cal.size() == 0)
      ThrowInputError(WhereIs(cal, file), "line.calibration must be a non-empty list");
    int next = 0;
    for (const auto& node : cal) {
      if (!node.IsMap()) ThrowInputError(WhereIs(node, file), "a calibration range is a map");
      RejectUnknownKeys(node, {"first", "last", "dx", "dy"}, file);
      for (const char* key : {"first", "last"})
        if (!node[key])
          ThrowInputError(WhereIs(node, file), std::string("calibration: missing ") + key);
      LinePolynomial p;
      p.first = YamlInt(node["first"], file, "first");
      p.last = YamlInt(node["last"], file, "last");
      if (p.first != next || p.last < p.first || p.last >= camera->detectors)
        ThrowInputError(
            WhereIs(node, file),
            "calibration ranges must be contiguous from detector 0 to line.detectors - 1 (got [" +
                std::to_string(p.first) + ", " + std::to_string(p.last) +
                "], expected first = " + std::to_string(next) + ")");
      next = p.last + 1;
      if (node["dx"]) p.dx = ReadNumbers(node["dx"], file, "calibration dx", kMaxPolynomialTerms);
      if (node["dy"]) p.dy = ReadNumbers(node["dy"], file, "calibration dy", kMaxPolynomialTerms);
      camera->calibration.push_back(p);
      if (!camera->subcameras.empty() &&
          camera->SubcameraOf(p.first) != camera->SubcameraOf(p.last))
        ThrowInputError(WhereIs(node, file),
                        "calibration range [" + std::to_string(p.first) + ", " +
                            std::to_string(p.last) + "] spans a sub-camera seam");
    }
    if (next != camera->detectors)
      ThrowInputError(WhereIs(cal, file),
                      "calibration ranges end at detector " + std::to_string(next - 1) +
                          ", expected " + std::to_string(camera->detectors - 1));
  }
}

// line.line_axis: the file's frame (y: the patent's, line along y) converted to ours.
void ReadLineAxis(const YAML::Node& line, const std::string& file, LineCamera* camera) {
  if (const YAML::Node& axis = line["line_axis"]) {
    const std::string value = YamlString(axis, file, "line.line_axis");
    if (value != "x" && value != "y")
      ThrowInputError(WhereIs(axis, file), "line.line_axis must be x or y (got " + value + ")");
    camera->file_line_along_y = value == "y";
    if (camera->file_line_along_y) ConvertLineAxis(camera, true);
  }
}

}  // namespace

LineCamera ParseLineCamera(const YAML::Node& root, const std::string& file) {
  if (!root.IsMap()) ThrowInputError({file, 1}, "a camera file is a YAML map");
  RejectUnknownKeys(root, {"name", "line"}, file);
  const YAML::Node& line = root["line"];
  if (!line || !line.IsMap())
    ThrowInputError(WhereIs(line ? line : root, file), "a line-camera file needs a 'line' map");
  RejectUnknownKeys(line,
                    {"detectors",
                     "pitch_mm",
                     "c",
                     "mount_deg",
                     "lever_arm_m",
                     "subcameras",
                     "dx_mm",
                     "dy_mm",
                     "calibration",
                     "line_axis"},
                    file);
  for (const char* key : {"detectors", "pitch_mm", "c"})
    if (!line[key]) ThrowInputError(WhereIs(line, file), std::string("line: missing ") + key);
  LineCamera camera;
  camera.name = root["name"] ? YamlString(root["name"], file, "name") : "";
  camera.detectors = YamlInt(line["detectors"], file, "line.detectors");
  if (camera.detectors < 1 || camera.detectors > kMaxDetectors)
    ThrowInputError(WhereIs(line["detectors"], file),
                    "line.detectors must be within 1 .. " + std::to_string(kMaxDetectors) +
                        " (got " + line["detectors"].Scalar() + ")");
  camera.pitch_mm = ReadPositive(line["pitch_mm"], file, "line.pitch_mm", kMinPitchMm, kMaxPitchMm);
  camera.c_mm = ReadPositive(line["c"], file, "line.c", 0.0, kMaxCMm);
  if (line["mount_deg"])
    camera.mount_rad =
        YamlVector3(line["mount_deg"], file, "line.mount_deg", -kMaxAngleDeg, kMaxAngleDeg) *
        kRadPerDeg;
  if (line["lever_arm_m"])
    camera.lever_arm_m =
        YamlVector3(line["lever_arm_m"], file, "line.lever_arm_m", -kMaxLeverArmM, kMaxLeverArmM);

  ReadSubcameras(line, file, &camera);

  ReadCorrectionTables(line, file, &camera);
  ReadCalibrationRanges(line, file, &camera);
  ReadLineAxis(line, file, &camera);
  camera.Validate(file);  // the design geometry (every detector looks forward)
  return camera;
}

LineCamera ReadLineCamera(const std::string& path) {
  return ParseLineCamera(LoadYamlFile(path), path);
}

std::string LineCameraToYaml(const LineCamera& ours) {
  LineCamera camera = ours;
  if (camera.file_line_along_y) ConvertLineAxis(&camera, false);
  const double deg = 180.0 / M_PI;
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << camera.name;
  out << YAML::Key << "line" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "detectors" << YAML::Value << camera.detectors;
  out << YAML::Key << "pitch_mm" << YAML::Value << camera.pitch_mm;
  out << YAML::Key << "c" << YAML::Value << camera.c_mm;
  if (camera.file_line_along_y) out << YAML::Key << "line_axis" << YAML::Value << "y";
  EmitVector3(out, "mount_deg", camera.mount_rad * deg);
  EmitVector3(out, "lever_arm_m", camera.lever_arm_m);
  if (!camera.subcameras.empty()) {
    out << YAML::Key << "subcameras" << YAML::Value << YAML::BeginSeq;
    for (const auto& s : camera.subcameras) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << s.id << YAML::Key
          << "detectors" << YAML::Value << s.Count() << YAML::Key << "c" << YAML::Value << s.c_mm
          << YAML::Key << "pitch_mm" << YAML::Value << s.pitch_mm;
      EmitVector3(out, "mount_deg", s.mount_rad * deg);
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (!camera.dx_mm.empty()) {
    out << YAML::Key << "dx_mm" << YAML::Value << YAML::Flow << camera.dx_mm;
    out << YAML::Key << "dy_mm" << YAML::Value << YAML::Flow << camera.dy_mm;
  }
  if (!camera.calibration.empty()) {
    out << YAML::Key << "calibration" << YAML::Value << YAML::BeginSeq;
    for (const auto& p : camera.calibration)
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "first" << YAML::Value << p.first
          << YAML::Key << "last" << YAML::Value << p.last << YAML::Key << "dx" << YAML::Value
          << YAML::Flow << p.dx << YAML::Key << "dy" << YAML::Value << YAML::Flow << p.dy
          << YAML::EndMap;
    out << YAML::EndSeq;
  }
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void WriteLineCamera(const std::string& path, const LineCamera& camera) {
  WriteFileAtomically(path, LineCameraToYaml(camera));
}

}  // namespace aerocal::calib
