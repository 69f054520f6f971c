// COLMAP cameras.txt (colmap.github.io/format.html "Text format": `CAMERA_ID, MODEL, WIDTH,
// HEIGHT, PARAMS[]`, blank-separated, '#' comment lines). The camera stays in the registry's
// COLMAP model (models/colmap.h converts COLMAP's pixel origin); the COLMAP import reads its
// cameras through ColmapCameraFromFields, so there is one conversion.
#include <sstream>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {
namespace {

std::vector<std::string> Blanks(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> fields;
  for (std::string f; in >> f;) fields.push_back(f);
  return fields;
}

}  // namespace

ModelCamera ColmapCameraFromFields(const std::vector<std::string>& fields, const SourceRef& where,
                                   double pixel_size_mm) {
  if (fields.size() < 4)
    ThrowInputError(where, "a camera line is CAMERA_ID MODEL WIDTH HEIGHT PARAMS...");
  const std::string& name = fields[1];
  const auto model = CameraModelFromColmapName(name);
  if (!model)
    ThrowInputError(where, "camera model " + name +
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
      ThrowInputError(where, std::string(what) + " out of range (got " + text +
                                 ", expected 1 .. 1000000)");
    if (v != static_cast<int>(v))
      ThrowInputError(where, std::string(what) + " must be an integer within 1 .. 1000000 (got " +
                                 text + ")");
    return static_cast<int>(v);
  };
  camera.frame.width_px = integer(fields[2], "WIDTH");
  camera.frame.height_px = integer(fields[3], "HEIGHT");
  for (size_t k = 0; k < num_params; ++k)
    camera.params.push_back(internal::ParseNumber(fields[4 + k], where, "PARAMS", 1e7));
  // Focal lengths (f, or fx and fy) lead every COLMAP model's parameters.
  const bool two_focals = name == "PINHOLE" || name == "OPENCV" || name == "FULL_OPENCV";
  if (!(camera.params[0] > 0) || (two_focals && !(camera.params[1] > 0)))
    ThrowInputError(where, "focal length must be > 0 px (got " + FormatNumber(camera.params[0]) +
                               ")");
  return camera;
}

CameraFile ReadColmapCameras(const std::string& path, const CameraReadOptions& options) {
  const std::vector<std::string> lines = SplitLines(ReadTextFile(path));
  std::string ids;
  std::optional<CameraFile> found;
  int found_line = 0, count = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!lines[i].empty() && lines[i][0] == '#') continue;
    const std::vector<std::string> fields = Blanks(lines[i]);
    if (fields.empty()) continue;
    ++count;
    ids += (ids.empty() ? "" : ", ") + fields[0];
    if (!options.camera_id.empty() && fields[0] != options.camera_id) continue;
    if (found) continue;
    const SourceRef where{path, static_cast<int>(i + 1)};
    CameraFile file;
    file.name = fields[0];
    file.camera = ColmapCameraFromFields(fields, where, kPlaceholderPixelSizeMm);
    found_line = where.line;
    found = file;
  }
  if (!found)
    ThrowInputError({path, 1}, options.camera_id.empty()
                                   ? "no camera line"
                                   : "no camera " + options.camera_id + " (cameras: " + ids + ")");
  if (count > 1 && options.camera_id.empty())
    ThrowInputError({path, 1}, "holds " + std::to_string(count) +
                                   " cameras: name one with --camera (" + ids + ")");
  const PixelFrame frame = found->camera.frame;
  internal::ResolveFormat(&*found, options, {path, found_line}, frame.width_px, frame.height_px,
                          0.0);
  return *found;
}

void WriteColmapCameras(const std::string& path, const CameraFile& file) {
  const std::string_view model = ColmapName(file.camera.model);
  AEROCAL_CHECK(!model.empty()) << "not a COLMAP model: " << CameraModelName(file.camera.model);
  std::ostringstream out;
  out.precision(17);
  out << "# Camera list with one line of data per camera:\n"
      << "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n# Number of cameras: 1\n"
      << "1 " << model << " " << file.camera.frame.width_px << " " << file.camera.frame.height_px;
  for (double p : file.camera.params) out << " " << p;
  out << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
