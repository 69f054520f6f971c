// Pix4D internal camera parameters, the .cam text file Pix4Dmapper writes
// (<project>_pix4d_calibrated_internal_camera_parameters.cam, support.pix4d.com article 202977149
// "What does the Output Params Folder contain"):
//   Pix4D camera calibration file 0
//   #Focal Length mm assuming a sensor width of <W>x<H>mm
//   F <mm>  #Principal Point mm  Px <mm>  Py <mm>
//   #Symmetrical Lens Distortion Coeffs  K1 K2 K3   #Tangential Lens Distortion Coeffs  T1 T2
// one `NAME value` per line ('#' comment lines). The .cam calls the radial terms K1-K3; the
// registry model (models/pix4d.h, which converts the conventions) calls them R1-R3; both names are
// read. The pixel size is the sensor width of the comment line over the image width in pixels,
// which the file does not hold: --width/--height (or --pixel-size-mm, which gives the size).
//
// Also read: a project's <project>_calibrated_camera_parameters.txt (Pix4Dmapper's params folder;
// the layout as EasyIDP's Pix4D reader documents it and as files quoted in public code show it):
//   7 header lines (fileName imageWidth imageHeight / camera matrix K [3x3] / radial distortion
//   [3x1] / tangential distortion [2x1] / camera position t [3x1] / camera rotation R [3x3] /
//   camera model m = K [R|-Rt] X), then per image: NAME W H, K (3 rows), R1 R2 R3, T1 T2,
//   position (3), rotation (3 rows); blank lines anywhere.
// K is in pixels with the .cam's corner origin (cx = Px / p), one focal length. Without a pixel
// size the camera is read with a placeholder one (pixels exact, mm meaningless, said).
// `--camera IMAGE` picks an image, else the first; images whose K or distortion differ from the
// picked one are said (they are another camera, or a per-image calibration).
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <cmath>
#include <map>
#include <sstream>

