// OpenSfM / OpenDroneMap cameras.json (and the "cameras" of a reconstruction.json): a map from
// camera id to {projection_type, width, height, ...} (opensfm.org/docs/geometry.html "Camera
// models"). Focal lengths and principal point are normalised by max(W, H); the principal point
// (c_x, c_y) is measured from the image centre; OpenSfM's normalised image coordinates are
// ((col + 0.5 - W / 2) / max(W, H), (row + 0.5 - H / 2) / max(W, H)) with (col, row) our pixel
// (features.normalized_image_coordinates), camera x right, y down, z forward. So in OpenCV pixels
//   fx = focal_x max(W, H), cx = (W - 1) / 2 + c_x max(W, H) (y alike);
// perspective (focal, k1, k2), simple_radial (focal, c_x, c_y, k1), radial (focal_x, focal_y,
// c_x, c_y, k1, k2) and brown (+ p1, p2, k3) use OpenCV's formula: the opencv model, exactly;
// fisheye (focal, k1, k2: theta_d = theta (1 + k1 theta^2 + k2 theta^4)) is opencv_fisheye.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/json_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>

namespace aerocal::calib {
namespace {

using Json = nlohmann::json;

// Line of the first `"key"` at or after `from` (the camera's own entry).
int LineOfKey(const std::string& text, const std::string& key, size_t from) {
  const size_t at = text.find("\"" + key + "\"", from);
  return LineOfOffset(text, at == std::string::npos ? from : at);
}

// The cameras map of the file: cameras.json itself, or the "cameras" of a reconstruction.json
// (an array of reconstructions or one).
const Json& CamerasOf(const Json& root, const std::string& path) {
  const Json* cameras = &root;
  if (root.is_array() && !root.empty() && root[0].is_object() && root[0].contains("cameras"))
    cameras = &root[0]["cameras"];
  else if (root.is_object() && root.contains("cameras"))
    cameras = &root["cameras"];
  if (!cameras->is_object() || cameras->empty())
    ThrowInputError({path, 1}, "no cameras (expected {id: {projection_type, width, ...}})");
  return *cameras;
}

// The id of the camera the options name (the only one when none is named).
std::string ChooseCamera(const Json& cameras,
                         const std::string& path,
                         const CameraReadOptions& options) {
  std::string ids;
  for (auto it = cameras.begin(); it != cameras.end(); ++it)
    ids += (ids.empty() ? "" : ", ") + it.key();
  std::string id = options.camera_id;
  if (id.empty()) {
    if (cameras.size() > 1)
      ThrowInputError({path, 1},
                      "holds " + std::to_string(cameras.size()) +
                          " cameras: name one with --camera (" + ids + ")");
    id = cameras.begin().key();
  }
  if (!cameras.contains(id))
    ThrowInputError({path, 1}, "no camera '" + id + "' (cameras: " + ids + ")");
  return id;
}

// One camera's entry: its keys' lines in the text and its numbers.
struct Entry {
  const std::string& path;
  const std::string& text;
  const Json& c;
  size_t from;  // offset of the camera's id in the text

