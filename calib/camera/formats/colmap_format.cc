// COLMAP cameras.txt (colmap.github.io/format.html "Text format": `CAMERA_ID, MODEL, WIDTH,
// HEIGHT, PARAMS[]`, blank-separated, '#' comment lines). The camera stays in the registry's
// COLMAP model (models/colmap.h converts COLMAP's pixel origin); the COLMAP import reads its
// cameras through ColmapCameraFromFields, so there is one conversion.
// Also cameras.bin (COLMAP's src/colmap/scene/reconstruction_io.cc WriteCamerasBinary, little
// endian: uint64 count, then per camera uint32 id, int32 model id, uint64 width, uint64 height,
// the model's parameters as doubles), read into the same fields; written when OUT ends in .bin.
// Camera ids are kept as they are (0 is a valid id); ours is written with its name when that is a
// non-negative integer, else as camera 1.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <regex>
#include <sstream>

namespace aerocal::calib {
namespace {

std::vector<std::string> Blanks(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

// COLMAP's model ids (sensor/models.h) and their parameter counts; -1: not a COLMAP id.
constexpr int kBinaryModelCount = 11;
constexpr const char* kBinaryModelNames[kBinaryModelCount] = {"SIMPLE_PINHOLE",
                                                              "PINHOLE",
                                                              "SIMPLE_RADIAL",
                                                              "RADIAL",
                                                              "OPENCV",
                                                              "OPENCV_FISHEYE",
                                                              "FULL_OPENCV",
                                                              "FOV",
                                                              "SIMPLE_RADIAL_FISHEYE",
                                                              "RADIAL_FISHEYE",
                                                              "THIN_PRISM_FISHEYE"};
constexpr int kBinaryParamCounts[kBinaryModelCount] = {3, 4, 4, 5, 8, 8, 12, 5, 4, 5, 12};

bool IsBinaryPath(const std::string& path) {
  return std::filesystem::path(path).extension() == ".bin";
}

template <typename T>
T Get(const std::string& bytes, size_t* at, const std::string& path, const char* what) {
  T value;
  if (bytes.size() - *at < sizeof(T))
    ThrowInputError(
        {path, 0},
        std::string("cameras.bin ends inside ") + what + " (byte " + std::to_string(*at) + ")");
  std::memcpy(&value, bytes.data() + *at, sizeof(T));  // little-endian host (x86-64, arm64)
  *at += sizeof(T);
  return value;
}

// The cameras of a cameras.bin as cameras.txt fields (line = camera number, 1-based).
std::vector<std::vector<std::string>> BinaryRows(const std::string& path) {
  const std::string bytes = ReadTextFile(path);
  size_t at = 0;
  const uint64_t count = Get<uint64_t>(bytes, &at, path, "the camera count");
  if (count > bytes.size() / 24)
    ThrowInputError({path, 0},
                    "cameras.bin: camera count " + std::to_string(count) +
                        " does not fit the file's " + std::to_string(bytes.size()) + " bytes");
  std::vector<std::vector<std::string>> rows;
  for (uint64_t k = 0; k < count; ++k) {
    const uint32_t id = Get<uint32_t>(bytes, &at, path, "a camera id");
    const int32_t model = Get<int32_t>(bytes, &at, path, "a model id");
    const uint64_t width = Get<uint64_t>(bytes, &at, path, "a width");
    const uint64_t height = Get<uint64_t>(bytes, &at, path, "a height");
    if (model < 0 || model >= kBinaryModelCount)
      ThrowInputError({path, 0},
                      "cameras.bin camera " + std::to_string(id) + ": model id " +
                          std::to_string(model) + " is not one of COLMAP's (0-10)");
    std::vector<std::string> row = {std::to_string(id),
                                    kBinaryModelNames[model],
                                    std::to_string(width),
                                    std::to_string(height)};
    for (int i = 0; i < kBinaryParamCounts[model]; ++i)
      row.push_back(internal::ShortestNumber(Get<double>(bytes, &at, path, "the parameters")));
    rows.push_back(row);
  }
  if (at != bytes.size())
    ThrowInputError(
        {path, 0},
        "cameras.bin: " + std::to_string(bytes.size() - at) + " bytes after the last camera");
  return rows;
}

}  // namespace

bool LooksLikeColmapBinary(const std::string& head, const std::string& path) {
  if (!IsBinaryPath(path) || head.size() < 8 + 24) return false;
  size_t at = 8;
  at += 4;
  const int32_t model = Get<int32_t>(head, &at, path, "a model id");
  return model >= 0 && model < kBinaryModelCount;
}

ModelCamera ColmapCameraFromFields(const std::vector<std::string>& fields,
                                   const SourceRef& where,
                                   double pixel_size_mm) {
  if (fields.size() < 4)
    ThrowInputError(where, "a camera line is CAMERA_ID MODEL WIDTH HEIGHT PARAMS...");
  const std::string& name = fields[1];
  const auto model = CameraModelFromColmapName(name);
  if (!model)
    ThrowInputError(where,
                    "camera model " + name +
                        " is not supported (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, "
                        "RADIAL, OPENCV, FULL_OPENCV)");
  const size_t num_params = CameraModelParamCount(*model);
  if (fields.size() != 4 + num_params)
    ThrowInputError(where, name + " needs " + std::to_string(num_params) + " parameters");
  ModelCamera camera;
  camera.model = *model;
  camera.frame.pixel_size_mm = pixel_size_mm;
  const auto integer = [&](const std::string& text, const char* what) {
    const double v = internal::ParseNumber(text, where, what, 1e300);
    if (!(v >= 1 && v <= 1e6))
      ThrowInputError(
          where, std::string(what) + " out of range (got " + text + ", expected 1 .. 1000000)");
    if (v != static_cast<int>(v))
      ThrowInputError(
          where, std::string(what) + " must be an integer within 1 .. 1000000 (got " + text + ")");
    return static_cast<int>(v);
  };
  camera.frame.width_px = integer(fields[2], "WIDTH");
  camera.frame.height_px = integer(fields[3], "HEIGHT");
  for (size_t k = 0; k < num_params; ++k)
    camera.params.push_back(internal::ParseNumber(fields[4 + k], where, "PARAMS", 1e7));
  // Focal lengths (f, or fx and fy) lead every COLMAP model's parameters.
  const bool two_focals = name == "PINHOLE" || name == "OPENCV" || name == "FULL_OPENCV";
  if (!(camera.params[0] > 0) || (two_focals && !(camera.params[1] > 0)))
    ThrowInputError(where,
                    "focal length must be > 0 px (got " + FormatNumber(camera.params[0]) + ")");
  return camera;
}

CameraFile ReadColmapCameras(const std::string& path, const CameraReadOptions& options) {
  // Rows of fields with their line (cameras.txt) or camera number (cameras.bin).
  std::vector<std::pair<std::vector<std::string>, int>> rows;
  const bool binary = IsBinaryPath(path);
  if (binary) {
    int k = 0;
    for (auto& row : BinaryRows(path)) rows.emplace_back(std::move(row), ++k);
  } else {
    const std::vector<std::string> lines = SplitLines(ReadTextFile(path));
    for (size_t i = 0; i < lines.size(); ++i) {
      if (!lines[i].empty() && lines[i][0] == '#') continue;
      std::vector<std::string> fields = Blanks(lines[i]);
      if (!fields.empty()) rows.emplace_back(std::move(fields), static_cast<int>(i + 1));
    }
  }
  const auto where_of = [&](int n) {
    return binary ? SourceRef{path + " camera " + std::to_string(n), 0} : SourceRef{path, n};
  };
  std::string ids;
  for (const auto& [fields, n] : rows) ids += (ids.empty() ? "" : ", ") + fields[0];
  const std::pair<std::vector<std::string>, int>* found = nullptr;
  for (const auto& row : rows) {
    if (!options.camera_id.empty() && row.first[0] != options.camera_id) continue;
    if (found) ThrowInputError(where_of(row.second), "camera id " + row.first[0] + " occurs twice");
    found = &row;
    if (options.camera_id.empty()) break;
  }
  if (!found)
    ThrowInputError({path, 1},
                    options.camera_id.empty()
                        ? "no camera line"
                        : "no camera " + options.camera_id + " (cameras: " + ids + ")");
  if (rows.size() > 1 && options.camera_id.empty())
    ThrowInputError(
        {path, 1},
        "holds " + std::to_string(rows.size()) + " cameras: name one with --camera (" + ids + ")");
  CameraFile file;
  file.name = found->first[0];
  file.chosen_by_camera_id = !options.camera_id.empty();
  file.camera =
      ColmapCameraFromFields(found->first, where_of(found->second), kPlaceholderPixelSizeMm);
  const PixelFrame frame = file.camera.frame;
  internal::ResolveFormat(
      &file, options, where_of(found->second), frame.width_px, frame.height_px, 0.0);
  return file;
}

void WriteColmapCameras(const std::string& path, const CameraFile& file) {
  const std::string_view model = ColmapName(file.camera.model);
  AEROCAL_CHECK(!model.empty()) << "not a COLMAP model: " << CameraModelName(file.camera.model);
  const bool keeps_id = std::regex_match(file.name, std::regex("[0-9]{1,9}"));
  const std::string id = keeps_id ? file.name : "1";
  const PixelFrame& f = file.camera.frame;
  if (IsBinaryPath(path)) {
    std::string bytes;
    const auto put = [&](const auto value) {
      bytes.append(reinterpret_cast<const char*>(&value), sizeof(value));
    };
    int model_id = 0;
    while (model_id < kBinaryModelCount && kBinaryModelNames[model_id] != model) ++model_id;
    put(uint64_t{1});
    put(static_cast<uint32_t>(std::stoul(id)));
    put(static_cast<int32_t>(model_id));
    put(static_cast<uint64_t>(f.width_px));
    put(static_cast<uint64_t>(f.height_px));
    for (double p : file.camera.params) put(p);
    WriteFileAtomically(path, bytes);
    return;
  }
  std::ostringstream out;
  out << "# Camera list with one line of data per camera:\n"
      << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: 1\n"
      << id << " " << model << " " << f.width_px << " " << f.height_px;
  for (double p : file.camera.params) out << " " << internal::ShortestNumber(p);
  out << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
