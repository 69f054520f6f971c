// Kalibr camchain YAML (github.com/ethz-asl/kalibr wiki "Yaml formats"): per camera `camN:` with
// camera_model (pinhole), intrinsics [fu, fv, pu, pv] (px), distortion_model radtan
// (distortion_coeffs [k1, k2, r1, r2] = OpenCV's k1, k2, p1, p2) or equidistant ([k1..k4] =
// OpenCV fisheye), resolution [W, H]; other keys (T_cam_imu, rostopic, cam_overlaps, ...) are
// kept out. Pixels as OpenCV (pixel centres at integer coordinates), so the opencv /
// opencv_fisheye models hold a Kalibr camera exactly.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/yaml_util.h"

#include <regex>
#include <sstream>

namespace aerocal::calib {

CameraFile ReadKalibrCamchain(const std::string& path, const CameraReadOptions& options) {
  const YAML::Node root = LoadYamlFile(path);
  if (!root.IsMap()) ThrowInputError({path, 1}, "a Kalibr camchain is a YAML map of camN entries");
  std::string ids, id = options.camera_id;
  for (const auto& entry : root) ids += (ids.empty() ? "" : ", ") + entry.first.Scalar();
  if (id.empty()) {
    if (root.size() != 1)
      ThrowInputError({path, 1},
                      "holds " + std::to_string(root.size()) +
                          " cameras: name one with --camera (" + ids + ")");
    id = root.begin()->first.Scalar();
  }
  const YAML::Node cam = root[id];
  if (!cam) ThrowInputError({path, 1}, "no camera '" + id + "' (cameras: " + ids + ")");
  if (!cam.IsMap()) ThrowInputError(WhereIs(cam, path), id + " must be a map");
  for (const char* key :
       {"camera_model", "intrinsics", "distortion_model", "distortion_coeffs", "resolution"})
    if (!cam[key]) ThrowInputError(WhereIs(cam, path), id + " needs '" + key + "'");
  const std::string camera_model = YamlString(cam["camera_model"], path, "camera_model");
  if (camera_model != "pinhole")
    ThrowInputError(WhereIs(cam["camera_model"], path),
                    "camera_model '" + camera_model + "' is not supported (pinhole)");
  const auto list = [&](const char* key, size_t n) {
    const YAML::Node node = cam[key];
    if (!node.IsSequence() || node.size() != n)
      ThrowInputError(WhereIs(node, path),
                      std::string(key) + " must hold " + std::to_string(n) + " values");
    std::vector<double> v;
    for (const auto& x : node) v.push_back(YamlBounded(x, path, key, -1e7, 1e7));
    return v;
  };
  const std::vector<double> k = list("intrinsics", 4);
  if (!(k[0] > 0 && k[1] > 0))
    ThrowInputError(WhereIs(cam["intrinsics"], path), "fu, fv must be > 0 px");
  const std::vector<double> size = list("resolution", 2);
  const std::string distortion = YamlString(cam["distortion_model"], path, "distortion_model");
  CameraFile file;
  file.name = id;
  file.chosen_by_camera_id = !options.camera_id.empty();
  if (distortion == "radtan") {
    const std::vector<double> d = list("distortion_coeffs", 4);
    file.camera.model = OpenCvModel::kId;
    file.camera.params = {k[0], k[1], k[2], k[3], d[0], d[1], d[2], d[3], 0, 0, 0, 0};
  } else if (distortion == "equidistant") {
    const std::vector<double> d = list("distortion_coeffs", 4);
    file.camera.model = OpenCvFisheyeModel::kId;
    file.camera.params = {k[0], k[1], k[2], k[3], d[0], d[1], d[2], d[3]};
  } else {
    ThrowInputError(WhereIs(cam["distortion_model"], path),
                    "distortion_model '" + distortion + "' is not supported (radtan, equidistant)");
  }
  if (size[0] != static_cast<int>(size[0]) || size[1] != static_cast<int>(size[1]))
    ThrowInputError(WhereIs(cam["resolution"], path), "resolution must be integers");
  internal::ResolveFormat(&file,
                          options,
                          WhereIs(cam["resolution"], path),
                          static_cast<int>(size[0]),
                          static_cast<int>(size[1]),
                          0.0);
  return file;
}

void WriteKalibrCamchain(const std::string& path, const CameraFile& file) {
  const std::vector<double>& p = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  // The camera's key survives (cam1 of a camchain); another name is written as cam0.
  const std::string key =
      std::regex_match(file.name, std::regex("cam[0-9]{1,3}")) ? file.name : "cam0";
  std::ostringstream out;
  out << key << ":\n  camera_model: pinhole\n  intrinsics: [" << n(p[0]) << ", " << n(p[1]) << ", "
      << n(p[2]) << ", " << n(p[3]) << "]\n";
  if (file.camera.model == OpenCvFisheyeModel::kId) {
    out << "  distortion_model: equidistant\n  distortion_coeffs: [" << n(p[4]) << ", " << n(p[5])
        << ", " << n(p[6]) << ", " << n(p[7]) << "]\n";
  } else {
    AEROCAL_CHECK(file.camera.model == OpenCvModel::kId) << "not opencv";
    out << "  distortion_model: radtan\n  distortion_coeffs: [" << n(p[4]) << ", " << n(p[5])
        << ", " << n(p[6]) << ", " << n(p[7]) << "]\n";
  }
  out << "  resolution: [" << file.camera.frame.width_px << ", " << file.camera.frame.height_px
      << "]\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
