// What the camera-format readers share (camera_formats.h).
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/svg.h"
#include "calib/core/yaml_util.h"

#include <charconv>
#include <cmath>

namespace aerocal::calib::internal {

void ResolveFormat(CameraFile* file,
                   const CameraReadOptions& options,
                   const SourceRef& where,
                   int file_width_px,
                   int file_height_px,
                   double file_pixel_size_mm) {
  PixelFrame& frame = file->camera.frame;
  const auto pick = [&](int from_file, int given, const char* option) {
    if (from_file > 0 && given > 0 && from_file != given)
      ThrowInputError(where,
                      std::string("the file says ") + std::to_string(from_file) + " px, " + option +
                          " says " + std::to_string(given));
    const int value = from_file > 0 ? from_file : given;
    if (value <= 0)
      ThrowInputError(where, std::string("the file gives no image size: pass ") + option);
    if (value > 1000000)
      ThrowInputError(where, std::string("image size above 1e6 px (") + option + ")");
    return value;
  };
  frame.width_px = pick(file_width_px, options.width_px, "--width");
  frame.height_px = pick(file_height_px, options.height_px, "--height");
  if (file_pixel_size_mm > 0 && options.pixel_size_mm > 0 &&
      std::abs(file_pixel_size_mm - options.pixel_size_mm) > 1e-9 * file_pixel_size_mm)
    ThrowInputError(where,
                    "the file's pixel size " + FormatNumber(file_pixel_size_mm) +
                        " mm contradicts --pixel-size-mm " + FormatNumber(options.pixel_size_mm));
  const double p = file_pixel_size_mm > 0 ? file_pixel_size_mm : options.pixel_size_mm;
  file->pixel_size_known = p > 0;
  frame.pixel_size_mm = p > 0 ? p : kPlaceholderPixelSizeMm;
  if (!(frame.pixel_size_mm >= 1e-5 && frame.pixel_size_mm <= 1.0))
    ThrowInputError(
        where,
        "pixel size must be within 1e-5 .. 1 mm (got " + FormatNumber(frame.pixel_size_mm) + ")");
}

double ParseNumber(const std::string& text,
                   const SourceRef& where,
                   const std::string& what,
                   double bound) {
  const auto value = ParseDouble(text);
  if (!value || !(std::abs(*value) <= bound))
    ThrowInputError(
        where,
        what + " must be a number within +-" + FormatNumber(bound) + " (got '" + text + "')");
  return *value;
}

double Param(const ModelCamera& camera, std::string_view name) {
  const std::vector<ParamInfo> table = CameraModelParams(camera.model);
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].name == name) return camera.params.at(i);
  throw LogicError(std::string(CameraModelName(camera.model)) + " has no parameter " +
                   std::string(name));
}

std::string OneLine(std::string_view name) {
  std::string out(name);
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = ' ';
  return out;
}

std::string ShortestNumber(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string YamlQuoted(std::string_view text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\' || c == '"') out += '\\';
    out += c;
  }
  return out;
}

YAML::Node LoadCameraYaml(const std::string& path) {
  std::string text = ReadTextFile(path);
  if (text.rfind("%YAML:", 0) == 0) text[0] = '#';
  return LoadYamlText(text, path);
}

std::string XmlEscaped(std::string_view text) { return SvgEscape(text); }

}  // namespace aerocal::calib::internal