  SourceRef Where(const std::string& key) const { return {path, LineOfKey(text, key, from)}; }
  double Number(const std::string& key, double fallback) const {
    if (!c.contains(key)) return fallback;
    if (!c[key].is_number()) ThrowInputError(Where(key), key + " must be a number");
    return internal::ParseNumber(FormatNumber(c[key].get<double>(), 17), Where(key), key, 1e6);
  }
  int Size(const char* key) const {
    const double v = Number(key, 0);
    if (!(v >= 1 && v <= 1e6) || v != static_cast<int>(v))
      ThrowInputError(Where(key), std::string(key) + " must be an integer within 1 .. 1e6");
    return static_cast<int>(v);
  }
};

// The projection's parameters in OpenCV pixels (fx = focal_x max(W, H), cx = (W - 1) / 2 + c_x
// max(W, H)): fisheye as opencv_fisheye, the others as opencv.
void ReadParameters(const Entry& e,
                    const std::string& type,
                    int w,
                    int h,
                    double focal_x,
                    double focal_y,
                    ModelCamera* camera) {
  const double size = std::max(w, h);
  if (type == "fisheye") {
    using F = OpenCvFisheyeModel;
    camera->model = F::kId;
    camera->params = {focal_x * size,
                      focal_y * size,
                      0.5 * (w - 1) + e.Number("c_x", 0) * size,
                      0.5 * (h - 1) + e.Number("c_y", 0) * size,
                      e.Number("k1", 0),
                      e.Number("k2", 0),
                      0.0,
                      0.0};
  } else if (type == "perspective" || type == "simple_radial" || type == "radial" ||
             type == "brown") {
    using O = OpenCvModel;
    camera->model = O::kId;
    std::vector<double>& p = camera->params;
    p.assign(O::kNumParams, 0.0);
    p[O::kFx] = focal_x * size;
    p[O::kFy] = focal_y * size;
    p[O::kCx] = 0.5 * (w - 1) + e.Number("c_x", 0) * size;
    p[O::kCy] = 0.5 * (h - 1) + e.Number("c_y", 0) * size;
    p[O::kK1] = e.Number("k1", 0);
    p[O::kK2] = e.Number("k2", 0);
    p[O::kK3] = e.Number("k3", 0);
    p[O::kP1] = e.Number("p1", 0);
    p[O::kP2] = e.Number("p2", 0);
  } else {
    ThrowInputError(e.Where("projection_type"),
                    "projection_type '" + type +
                        "' is not supported (perspective, simple_radial, radial, brown, fisheye)");
  }
}

}  // namespace

CameraFile ReadOpenSfmCameras(const std::string& path, const CameraReadOptions& options) {
  const std::string text = ReadTextFile(path);
  const Json root = ParseJsonText(text, path);
  const Json& cameras = CamerasOf(root, path);
  const std::string id = ChooseCamera(cameras, path, options);
  const Entry e{path, text, cameras[id], text.find("\"" + id + "\"")};
  if (!e.c.is_object()) ThrowInputError(e.Where(id), "camera '" + id + "' is not an object");
  if (!e.c.contains("projection_type") || !e.c["projection_type"].is_string())
    ThrowInputError(e.Where(id), "missing projection_type");
  const std::string type = e.c["projection_type"];
  if (!e.c.contains("width") || !e.c.contains("height"))
    ThrowInputError(e.Where(id), "missing width/height");
  const int w = e.Size("width"), h = e.Size("height");
  const double focal = e.Number("focal", 0);
  const double focal_x = e.Number("focal_x", focal), focal_y = e.Number("focal_y", focal_x);
  if (!(focal_x > 0 && focal_y > 0)) ThrowInputError(e.Where(id), "focal length must be > 0");
  CameraFile file;
  file.name = id;
  file.chosen_by_camera_id = !options.camera_id.empty();
  ReadParameters(e, type, w, h, focal_x, focal_y, &file.camera);
  internal::ResolveFormat(&file, options, e.Where(id), w, h, 0.0);
  return file;
}

void ConformOpenSfmFisheye(ModelCamera* camera) {
  using F = OpenCvFisheyeModel;
  std::vector<double>& p = camera->params;
  p[F::kFy] = p[F::kFx];
  p[F::kCx] = 0.5 * (camera->frame.width_px - 1);
  p[F::kCy] = 0.5 * (camera->frame.height_px - 1);
}

// The camera is one the format holds (the registry's CheckWritable: k4-k6 of opencv, k3, k4 of the
// fisheye at 0, the fisheye conformed by ConformOpenSfmFisheye).
void WriteOpenSfmCameras(const std::string& path, const CameraFile& file) {
  const ModelCamera& camera = file.camera;
  const PixelFrame& f = camera.frame;
  const double size = std::max(f.width_px, f.height_px);
  const std::vector<double>& p = camera.params;
  Json c;
  c["width"] = f.width_px;
  c["height"] = f.height_px;
  const double c_x = (p[2] - 0.5 * (f.width_px - 1)) / size,
               c_y = (p[3] - 0.5 * (f.height_px - 1)) / size;
  if (camera.model == OpenCvFisheyeModel::kId) {
    c["projection_type"] = "fisheye";
    c["focal"] = p[0] / size;
    c["k1"] = p[4];
    c["k2"] = p[5];
  } else {
    using O = OpenCvModel;
    AEROCAL_CHECK(camera.model == O::kId) << "not opencv";
    const bool perspective = p[O::kFx] == p[O::kFy] && c_x == 0 && c_y == 0 && p[O::kK3] == 0 &&
                             p[O::kP1] == 0 && p[O::kP2] == 0;
    if (perspective) {
      c["projection_type"] = "perspective";
      c["focal"] = p[O::kFy] / size;
    } else {
      c["projection_type"] = "brown";
      c["focal_x"] = p[O::kFx] / size;
      c["focal_y"] = p[O::kFy] / size;
      c["c_x"] = c_x;
      c["c_y"] = c_y;
      c["k3"] = p[O::kK3];
      c["p1"] = p[O::kP1];
      c["p2"] = p[O::kP2];
    }
    c["k1"] = p[O::kK1];
    c["k2"] = p[O::kK2];
  }
  Json root;
  root[file.name.empty() ? "aerocal" : file.name] = c;
  WriteFileAtomically(path, root.dump(4) + "\n");
}

}  // namespace aerocal::calib
