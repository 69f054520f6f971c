// ROS camera_info YAML, as camera_calibration_parsers writes and reads it
// (github.com/ros-perception/image_common, camera_calibration_parsers/src/parse_yml.cpp:
// writeCalibrationYml): image_width, image_height, camera_name, camera_matrix {rows: 3, cols: 3,
// data: [9]}, distortion_model, distortion_coefficients {rows: 1, cols: n, data: [n]},
// rectification_matrix, projection_matrix (the last two describe a rectified stereo pair: not a
// property of the camera, not read; written as identity and [K | 0]). Pixels as OpenCV's
// (sensor_msgs/CameraInfo: K and D are OpenCV's), so the opencv / opencv_fisheye models hold a ROS
// camera exactly: plumb_bob (k1 k2 p1 p2 k3), rational_polynomial (k1 k2 p1 p2 k3 k4 k5 k6),
// equidistant (k1-k4, OpenCV fisheye). A file without distortion_model is plumb_bob, the rule
// camera_calibration_parsers applies (and warns about): said in a note.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/yaml_util.h"

#include <sstream>

namespace aerocal::calib {
namespace {

// A {rows, cols, data} matrix of the file; InputError at its line when it is not one.
std::vector<double> RosMatrix(
    const YAML::Node& root, const char* key, const std::string& path, int rows, int cols) {
  const YAML::Node m = root[key];
  if (!m) ThrowInputError({path, 1}, std::string("missing ") + key);
  if (!m.IsMap() || !m["data"] || !m["data"].IsSequence())
    ThrowInputError(WhereIs(m, path), std::string(key) + " must be {rows, cols, data: [...]}");
  const int file_rows = YamlInt(m["rows"], path, std::string(key) + ".rows");
  const int file_cols = YamlInt(m["cols"], path, std::string(key) + ".cols");
  if ((rows > 0 && file_rows != rows) || (cols > 0 && file_cols != cols) || file_rows < 1 ||
      file_cols < 1 || file_rows * static_cast<size_t>(file_cols) != m["data"].size())
    ThrowInputError(WhereIs(m, path),
                    std::string(key) + ": rows x cols must be " +
                        (rows > 0 ? std::to_string(rows) : "n") + " x " +
                        (cols > 0 ? std::to_string(cols) : "n") + " and match the data's length");
  std::vector<double> values;
  for (const auto& v : m["data"]) values.push_back(YamlBounded(v, path, key, -1e7, 1e7));
  return values;
}

}  // namespace

CameraFile ReadRosCameraInfo(const std::string& path, const CameraReadOptions& options) {
  const YAML::Node root = internal::LoadCameraYaml(path);
  if (!root.IsMap()) ThrowInputError({path, 1}, "a ROS camera_info file is a YAML map");
  CameraFile file;
  file.name = root["camera_name"] ? YamlString(root["camera_name"], path, "camera_name") : "";
  const std::vector<double> k = RosMatrix(root, "camera_matrix", path, 3, 3);
  const SourceRef k_where = WhereIs(root["camera_matrix"], path);
  if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1)
    ThrowInputError(k_where,
                    "camera_matrix must be [fx 0 cx; 0 fy cy; 0 0 1] (skew is not "
                    "modelled)");
  if (!(k[0] > 0 && k[4] > 0)) ThrowInputError(k_where, "fx, fy must be > 0 px");
  std::string model = "plumb_bob";
  if (root["distortion_model"])
    model = YamlString(root["distortion_model"], path, "distortion_model");
  else
    file.notes.push_back("no distortion_model: plumb_bob (camera_calibration_parsers' rule)");
  const std::vector<double> d = RosMatrix(root, "distortion_coefficients", path, 0, 0);
  const SourceRef d_where = WhereIs(root["distortion_coefficients"], path);
  const size_t n = model == "plumb_bob"             ? 5
                   : model == "rational_polynomial" ? 8
                   : model == "equidistant"         ? 4
                                                    : 0;
  if (n == 0)
    ThrowInputError(WhereIs(root["distortion_model"], path),
                    "distortion_model '" + model +
                        "' is not supported (plumb_bob, rational_polynomial, equidistant)");
  if (d.size() != n)
    ThrowInputError(d_where,
                    model + " needs " + std::to_string(n) + " distortion coefficients (got " +
                        std::to_string(d.size()) + ")");
  if (model == "equidistant") {
    file.camera.model = OpenCvFisheyeModel::kId;
    file.camera.params = {k[0], k[4], k[2], k[5], d[0], d[1], d[2], d[3]};
  } else {
    using O = OpenCvModel;
    file.camera.model = O::kId;
    file.camera.params.assign(O::kNumParams, 0.0);
    std::vector<double>& p = file.camera.params;
    p[O::kFx] = k[0], p[O::kFy] = k[4], p[O::kCx] = k[2], p[O::kCy] = k[5];
    static const int kOrder[8] = {O::kK1, O::kK2, O::kP1, O::kP2, O::kK3, O::kK4, O::kK5, O::kK6};
    for (size_t i = 0; i < n; ++i) p[kOrder[i]] = d[i];
  }
  const int width = YamlInt(root["image_width"], path, "image_width");
  const int height = YamlInt(root["image_height"], path, "image_height");
  if (width < 1 || height < 1)
    ThrowInputError(WhereIs(root["image_width"], path), "image_width, image_height must be >= 1");
  internal::ResolveFormat(&file, options, WhereIs(root["image_width"], path), width, height, 0.0);
  return file;
}

void WriteRosCameraInfo(const std::string& path, const CameraFile& file) {
  const std::vector<double>& p = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::string model;
  std::vector<double> d;
  if (file.camera.model == OpenCvFisheyeModel::kId) {
    model = "equidistant";
    d = {p[4], p[5], p[6], p[7]};
  } else {
    using O = OpenCvModel;
    AEROCAL_CHECK(file.camera.model == O::kId) << "not opencv";
    const bool rational = p[O::kK4] != 0 || p[O::kK5] != 0 || p[O::kK6] != 0;
    model = rational ? "rational_polynomial" : "plumb_bob";
    d = {p[O::kK1], p[O::kK2], p[O::kP1], p[O::kP2], p[O::kK3]};
    if (rational) d.insert(d.end(), {p[O::kK4], p[O::kK5], p[O::kK6]});
  }
  // fx fy cx cy lead both models' parameters.
  const std::string fx = n(p[0]), fy = n(p[1]), cx = n(p[2]), cy = n(p[3]);
  std::ostringstream out;
  out << "image_width: " << file.camera.frame.width_px
      << "\nimage_height: " << file.camera.frame.height_px << "\ncamera_name: \""
      << internal::YamlQuoted(internal::OneLine(file.name)) << "\"\ncamera_matrix:\n  rows: 3\n"
      << "  cols: 3\n  data: [" << fx << ", 0, " << cx << ", 0, " << fy << ", " << cy
      << ", 0, 0, 1]\ndistortion_model: " << model << "\ndistortion_coefficients:\n  rows: 1\n"
      << "  cols: " << d.size() << "\n  data: [";
  for (size_t i = 0; i < d.size(); ++i) out << (i ? ", " : "") << n(d[i]);
  out << "]\nrectification_matrix:\n  rows: 3\n  cols: 3\n  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]\n"
      << "projection_matrix:\n  rows: 3\n  cols: 4\n  data: [" << fx << ", 0, " << cx << ", 0, 0, "
      << fy << ", " << cy << ", 0, 0, 0, 1, 0]\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