namespace aerocal::calib {

namespace {

constexpr char kCalibratedHeader[] = "fileName imageWidth imageHeight";

// One image of calibrated_camera_parameters.txt: its name, size and the 14 numbers of K,
// radial and tangential distortion (position and rotation are checked, not kept).
struct CalibratedImage {
  std::string name;
  int line = 0, width = 0, height = 0;
  std::vector<double> intrinsics;  // K (9), R1-R3, T1, T2
};

std::vector<CalibratedImage> ReadCalibratedImages(const std::string& path,
                                                  const std::vector<std::string>& lines) {
  struct Token {
    std::string text;
    int line;
  };
  std::vector<Token> tokens;
  for (size_t i = 7; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    for (std::string t; in >> t;) tokens.push_back({t, static_cast<int>(i + 1)});
  }
  constexpr size_t kPerImage = 3 + 9 + 3 + 2 + 3 + 9;
  std::vector<CalibratedImage> images;
  for (size_t at = 0; at < tokens.size(); at += kPerImage) {
    if (tokens.size() - at < kPerImage)
      ThrowInputError({path, tokens[at].line},
                      "image " + tokens[at].text +
                          ": a record is NAME W H, K (9), radial (3), "
                          "tangential (2), position (3), rotation (9): the file ends after " +
                          std::to_string(tokens.size() - at) + " of its 29 values");
    CalibratedImage image;
    image.name = tokens[at].text;
    image.line = tokens[at].line;
    for (int k = 1; k <= 2; ++k) {
      const SourceRef where{path, tokens[at + k].line};
      const double v = internal::ParseNumber(tokens[at + k].text, where, "image size", 1e6);
      if (!(v >= 1) || v != std::floor(v))
        ThrowInputError(where, "image size must be a positive integer");
      (k == 1 ? image.width : image.height) = static_cast<int>(v);
    }
    for (size_t k = 3; k < kPerImage; ++k) {
      const double v = internal::ParseNumber(
          tokens[at + k].text, {path, tokens[at + k].line}, "image " + image.name + " value", 1e9);
      if (k < 3 + 9 + 3 + 2) image.intrinsics.push_back(v);
    }
    images.push_back(image);
  }
  if (images.empty()) ThrowInputError({path, 8}, "no image record after the 7 header lines");
  return images;
}

CameraFile ReadPix4dCalibratedParameters(const std::string& path,
                                         const std::vector<std::string>& lines,
                                         const CameraReadOptions& options) {
  using M = Pix4dPerspectiveModel;
  const std::vector<CalibratedImage> images = ReadCalibratedImages(path, lines);
  const CalibratedImage* picked = &images.front();
  if (!options.camera_id.empty()) {
    picked = nullptr;
    std::string names;
    for (const CalibratedImage& image : images) {
      names += (names.empty() ? "" : ", ") + image.name;
      if (image.name == options.camera_id) picked = &image;
    }
    if (!picked)
      ThrowInputError({path, 1}, "no image " + options.camera_id + " (images: " + names + ")");
  }
  const std::vector<double>& k = picked->intrinsics;
  const SourceRef where{path, picked->line};
  if (k[1] != 0 || k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1)
    ThrowInputError(where, "K must be [f 0 cx; 0 f cy; 0 0 1]");
  if (!(k[0] > 0) || k[4] != k[0])
    ThrowInputError(where,
                    "K must hold one focal length > 0 px (Pix4D's F; got " + FormatNumber(k[0]) +
                        " and " + FormatNumber(k[4]) + ")");
  CameraFile file;
  file.name = picked->name;
  file.chosen_by_camera_id = !options.camera_id.empty();
  std::vector<std::string> differ;
  for (const CalibratedImage& image : images)
    if (image.intrinsics != k || image.width != picked->width || image.height != picked->height)
      differ.push_back(image.name);
  if (!differ.empty())
    file.notes.push_back(std::to_string(differ.size()) + " of " + std::to_string(images.size()) +
                         " images have another K, distortion or size than " + picked->name +
                         " (first: " + differ.front() + "): " + picked->name + " read");
  else if (images.size() > 1)
    file.notes.push_back("all " + std::to_string(images.size()) +
                         " images share K and distortion: " + picked->name + " read");
  internal::ResolveFormat(&file, options, where, picked->width, picked->height, 0.0);
  if (!file.pixel_size_known)
    file.notes.push_back(
        "no pixel size (pass --pixel-size-mm): F, Px, Py in units of the placeholder");
  const double p = file.camera.frame.pixel_size_mm;
  file.camera.model = M::kId;
  file.camera.params = {k[0] * p, k[2] * p, k[5] * p, k[9], k[10], k[11], k[12], k[13]};
  return file;
}

}  // namespace

bool IsPix4dCalibratedParameters(const std::string& head) {
  return head.rfind(kCalibratedHeader, 0) == 0;
}

CameraFile ReadPix4dCam(const std::string& path, const CameraReadOptions& options) {
  using M = Pix4dPerspectiveModel;
  const std::vector<std::string> lines = SplitLines(ReadTextFile(path));
  if (!lines.empty() && IsPix4dCalibratedParameters(lines[0]))
    return ReadPix4dCalibratedParameters(path, lines, options);
  std::map<std::string, std::pair<double, int>> values;
  double sensor_w = 0, sensor_h = 0;
  int sensor_line = 1;
  for (size_t i = 0; i < lines.size(); ++i) {
    const SourceRef where{path, static_cast<int>(i + 1)};
    const std::string& line = lines[i];
    static const std::string kSensor = "#Focal Length mm assuming a sensor width of ";
    if (line.rfind(kSensor, 0) == 0) {
      std::string size = line.substr(kSensor.size());
      const auto x = size.find('x');
      const auto mm = size.rfind("mm");
      if (x == std::string::npos || mm == std::string::npos || mm < x)
        ThrowInputError(where, "sensor size must read <W>x<H>mm");
      sensor_w = internal::ParseNumber(size.substr(0, x), where, "sensor width", 1e4);
      sensor_h = internal::ParseNumber(size.substr(x + 1, mm - x - 1), where, "sensor height", 1e4);
      if (!(sensor_w > 0 && sensor_h > 0)) ThrowInputError(where, "sensor size must be > 0 mm");
      sensor_line = where.line;
      continue;
    }
    if (line.empty() || line[0] == '#' || line.rfind("Pix4D camera calibration file", 0) == 0)
      continue;
    std::istringstream in(line);
    std::string name, value, extra;
    in >> name >> value;
    if (name.empty()) continue;
    if (value.empty() || (in >> extra))
      ThrowInputError(where, "a parameter line is NAME VALUE (got '" + line + "')");
    if (name == "K1" || name == "K2" || name == "K3") name = "R" + name.substr(1);
    if (IndexOfParam(M::kParams, name) < 0)
      ThrowInputError(where, "unknown parameter '" + name + "' (F, Px, Py, K1-K3, T1, T2)");
    if (values.count(name)) ThrowInputError(where, "duplicate " + name);
    values[name] = {internal::ParseNumber(value, where, name, 1e4), where.line};
  }
  for (const char* required : {"F", "Px", "Py"})
    if (!values.count(required)) ThrowInputError({path, 1}, std::string("missing ") + required);
  if (!(values["F"].first > 0)) ThrowInputError({path, values["F"].second}, "F must be > 0 mm");
  CameraFile file;
  file.camera.model = M::kId;
  file.camera.params.assign(M::kNumParams, 0.0);
  for (const auto& [name, v] : values) file.camera.params[IndexOfParam(M::kParams, name)] = v.first;
  // Image size and pixel size from the sensor size and whichever of them the caller gave.
  int width = options.width_px, height = options.height_px;
  double pixel = options.pixel_size_mm;
  const SourceRef where{path, sensor_line};
  if (sensor_w > 0) {
    if (width == 0 && pixel > 0) width = static_cast<int>(std::lround(sensor_w / pixel));
    if (height == 0 && pixel > 0) height = static_cast<int>(std::lround(sensor_h / pixel));
    if (pixel == 0 && width > 0) pixel = sensor_w / width;
    if (width > 0 && std::abs(sensor_w - width * pixel) > 0.5 * pixel)
      ThrowInputError(where,
                      "sensor width " + FormatNumber(sensor_w) + " mm contradicts " +
                          std::to_string(width) + " px of " + FormatNumber(pixel) + " mm");
    if (height > 0 && std::abs(sensor_h - height * pixel) > 0.5 * pixel)
      ThrowInputError(where,
                      "sensor height " + FormatNumber(sensor_h) + " mm contradicts " +
                          std::to_string(height) + " px of " + FormatNumber(pixel) + " mm");
  }
  if (!(pixel > 0))
    ThrowInputError(where,
                    "the pixel size is needed (F, Px, Py are mm): pass --width/--height "
                    "with the sensor-size line, or --pixel-size-mm");
  CameraReadOptions derived;
  internal::ResolveFormat(&file, derived, where, width, height, pixel);
  return file;
}

void WritePix4dCam(const std::string& path, const CameraFile& file) {
  using M = Pix4dPerspectiveModel;
  AEROCAL_CHECK(file.camera.model == M::kId) << "not pix4d_perspective";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& p = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "Pix4D camera calibration file 0\n#Focal Length mm assuming a sensor width of "
      << n(f.width_px * f.pixel_size_mm) << "x" << n(f.height_px * f.pixel_size_mm) << "mm\n"
      << "F " << n(p[M::kF]) << "\n#Principal Point mm\nPx " << n(p[M::kPx]) << "\nPy "
      << n(p[M::kPy]) << "\n#Symmetrical Lens Distortion Coeffs\nK1 " << n(p[M::kR1]) << "\nK2 "
      << n(p[M::kR2]) << "\nK3 " << n(p[M::kR3]) << "\n#Tangential Lens Distortion Coeffs\nT1 "
      << n(p[M::kT1]) << "\nT2 " << n(p[M::kT2]) << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
