#include "calib/camera/camera_io.h"

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/yaml_util.h"

#include <set>
#include <sstream>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

// Physical bounds of the camera file's values (calib/README.md "Camera file bounds").
constexpr int kMaxFormatPx = 1000000;              // per side, virtual image or sub-image
constexpr double kMaxPixelSizeMm = 1.0;            // 1 mm pixels
constexpr double kMinPixelSizeMm = 1e-5;           // 10 nm pixels
constexpr double kMaxCMm = 10000.0;                // 10 m principal distance
constexpr double kMinPrincipalDistancePx = 100.0;  // c / pixel size (a fisheye has about 400)
constexpr double kMaxPpMm = 1e4;                   // |x0|, |y0|
constexpr double kMaxDistortion = 1e4;             // |K1..K3, P1, P2, B1, B2| (overflow-safe only)
constexpr double kMaxMappingParam = 1e7;           // |sub-image mapping parameter|
constexpr double kMaxPixelCoordinate = 1e7;        // |u|, |v|, |U|, |V| of reference points, px
constexpr double kMaxSigmaPx = 1e4;

// Bound of |value| of a registered model's parameter, from its unit (calib/README.md "Camera file
// bounds"): pixel and millimetre lengths as for our model, dimensionless and inverse-length
// coefficients as our distortion terms (overflow-safe only, not physical plausibility).
double ModelParamBound(const ParamInfo& info) {
  if (info.unit == "px") return kMaxPixelCoordinate;
  if (info.unit == "mm") return info.group == ParamGroup::kPrincipalDistance ? kMaxCMm : kMaxPpMm;
  return kMaxDistortion;
}

std::pair<int, int> ReadFormat(const YAML::Node& node, const std::string& file) {
  if (!node.IsSequence() || node.size() != 2)
    ThrowInputError(WhereIs(node, file), "format_px must be [width, height]");
  const int w = YamlInt(node[0], file, "format_px width");
  const int h = YamlInt(node[1], file, "format_px height");
  if (w <= 0 || h <= 0 || w > kMaxFormatPx || h > kMaxFormatPx)
    ThrowInputError(WhereIs(node, file),
                    "format_px must be within 1 .. " + std::to_string(kMaxFormatPx) + " (got [" +
                        std::to_string(w) + ", " + std::to_string(h) + "])");
  return {w, h};
}

SubimageMapping ReadSubimage(const YAML::Node& node, const std::string& file) {
  RejectUnknownKeys(node, {"id", "format_px", "model", "params"}, file);
  SubimageMapping s;
  if (!node["id"]) ThrowInputError(WhereIs(node, file), "sub-image needs an 'id'");
  s.id = YamlString(node["id"], file, "id");
  if (!node["format_px"])
    ThrowInputError(WhereIs(node, file), "sub-image " + s.id + " needs format_px");
  std::tie(s.width_px, s.height_px) = ReadFormat(node["format_px"], file);
  const std::string model_name =
      node["model"] ? YamlString(node["model"], file, "model") : "affine";
  const auto model = ParseMappingModel(model_name);
  if (!model)
    ThrowInputError(WhereIs(node["model"], file),
                    "unknown mapping model '" + model_name +
                        "' (expected translation, conformal, affine or projective)");
  s.model = *model;
  if (node["params"]) {
    const YAML::Node& p = node["params"];
    if (!p.IsSequence() || static_cast<int>(p.size()) != MappingParamCount(s.model))
      ThrowInputError(WhereIs(p, file),
                      "sub-image " + s.id + ": model " + model_name + " needs " +
                          std::to_string(MappingParamCount(s.model)) + " params");
    for (const auto& v : p)
      s.params.push_back(YamlBounded(v, file, "params", -kMaxMappingParam, kMaxMappingParam));
  } else {
    s.params = IdentityMappingParams(s.model);
  }
  return s;
}

