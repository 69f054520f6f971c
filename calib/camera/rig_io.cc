#include "calib/camera/rig_io.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/yaml_util.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal::calib {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

// The head keys that belong to the head's camera (read by ParseCamera) and those of the rig.
const std::vector<std::string> kHeadCameraKeys = {
    "pixel_size_mm", "format_px", "interior", "interior_sigma", "model"};
const std::vector<std::string> kHeadRigKeys = {
    "id", "mount_deg", "lever_arm_m", "mount_sigma_deg", "lever_arm_sigma_m"};

// Bounds of the rig's relative orientation (as the line camera's, calib/camera/line_camera_io.cc):
// a mount is an attitude (|angle| <= 360 deg), a lever arm a body offset (|t| <= 1000 m); sigmas of
// either are positive and below those bounds.
constexpr double kMaxAngleDeg = 360.0;
constexpr double kMaxLeverArmM = 1000.0;
constexpr double kMaxHeadTiltDeg = 80.0;  // a head's axis off the virtual camera's axis
// Relative flying height of the virtual camera: 1 m .. 100 km.
constexpr double kMinHeightM = 1.0, kMaxHeightM = 1e5;

Eigen::Vector3d ReadSigma3(const YAML::Node& node,
                           const std::string& file,
                           const std::string& what,
                           double bound) {
  const Eigen::Vector3d sigma = YamlVector3(node, file, what, 0.0, bound);
  if (!(sigma.minCoeff() > 0))
    ThrowInputError(WhereIs(node, file),
                    what + " must be > 0 (got [" + FormatNumber(sigma[0]) + ", " +
                        FormatNumber(sigma[1]) + ", " + FormatNumber(sigma[2]) + "])");
  return sigma;
}

double ReadPositive(const YAML::Node& node,
                    const std::string& file,
                    const std::string& what,
                    const std::string& unit) {
  const double value = YamlDouble(node, file, what);
  if (!(value > 0))
    ThrowInputError(WhereIs(node, file),
                    what + " must be > 0 " + unit + " (got " + FormatNumber(value) + ")");
  return value;
}

RigHead ReadHead(const YAML::Node& node, const std::string& file) {
  if (!node.IsMap()) ThrowInputError(WhereIs(node, file), "a rig head is a map");
  std::vector<std::string> allowed = kHeadRigKeys;
  allowed.insert(allowed.end(), kHeadCameraKeys.begin(), kHeadCameraKeys.end());
  RejectUnknownKeys(node, allowed, file);
  RigHead head;
  if (!node["id"]) ThrowInputError(WhereIs(node, file), "rig head needs an 'id'");
  head.id = YamlString(node["id"], file, "id");
  if (head.id.empty()) ThrowInputError(WhereIs(node["id"], file), "head id must not be empty");
  for (const char* key : {"pixel_size_mm", "format_px", "interior"})
    if (!node[key]) ThrowInputError(WhereIs(node, file), "head " + head.id + ": missing " + key);
  // The head's camera keys, read in place by the camera reader (it cites their lines). Copying them
  // into a new node merged the whole document into that node's memory (yaml-cpp), once per head:
  // reading was quadratic in the number of heads (1000 heads took about 20 s).
  head.camera = ParseCamera(node, file, CameraModels::kAny, kHeadRigKeys);
  head.camera.name = head.id;
  if (node["mount_deg"]) {
    head.mount_rad =
        YamlVector3(node["mount_deg"], file, "mount_deg", -kMaxAngleDeg, kMaxAngleDeg) * kRadPerDeg;
    // The head's viewing axis (-z of the head) in the rig frame must look down, at most
    // kMaxHeadTiltDeg off the virtual camera's axis: a head looking up or sideways sees no point
    // of the rectification plane (its ratios were NaN downstream).
    const Eigen::Vector3d axis = RotationFromOpk(head.mount_rad) * Eigen::Vector3d(0, 0, -1);
    const double tilt_deg = std::acos(std::clamp(-axis.z(), -1.0, 1.0)) / kRadPerDeg;
    if (!(tilt_deg <= kMaxHeadTiltDeg))
      ThrowInputError(WhereIs(node["mount_deg"], file),
                      "head " + head.id + ": mount_deg turns the head's axis " +
                          FormatNumber(tilt_deg, 4) + " deg off the rig's nadir (at most " +
                          FormatNumber(kMaxHeadTiltDeg) + " deg)");
  }
  if (node["lever_arm_m"])
    head.lever_arm_m =
        YamlVector3(node["lever_arm_m"], file, "lever_arm_m", -kMaxLeverArmM, kMaxLeverArmM);
  if (node["mount_sigma_deg"])
    head.mount_sigma_rad =
        ReadSigma3(node["mount_sigma_deg"], file, "mount_sigma_deg", kMaxAngleDeg) * kRadPerDeg;
  if (node["lever_arm_sigma_m"])
    head.lever_arm_sigma_m =
        ReadSigma3(node["lever_arm_sigma_m"], file, "lever_arm_sigma_m", kMaxLeverArmM);
  return head;
}

