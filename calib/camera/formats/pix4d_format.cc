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
// which the file does not hold: --width/--height (or --pixel-mm, which gives the size).
#include <cmath>
#include <map>
#include <sstream>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {

CameraFile ReadPix4dCam(const std::string& path, const CameraReadOptions& options) {
  using M = Pix4dPerspectiveModel;
  const std::vector<std::string> lines = SplitLines(ReadTextFile(path));
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
      ThrowInputError(where, "sensor width " + FormatNumber(sensor_w) + " mm contradicts " +
                                 std::to_string(width) + " px of " + FormatNumber(pixel) + " mm");
    if (height > 0 && std::abs(sensor_h - height * pixel) > 0.5 * pixel)
      ThrowInputError(where, "sensor height " + FormatNumber(sensor_h) + " mm contradicts " +
                                 std::to_string(height) + " px of " + FormatNumber(pixel) + " mm");
  }
  if (!(pixel > 0))
    ThrowInputError(where, "the pixel size is needed (F, Px, Py are mm): pass --width/--height "
                           "with the sensor-size line, or --pixel-mm");
  CameraReadOptions derived;
  internal::ResolveFormat(&file, derived, where, width, height, pixel);
  return file;
}

void WritePix4dCam(const std::string& path, const CameraFile& file) {
  using M = Pix4dPerspectiveModel;
  AEROCAL_CHECK(file.camera.model == M::kId) << "not pix4d_perspective";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& p = file.camera.params;
  std::ostringstream out;
  out.precision(17);
  out << "Pix4D camera calibration file 0\n#Focal Length mm assuming a sensor width of "
      << f.width_px * f.pixel_size_mm << "x" << f.height_px * f.pixel_size_mm << "mm\n"
      << "F " << p[M::kF] << "\n#Principal Point mm\nPx " << p[M::kPx] << "\nPy " << p[M::kPy]
      << "\n#Symmetrical Lens Distortion Coeffs\nK1 " << p[M::kR1] << "\nK2 " << p[M::kR2]
      << "\nK3 " << p[M::kR3] << "\n#Tangential Lens Distortion Coeffs\nT1 " << p[M::kT1]
      << "\nT2 " << p[M::kT2] << "\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