ReferencePoint ReadReferencePoint(const YAML::Node& node,
                                  const std::string& file,
                                  const Camera& camera) {
  RejectUnknownKeys(node, {"id", "subimage", "u", "v", "U", "V", "sigma_px"}, file);
  ReferencePoint r;
  for (const char* key : {"id", "subimage", "u", "v", "U", "V"})
    if (!node[key])
      ThrowInputError(WhereIs(node, file), std::string("reference point needs '") + key + "'");
  r.id = YamlString(node["id"], file, "id");
  r.subimage = YamlString(node["subimage"], file, "subimage");
  if (camera.SubimageIndex(r.subimage) < 0)
    ThrowInputError(WhereIs(node["subimage"], file),
                    "reference point " + r.id + " names unknown sub-image '" + r.subimage + "'");
  r.u = YamlBounded(node["u"], file, "u", -kMaxPixelCoordinate, kMaxPixelCoordinate);
  r.v = YamlBounded(node["v"], file, "v", -kMaxPixelCoordinate, kMaxPixelCoordinate);
  r.U = YamlBounded(node["U"], file, "U", -kMaxPixelCoordinate, kMaxPixelCoordinate);
  r.V = YamlBounded(node["V"], file, "V", -kMaxPixelCoordinate, kMaxPixelCoordinate);
  if (node["sigma_px"])
    r.sigma_px = YamlBounded(node["sigma_px"], file, "sigma_px", 0, kMaxSigmaPx);
  if (!(r.sigma_px > 0))
    ThrowInputError(WhereIs(node, file),
                    "reference point " + r.id + ": sigma_px must be > 0 (got " +
                        FormatNumber(r.sigma_px) + ")");
  return r;
}

/// The file's camera model (default the 10-parameter one), refused where the command needs that.
CameraModelId ReadCameraModel(const YAML::Node& root,
                              const std::string& file,
                              CameraModels models) {
  const std::string model_name =
      root["model"] ? YamlString(root["model"], file, "model") : std::string(Model::kName);
  const std::optional<CameraModelId> id = CameraModelFromName(model_name);
  if (!id)
    ThrowInputError(
        WhereIs(root["model"], file),
        "unknown camera model '" + model_name + "' (expected one of " + CameraModelNames() + ")");
  if (*id != Model::kId && models == CameraModels::kBrownFraser10Only)
    ThrowInputError(WhereIs(root["model"], file),
                    "camera model '" + model_name + "': this command needs " +
                        std::string(Model::kName) +
                        " (convert it first: aerocal camera convert "
                        "--to aerocal --model " +
                        std::string(Model::kName) + ")");
  return *id;
}

/// The interior and its sigmas are keyed by the model's parameter table: a new model needs
/// nothing here. A principal distance must be > 0 and at least kMinPrincipalDistancePx pixels.
void ReadInterior(const YAML::Node& root, const std::string& file, Camera* camera) {
  const std::vector<ParamInfo> table = camera->Params();
  std::vector<std::string> keys;
  for (const ParamInfo& info : table) keys.emplace_back(info.name);
  if (!root["interior"])
    ThrowInputError({file, 1}, "missing interior (at least " + keys.front() + ")");
  const YAML::Node& interior = root["interior"];
  RejectUnknownKeys(interior, keys, file);
  for (size_t i = 0; i < table.size(); ++i) {
    if (!interior[keys[i]]) continue;
    const double bound = ModelParamBound(table[i]);
    camera->interior[i] =
        YamlBounded(interior[keys[i]], file, "interior." + keys[i], -bound, bound);
  }
  for (size_t i = 0; i < table.size(); ++i) {
    if (table[i].group != ParamGroup::kPrincipalDistance) continue;
    if (!(camera->interior[i] > 0))
      ThrowInputError(WhereIs(interior, file),
                      "interior." + keys[i] + " must be > 0 " + std::string(table[i].unit) +
                          " (got " + FormatNumber(camera->interior[i]) + ")");
    // At least kMinPrincipalDistancePx pixels: a principal distance of 1e-9 mm is no lens (every
    // ray leaves the format at once) and passed as one.
    const double c_px =
        table[i].unit == "px" ? camera->interior[i] : camera->interior[i] / camera->pixel_size_mm;
    if (table[i].unit != "1" && !(c_px >= kMinPrincipalDistancePx))
      ThrowInputError(WhereIs(interior[keys[i]] ? interior[keys[i]] : interior, file),
                      "interior." + keys[i] + " must be at least " +
                          FormatNumber(kMinPrincipalDistancePx) + " pixels (got " +
                          FormatNumber(camera->interior[i]) + " " + std::string(table[i].unit) +
                          " = " + FormatNumber(c_px) + " px)");
  }
  if (root["interior_sigma"]) {
    const YAML::Node& sig = root["interior_sigma"];
    RejectUnknownKeys(sig, keys, file);
    for (size_t i = 0; i < table.size(); ++i) {
      const std::string& key = keys[i];
      if (!sig[key]) continue;
      const double s = YamlBounded(sig[key], file, "interior_sigma." + key, 0, 1e6);
      if (!(s > 0))
        ThrowInputError(WhereIs(sig[key], file),
                        "interior_sigma." + key + " must be > 0 (got " + FormatNumber(s) + ")");
      camera->interior_sigma[i] = s;
    }
  }
}