// The keys of a `virtual` section: the rig's own, then either the pinhole's (c, x0, y0) or a
// camera's in any model (model, interior), with the format keys common to both.
const std::vector<std::string> kVirtualRigKeys = {"orientation", "height_m"};
const std::vector<std::string> kVirtualPinholeKeys = {
    "c", "pixel_size_mm", "format_px", "x0", "y0"};

// The pinhole form: c (mm, > 0), pixel_size_mm, format_px, optional x0, y0 (mm).
Camera ReadVirtualPinhole(const YAML::Node& node, const std::string& file) {
  for (const char* key : {"c", "pixel_size_mm", "format_px"})
    if (!node[key]) ThrowInputError(WhereIs(node, file), std::string("virtual: missing ") + key);
  PixelFrame frame;
  const double c_mm = ReadPositive(node["c"], file, "virtual.c", "mm");
  frame.pixel_size_mm = ReadPositive(node["pixel_size_mm"], file, "virtual.pixel_size_mm", "mm");
  const YAML::Node& format = node["format_px"];
  if (!format.IsSequence() || format.size() != 2)
    ThrowInputError(WhereIs(format, file), "virtual.format_px must be [width, height]");
  frame.width_px = YamlInt(format[0], file, "virtual.format_px width");
  frame.height_px = YamlInt(format[1], file, "virtual.format_px height");
  if (frame.width_px <= 0 || frame.height_px <= 0)
    ThrowInputError(WhereIs(format, file), "virtual.format_px must be positive");
  const double x0_mm = node["x0"] ? YamlDouble(node["x0"], file, "virtual.x0") : 0.0;
  const double y0_mm = node["y0"] ? YamlDouble(node["y0"], file, "virtual.y0") : 0.0;
  return PinholeCamera(c_mm, x0_mm, y0_mm, frame);
}

// The camera form: the camera reader on the section (any model; no sigmas or sub-images).
Camera ReadVirtualModelCamera(const YAML::Node& node, const std::string& file) {
  for (const char* key : {"c", "x0", "y0"})
    if (node[key])
      ThrowInputError(WhereIs(node[key], file),
                      std::string("virtual.") + key +
                          ": give the pinhole's c, x0, y0 or a camera's interior, not both");
  for (const char* key : {"name", "interior_sigma", "subimages", "reference_points"})
    if (node[key])
      ThrowInputError(WhereIs(node[key], file),
                      std::string("virtual.") + key + ": the virtual camera has no " + key);
  return ParseCamera(node, file, CameraModels::kAny, kVirtualRigKeys);
}

VirtualCamera ReadVirtual(const YAML::Node& node, const std::string& file) {
  if (!node.IsMap()) ThrowInputError(WhereIs(node, file), "rig.virtual must be a map");
  VirtualCamera v;
  if (node["interior"] || node["model"]) {
    v.camera = ReadVirtualModelCamera(node, file);
  } else {
    std::vector<std::string> allowed = kVirtualRigKeys;
    allowed.insert(allowed.end(), kVirtualPinholeKeys.begin(), kVirtualPinholeKeys.end());
    RejectUnknownKeys(node, allowed, file);
    v.camera = ReadVirtualPinhole(node, file);
  }
  if (node["orientation"]) {
    const std::string name = YamlString(node["orientation"], file, "orientation");
    const auto orientation = ParseVirtualOrientation(name);
    if (!orientation)
      ThrowInputError(WhereIs(node["orientation"], file),
                      "virtual.orientation must be rig or level (got '" + name + "')");
    v.orientation = *orientation;
  }
  if (node["height_m"])
    v.height_m = YamlBounded(node["height_m"], file, "virtual.height_m", kMinHeightM, kMaxHeightM);
  return v;
}

// The virtual camera's keys: the pinhole form when it reads back as the same camera, else the
// camera writer's model, format and interior.
void EmitVirtualCamera(YAML::Emitter& out, const Camera& camera) {
  const Eigen::Vector2d principal = camera.PrincipalPointMm();
  const Camera pinhole = PinholeCamera(camera.c_mm(), principal.x(), principal.y(), camera.frame());
  if (pinhole.model == camera.model && pinhole.interior == camera.interior) {
    out << YAML::Key << "c" << YAML::Value << camera.c_mm();
    out << YAML::Key << "pixel_size_mm" << YAML::Value << camera.pixel_size_mm;
    out << YAML::Key << "format_px" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << camera.width_px << camera.height_px << YAML::EndSeq;
    out << YAML::Key << "x0" << YAML::Value << principal.x();
    out << YAML::Key << "y0" << YAML::Value << principal.y();
    return;
  }
  const YAML::Node keys = YAML::Load(CameraToYaml(camera));
  for (const char* key : {"model", "pixel_size_mm", "format_px", "interior"})
    out << YAML::Key << key << YAML::Value << keys[key];
}

