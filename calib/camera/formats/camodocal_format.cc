// camodocal / VINS-Mono / VINS-Fusion camera YAML (PINHOLE model), as camodocal's
// PinholeCamera::Parameters::writeToYamlFile writes it through cv::FileStorage and as VINS-Fusion
// ships it (github.com/HKUST-Aerial-Robotics/VINS-Fusion config/euroc/cam0_pinhole.yaml):
//   %YAML:1.0 / --- / model_type: PINHOLE / camera_name / image_width / image_height /
//   distortion_parameters: {k1, k2, p1, p2} / projection_parameters: {fx, fy, cx, cy}
// OpenCV's pinhole with k1 k2 p1 p2 in OpenCV pixels: the opencv model (k3-k6 held at 0) exactly.
// Other camodocal models (KANNALA_BRANDT, MEI, SCARAMUZZA) are refused by name.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/yaml_util.h"

#include <sstream>

namespace aerocal::calib {

CameraFile ReadCamodocalCamera(const std::string& path, const CameraReadOptions& options) {
  const YAML::Node root = internal::LoadCameraYaml(path);
  if (!root.IsMap() || !root["model_type"])
    ThrowInputError({path, 1}, "a camodocal camera file is a YAML map with model_type");
  const std::string type = YamlString(root["model_type"], path, "model_type");
  if (type != "PINHOLE")
    ThrowInputError(WhereIs(root["model_type"], path),
                    "model_type '" + type + "' is not supported (PINHOLE)");
  const auto group = [&](const char* key, std::vector<const char*> names) {
    const YAML::Node g = root[key];
    if (!g || !g.IsMap()) ThrowInputError(WhereIs(root, path), std::string("missing map ") + key);
    std::vector<double> values;
    for (const char* name : names) {
      if (!g[name]) ThrowInputError(WhereIs(g, path), std::string(key) + " needs " + name);
      values.push_back(YamlBounded(g[name], path, std::string(key) + "." + name, -1e7, 1e7));
    }
    return values;
  };
  const std::vector<double> k = group("projection_parameters", {"fx", "fy", "cx", "cy"});
  const std::vector<double> d = group("distortion_parameters", {"k1", "k2", "p1", "p2"});
  if (!(k[0] > 0 && k[1] > 0))
    ThrowInputError(WhereIs(root["projection_parameters"], path), "fx, fy must be > 0 px");
  CameraFile file;
  file.name = root["camera_name"] ? YamlString(root["camera_name"], path, "camera_name") : "";
  file.camera.model = OpenCvModel::kId;
  file.camera.params = {k[0], k[1], k[2], k[3], d[0], d[1], d[2], d[3], 0, 0, 0, 0};
  const int width = YamlInt(root["image_width"], path, "image_width");
  const int height = YamlInt(root["image_height"], path, "image_height");
  internal::ResolveFormat(&file, options, WhereIs(root["image_width"], path), width, height, 0.0);
  return file;
}

void WriteCamodocalCamera(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == OpenCvModel::kId) << "not opencv";
  const std::vector<double>& p = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "%YAML:1.0\n---\nmodel_type: PINHOLE\ncamera_name: \""
      << internal::YamlQuoted(internal::OneLine(file.name))
      << "\"\nimage_width: " << file.camera.frame.width_px
      << "\nimage_height: " << file.camera.frame.height_px
      << "\ndistortion_parameters:\n   k1: " << n(p[4]) << "\n   k2: " << n(p[5])
      << "\n   p1: " << n(p[6]) << "\n   p2: " << n(p[7])
      << "\nprojection_parameters:\n   fx: " << n(p[0]) << "\n   fy: " << n(p[1])
      << "\n   cx: " << n(p[2]) << "\n   cy: " << n(p[3]) << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
