// DJI XMP DewarpData: drone-dji:DewarpData = "date;fx,fy,cx,cy,k1,k2,p1,p2,k3" (DJI user manuals,
// e.g. Mavic 3M / Matrice 4, metadata tables: "fx, fy - calibrated focal length (unit: pixel);
// cx, cy - calibrated optical center position (unit: pixel, origin point: photo center);
// k1, k2, p1, p2, k3 - radial and tangential distortion parameters"), and DewarpDataK6 (fx, fy, cx,
// cy, k1, k2, p1, p2, k3, k4, k5, k6) of newer models. DJI gives no formula: the coefficients are
// read as OpenCV's (distCoeffs order), as Metashape's and Pix4D's DJI imports do. The principal
// point: cx_opencv = W / 2 + cx, cy_opencv = H / 2 + cy (which centre is meant is not stated;
// (W - 1) / 2 would move it by 0.5 px). Input: a DJI JPEG (the XMP packet is found in the file;
// the size from its SOF marker), an XMP sidecar, or a text file holding the string (then
// --width/--height). CalibratedFocalLength and CalibratedOpticalCenterX/Y (design values) are
// reported as notes.
#include <cmath>
#include <sstream>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {
namespace {

int LineAt(const std::string& text, size_t offset) {
  int line = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

// The value of an XMP property written as an attribute (drone-dji:NAME="v") or an element
// (<drone-dji:NAME>v</drone-dji:NAME>); npos when absent.
size_t FindXmp(const std::string& text, const std::string& qualified, std::string* value) {
  const std::string attribute = qualified + "=\"";
  size_t at = text.find(attribute);
  if (at != std::string::npos) {
    const size_t begin = at + attribute.size(), end = text.find('"', begin);
    if (end == std::string::npos) return std::string::npos;
    *value = text.substr(begin, end - begin);
    return begin;
  }
  const std::string open = "<" + qualified + ">", close = "</" + qualified + ">";
  at = text.find(open);
  if (at == std::string::npos) return std::string::npos;
  const size_t begin = at + open.size(), end = text.find(close, begin);
  if (end == std::string::npos) return std::string::npos;
  *value = text.substr(begin, end - begin);
  return begin;
}

// Width and height from a JPEG's SOF marker; false when the bytes are not a JPEG.
bool JpegSize(const std::string& bytes, int* width, int* height) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(bytes[i]); };
  if (bytes.size() < 4 || byte(0) != 0xFF || byte(1) != 0xD8) return false;
  size_t i = 2;
  while (i + 9 < bytes.size()) {
    if (byte(i) != 0xFF) return false;
    const unsigned marker = byte(i + 1);
    const size_t length = (byte(i + 2) << 8) | byte(i + 3);
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      *height = (byte(i + 5) << 8) | byte(i + 6);
      *width = (byte(i + 7) << 8) | byte(i + 8);
      return true;
    }
    if (marker == 0xDA || length < 2) return false;
    i += 2 + length;
  }
  return false;
}

std::string Trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

ModelCamera DjiDewarpDataCamera(const std::string& text, const SourceRef& where, int width_px,
                                int height_px) {
  std::string values = Trim(text);
  const size_t semicolon = values.find(';');
  if (semicolon != std::string::npos) values = values.substr(semicolon + 1);  // the date
  const std::vector<std::string> fields = SplitCommaList(values, {true, true});
  if (fields.size() != 9 && fields.size() != 12)
    ThrowInputError(where, "DewarpData must hold 9 values (fx,fy,cx,cy,k1,k2,p1,p2,k3) or 12 "
                           "(DewarpDataK6: ...,k4,k5,k6); got " +
                               std::to_string(fields.size()));
  std::vector<double> v;
  for (const std::string& f : fields) v.push_back(internal::ParseNumber(f, where, "DewarpData value", 1e7));
  if (!(v[0] > 0 && v[1] > 0)) ThrowInputError(where, "DewarpData fx, fy must be > 0 px");
  using O = OpenCvModel;
  ModelCamera camera;
  camera.model = O::kId;
  camera.params.assign(O::kNumParams, 0.0);
  camera.params[O::kFx] = v[0];
  camera.params[O::kFy] = v[1];
  camera.params[O::kCx] = 0.5 * width_px + v[2];
  camera.params[O::kCy] = 0.5 * height_px + v[3];
  camera.params[O::kK1] = v[4];
  camera.params[O::kK2] = v[5];
  camera.params[O::kP1] = v[6];
  camera.params[O::kP2] = v[7];
  camera.params[O::kK3] = v[8];
  if (v.size() == 12) {
    camera.params[O::kK4] = v[9];
    camera.params[O::kK5] = v[10];
    camera.params[O::kK6] = v[11];
  }
  camera.frame.width_px = width_px;
  camera.frame.height_px = height_px;
  return camera;
}