/// The sub-images (ids unique) and the reference points that name them.
void ReadSubimagesAndReferences(const YAML::Node& root, const std::string& file, Camera* camera) {
  if (root["subimages"]) {
    if (!root["subimages"].IsSequence())
      ThrowInputError(WhereIs(root["subimages"], file), "subimages must be a list");
    std::set<std::string> ids;
    for (const auto& node : root["subimages"]) {
      camera->subimages.push_back(ReadSubimage(node, file));
      if (!ids.insert(camera->subimages.back().id).second)
        ThrowInputError(WhereIs(node, file),
                        "duplicate sub-image id '" + camera->subimages.back().id + "'");
    }
  }
  if (root["reference_points"]) {
    if (!root["reference_points"].IsSequence())
      ThrowInputError(WhereIs(root["reference_points"], file), "reference_points must be a list");
    for (const auto& node : root["reference_points"])
      camera->reference_points.push_back(ReadReferencePoint(node, file, *camera));
  }
}

}  // namespace

Camera ParseCamera(const YAML::Node& root,
                   const std::string& file,
                   CameraModels models,
                   const std::vector<std::string>& record_keys) {
  if (!root.IsMap()) ThrowInputError({file, 1}, "a camera file is a YAML map");
  std::vector<std::string> allowed = {"name",
                                      "pixel_size_mm",
                                      "pixel_size_tolerance_mm",
                                      "format_px",
                                      "interior",
                                      "interior_sigma",
                                      "subimages",
                                      "reference_points",
                                      "model"};
  allowed.insert(allowed.end(), record_keys.begin(), record_keys.end());
  RejectUnknownKeys(root, allowed, file);
  Camera camera = Camera::OfModel(ReadCameraModel(root, file, models));
  camera.name = root["name"] ? YamlString(root["name"], file, "name") : "";
  if (!root["pixel_size_mm"]) ThrowInputError({file, 1}, "missing pixel_size_mm");
  camera.pixel_size_mm =
      YamlBounded(root["pixel_size_mm"], file, "pixel_size_mm", kMinPixelSizeMm, kMaxPixelSizeMm);
  if (root["pixel_size_tolerance_mm"])
    camera.pixel_size_tolerance_mm = YamlBounded(
        root["pixel_size_tolerance_mm"], file, "pixel_size_tolerance_mm", 0, camera.pixel_size_mm);
  if (!root["format_px"]) ThrowInputError({file, 1}, "missing format_px");
  std::tie(camera.width_px, camera.height_px) = ReadFormat(root["format_px"], file);
  ReadInterior(root, file, &camera);
  ReadSubimagesAndReferences(root, file, &camera);
  return camera;
}

Camera ReadCamera(const std::string& path, CameraModels models) {
  try {
    return ParseCamera(LoadYamlFile(path), path, models);
  } catch (const InputError& e) {
    throw InputError(e.what() + ForeignCameraHint(path));  // another tool's file: say which
  }
}

