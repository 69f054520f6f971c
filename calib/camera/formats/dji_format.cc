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
#include "calib/camera/formats/xmp_packet.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {

using internal::FindXmpValue;
using internal::JpegSize;
using internal::LineAt;
using internal::TrimBlanks;
ModelCamera DjiDewarpDataCamera(const std::string& text, const SourceRef& where, int width_px,
                                int height_px) {
  std::string values = TrimBlanks(text);
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
  size_t at = FindXmpValue(bytes, "drone-dji:DewarpDataK6", &data);
  if (at == std::string::npos) at = FindXmpValue(bytes, "drone-dji:DewarpData", &data);
  if (at == std::string::npos) {
    if (jpeg || bytes.find("drone-dji") != std::string::npos)
      ThrowInputError({path, jpeg ? 0 : 1}, "no drone-dji:DewarpData in the file's XMP");
    data = bytes;  // a text file holding the string
    at = bytes.find_first_not_of(" \t\r\n");
  }
  const SourceRef where{path, jpeg ? 0 : LineAt(bytes, at)};
  if (!jpeg) {  // an XMP sidecar may carry the size (tiff:ImageWidth / tiff:ImageLength)
    std::string w, h;
    if (FindXmpValue(bytes, "tiff:ImageWidth", &w) != std::string::npos &&
        FindXmpValue(bytes, "tiff:ImageLength", &h) != std::string::npos) {
      jpeg_width = static_cast<int>(internal::ParseNumber(TrimBlanks(w), where, "tiff:ImageWidth", 1e6));
      jpeg_height = static_cast<int>(internal::ParseNumber(TrimBlanks(h), where, "tiff:ImageLength", 1e6));
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
    if (FindXmpValue(bytes, std::string("drone-dji:") + design, &value) != std::string::npos)
      file.notes.push_back(std::string(design) + " = " + TrimBlanks(value) + " px (design value, not used)");
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