CameraFile ReadDjiDewarpData(const std::string& path, const CameraReadOptions& options) {
  const std::string bytes = ReadTextFile(path);
  int jpeg_width = 0, jpeg_height = 0;
  const bool jpeg = JpegSize(bytes, &jpeg_width, &jpeg_height);
  std::string data;
  size_t at = FindXmp(bytes, "drone-dji:DewarpDataK6", &data);
  if (at == std::string::npos) at = FindXmp(bytes, "drone-dji:DewarpData", &data);
  if (at == std::string::npos) {
    if (jpeg || bytes.find("drone-dji") != std::string::npos)
      ThrowInputError({path, jpeg ? 0 : 1}, "no drone-dji:DewarpData in the file's XMP");
    data = bytes;  // a text file holding the string
    at = bytes.find_first_not_of(" \t\r\n");
  }
  const SourceRef where{path, jpeg ? 0 : LineAt(bytes, at)};
  if (!jpeg) {  // an XMP sidecar may carry the size (tiff:ImageWidth / tiff:ImageLength)
    std::string w, h;
    if (FindXmp(bytes, "tiff:ImageWidth", &w) != std::string::npos &&
        FindXmp(bytes, "tiff:ImageLength", &h) != std::string::npos) {
      jpeg_width = static_cast<int>(internal::ParseNumber(Trim(w), where, "tiff:ImageWidth", 1e6));
      jpeg_height = static_cast<int>(internal::ParseNumber(Trim(h), where, "tiff:ImageLength", 1e6));
    }
  }
  CameraFile file;
  internal::ResolveFormat(&file, options, where, jpeg_width, jpeg_height, 0.0);
  const PixelFrame frame = file.camera.frame;
  file.camera = DjiDewarpDataCamera(data, where, frame.width_px, frame.height_px);
  file.camera.frame = frame;
  file.name = "dji";
  for (const char* design : {"CalibratedFocalLength", "CalibratedOpticalCenterX", "CalibratedOpticalCenterY"}) {
    std::string value;
    if (FindXmp(bytes, std::string("drone-dji:") + design, &value) != std::string::npos)
      file.notes.push_back(std::string(design) + " = " + Trim(value) + " px (design value, not used)");
  }
  return file;
}

void WriteDjiDewarpData(const std::string& path, const CameraFile& file) {
  using O = OpenCvModel;
  AEROCAL_CHECK(file.camera.model == O::kId) << "not opencv";
  const std::vector<double>& p = file.camera.params;
  const PixelFrame& f = file.camera.frame;
  const bool k6 = p[O::kK4] != 0 || p[O::kK5] != 0 || p[O::kK6] != 0;
  std::ostringstream out;
  out.precision(17);
  out << p[O::kFx] << "," << p[O::kFy] << "," << p[O::kCx] - 0.5 * f.width_px << ","
      << p[O::kCy] - 0.5 * f.height_px << "," << p[O::kK1] << "," << p[O::kK2] << "," << p[O::kP1]
      << "," << p[O::kP2] << "," << p[O::kK3];
  if (k6) out << "," << p[O::kK4] << "," << p[O::kK5] << "," << p[O::kK6];
  // An XMP sidecar: what a DJI JPEG carries, readable by this reader and by XMP tools.
  WriteFileAtomically(path, std::string("<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n <rdf:RDF "
                                        "xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n"
                                        "  <rdf:Description xmlns:drone-dji=\"http://www.dji.com/drone-dji/1.0/\"\n"
                                        "    xmlns:tiff=\"http://ns.adobe.com/tiff/1.0/\"\n"
                                        "    tiff:ImageWidth=\"") +
                                std::to_string(f.width_px) + "\" tiff:ImageLength=\"" +
                                std::to_string(f.height_px) + "\"\n    drone-dji:" +
                                (k6 ? "DewarpDataK6" : "DewarpData") + "=\"" + out.str() +
                                "\"/>\n </rdf:RDF>\n</x:xmpmeta>\n");
}

}  // namespace aerocal::calib