std::string CameraToYaml(const Camera& camera) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << camera.name;
  out << YAML::Key << "model" << YAML::Value << std::string(CameraModelName(camera.model));
  out << YAML::Key << "pixel_size_mm" << YAML::Value << camera.pixel_size_mm;
  if (camera.pixel_size_tolerance_mm)
    out << YAML::Key << "pixel_size_tolerance_mm" << YAML::Value << *camera.pixel_size_tolerance_mm;
  out << YAML::Key << "format_px" << YAML::Value << YAML::Flow << YAML::BeginSeq << camera.width_px
      << camera.height_px << YAML::EndSeq;
  const std::vector<ParamInfo> table = camera.Params();
  out << YAML::Key << "interior" << YAML::Value << YAML::BeginMap;
  for (size_t i = 0; i < table.size(); ++i)
    out << YAML::Key << std::string(table[i].name) << YAML::Value << camera.interior[i];
  out << YAML::EndMap;
  bool any_sigma = false;
  for (const auto& s : camera.interior_sigma) any_sigma |= s.has_value();
  if (any_sigma) {
    out << YAML::Key << "interior_sigma" << YAML::Value << YAML::BeginMap;
    for (size_t i = 0; i < table.size(); ++i)
      if (camera.interior_sigma[i])
        out << YAML::Key << std::string(table[i].name) << YAML::Value << *camera.interior_sigma[i];
    out << YAML::EndMap;
  }
  if (!camera.subimages.empty()) {
    out << YAML::Key << "subimages" << YAML::Value << YAML::BeginSeq;
    for (const auto& s : camera.subimages) {
      out << YAML::BeginMap << YAML::Key << "id" << YAML::Value << s.id;
      out << YAML::Key << "format_px" << YAML::Value << YAML::Flow << YAML::BeginSeq << s.width_px
          << s.height_px << YAML::EndSeq;
      out << YAML::Key << "model" << YAML::Value << std::string(MappingModelName(s.model));
      out << YAML::Key << "params" << YAML::Value << YAML::Flow << s.params;
      out << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  if (!camera.reference_points.empty()) {
    out << YAML::Key << "reference_points" << YAML::Value << YAML::BeginSeq;
    for (const auto& r : camera.reference_points) {
      out << YAML::Flow << YAML::BeginMap << YAML::Key << "id" << YAML::Value << r.id << YAML::Key
          << "subimage" << YAML::Value << r.subimage << YAML::Key << "u" << YAML::Value << r.u
          << YAML::Key << "v" << YAML::Value << r.v << YAML::Key << "U" << YAML::Value << r.U
          << YAML::Key << "V" << YAML::Value << r.V << YAML::Key << "sigma_px" << YAML::Value
          << r.sigma_px << YAML::EndMap;
    }
    out << YAML::EndSeq;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void WriteCamera(const std::string& path, const Camera& camera) {
  WriteFileAtomically(path, CameraToYaml(camera));
}

ModelCamera ParseModelCamera(const YAML::Node& root, const std::string& file) {
  return ParseCamera(root, file, CameraModels::kAny).AsModelCamera();
}

ModelCamera ReadModelCamera(const std::string& path) {
  return ParseModelCamera(LoadYamlFile(path), path);
}

std::string ModelCameraToYaml(const ModelCamera& camera, const std::string& name) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << name;
  out << YAML::Key << "model" << YAML::Value << std::string(CameraModelName(camera.model));
  out << YAML::Key << "pixel_size_mm" << YAML::Value << camera.frame.pixel_size_mm;
  out << YAML::Key << "format_px" << YAML::Value << YAML::Flow << YAML::BeginSeq
      << camera.frame.width_px << camera.frame.height_px << YAML::EndSeq;
  out << YAML::Key << "interior" << YAML::Value << YAML::BeginMap;
  const std::vector<ParamInfo> table = CameraModelParams(camera.model);
  for (size_t i = 0; i < table.size(); ++i)
    out << YAML::Key << std::string(table[i].name) << YAML::Value << camera.params.at(i);
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace aerocal::calib