void EmitVector3(YAML::Emitter& out, const std::string& key, const Eigen::Vector3d& v) {
  out << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v[0] << v[1] << v[2]
      << YAML::EndSeq;
}

}  // namespace

std::string_view VirtualOrientationName(VirtualOrientation orientation) {
  return orientation == VirtualOrientation::kLevel ? "level" : "rig";
}

std::optional<VirtualOrientation> ParseVirtualOrientation(std::string_view name) {
  if (name == "rig") return VirtualOrientation::kRig;
  if (name == "level") return VirtualOrientation::kLevel;
  return std::nullopt;
}

Rig ParseRig(const YAML::Node& root, const std::string& file) {
  if (!root.IsMap()) ThrowInputError({file, 1}, "a camera file is a YAML map");
  if (!root["rig"]) {
    const Camera camera = ParseCamera(root, file, CameraModels::kAny);
    if (!camera.subimages.empty() || !camera.reference_points.empty())
      ThrowInputError({file, 1}, "a camera with sub-images is not a rig head (no 'rig' section)");
    Rig rig = RigFromCamera(camera);
    rig.Validate(file);
    return rig;
  }
  RejectUnknownKeys(root, {"name", "rig"}, file);
  Rig rig;
  rig.name = root["name"] ? YamlString(root["name"], file, "name") : "";
  const YAML::Node& section = root["rig"];
  RejectUnknownKeys(section, {"reference_head", "virtual", "heads"}, file);
  const YAML::Node& heads = section["heads"];
  if (!heads || !heads.IsSequence() || heads.size() == 0)
    ThrowInputError(WhereIs(heads ? heads : section, file), "rig.heads must be a non-empty list");
  // Checked before any head is read: the rig's coverage and design work on a bit per head.
  if (heads.size() > kMaxRigHeads)
    ThrowInputError(WhereIs(heads, file),
                    "rig.heads: " + std::to_string(heads.size()) + " heads, at most " +
                        std::to_string(kMaxRigHeads));
  std::set<std::string> ids;
  for (const auto& node : heads) {
    RigHead head = ReadHead(node, file);
    if (!ids.insert(head.id).second)
      ThrowInputError(WhereIs(node["id"], file), "duplicate head id '" + head.id + "'");
    rig.heads.push_back(std::move(head));
  }
  if (section["reference_head"]) {
    rig.reference_head = YamlString(section["reference_head"], file, "reference_head");
    if (rig.HeadIndex(rig.reference_head) < 0)
      ThrowInputError(WhereIs(section["reference_head"], file),
                      "reference_head '" + rig.reference_head + "' is not one of the heads");
  } else if (rig.heads.size() == 1) {
    rig.reference_head = rig.heads.front().id;
  } else {
    ThrowInputError(WhereIs(section, file), "a rig of several heads needs reference_head");
  }
  if (section["virtual"]) {
    rig.virtual_camera = ReadVirtual(section["virtual"], file);
  } else {
    const Camera& ref = rig.heads[rig.ReferenceIndex()].camera;
    rig.virtual_camera = RigFromCamera(ref).virtual_camera;
  }
  rig.Validate(file);
  return rig;
}

Rig ReadRig(const std::string& path) { return ParseRig(LoadYamlFile(path), path); }

std::string RigToYaml(const Rig& rig) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << rig.name;
  out << YAML::Key << "rig" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "reference_head" << YAML::Value << rig.reference_head;
  const VirtualCamera& v = rig.virtual_camera;
  out << YAML::Key << "virtual" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "orientation" << YAML::Value
      << std::string(VirtualOrientationName(v.orientation));
  EmitVirtualCamera(out, v.camera);
  if (v.height_m) out << YAML::Key << "height_m" << YAML::Value << *v.height_m;
  out << YAML::EndMap;
  out << YAML::Key << "heads" << YAML::Value << YAML::BeginSeq;
  for (const RigHead& head : rig.heads) {
    out << YAML::BeginMap << YAML::Key << "id" << YAML::Value << head.id;
    // The head's camera keys as the camera writer writes them.
    const YAML::Node camera = YAML::Load(CameraToYaml(head.camera));
    for (const std::string& key : kHeadCameraKeys)
      if (camera[key]) out << YAML::Key << key << YAML::Value << camera[key];
    EmitVector3(out, "mount_deg", head.mount_rad / kRadPerDeg);
    EmitVector3(out, "lever_arm_m", head.lever_arm_m);
    if (head.mount_sigma_rad)
      EmitVector3(out, "mount_sigma_deg", *head.mount_sigma_rad / kRadPerDeg);
    if (head.lever_arm_sigma_m) EmitVector3(out, "lever_arm_sigma_m", *head.lever_arm_sigma_m);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void WriteRig(const std::string& path, const Rig& rig) {
  WriteFileAtomically(path, RigToYaml(rig));
}

}  // namespace aerocal::calib
