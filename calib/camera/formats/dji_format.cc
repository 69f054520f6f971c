// DJI XMP DewarpData: drone-dji:DewarpData = "date;fx,fy,cx,cy,k1,k2,p1,p2,k3" (DJI user manuals,
// e.g. Mavic 3M / Matrice 4, metadata tables: "fx, fy - calibrated focal length (unit: pixel);
// cx, cy - calibrated optical center position (unit: pixel, origin point: photo center);
// k1, k2, p1, p2, k3 - radial and tangential distortion parameters"), and DewarpDataK6 (fx, fy, cx,
// cy, k1, k2, p1, p2, k3, k4, k5, k6) of newer models. DJI gives no formula: the coefficients are
// read as OpenCV's (distCoeffs order), as Metashape's and Pix4D's DJI imports do. The principal
// point: cx_opencv = W / 2 + cx, cy_opencv = H / 2 + cy (which centre is meant is not stated;
// (W - 1) / 2 would move it by 0.5 px). Input: a DJI JPEG (the XMP packet is found in the file;
// the size from its SOF marker; calib/metadata/image_metadata.h: the properties are matched by
// namespace URI, whatever prefix the file binds), an XMP sidecar, or a text file holding the string
// (then
// --width/--height). CalibratedFocalLength and CalibratedOpticalCenterX/Y (design values) are
// reported as notes. A text file may hold several records as exiftool prints them (default print
// names "Dewarp Data : ...", -s tag names, -G group prefixes, "======== FILE" blocks with their
// Image Width / Height) or bare lines; --camera picks one by file, date or number, identical
// records are one camera (said). The date of the record is the camera's name and is written back.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/metadata/image_metadata.h"

#include <cctype>
#include <cmath>
#include <regex>
#include <sstream>

namespace aerocal::calib {

namespace {

std::string TrimBlanks(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

}  // namespace

ModelCamera DjiDewarpDataCamera(const std::string& text,
                                const SourceRef& where,
                                int width_px,
                                int height_px) {
  std::string values = TrimBlanks(text);
  const size_t semicolon = values.find(';');
  if (semicolon != std::string::npos) values = values.substr(semicolon + 1);  // the date
  const std::vector<std::string> fields = SplitCommaList(values, {true, true});
  if (fields.size() != 9 && fields.size() != 12)
    ThrowInputError(where,
                    "DewarpData must hold 9 values (fx,fy,cx,cy,k1,k2,p1,p2,k3) or 12 "
                    "(DewarpDataK6: ...,k4,k5,k6); got " +
                        std::to_string(fields.size()));
  std::vector<double> v;
  for (const std::string& f : fields)
    v.push_back(internal::ParseNumber(f, where, "DewarpData value", 1e7));
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

namespace {

// One DewarpData record of a text file, with what the same block printed beside it.
struct DewarpRecord {
  std::string file;  // exiftool's "======== NAME" block, else ""
  std::string data;  // the value, "[date;]fx,..."
  int line = 0, width = 0, height = 0;
  std::vector<std::string> design;  // CalibratedFocalLength / OpticalCenterX / Y, as notes
};

std::string Date(const std::string& data) {
  const size_t semicolon = data.find(';');
  return semicolon == std::string::npos ? "" : TrimBlanks(data.substr(0, semicolon));
}

// exiftool's print name or tag name, or a bare key: "Dewarp Data" / "DewarpData" -> "dewarpdata".
std::string KeyOf(const std::string& key) {
  std::string out;
  for (char c : key)
    if (c != ' ' && c != '\t')
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (!out.empty() && out[0] == '[' && out.find(']') != std::string::npos)  // -G: "[XMP] "
    out = out.substr(out.find(']') + 1);
  return out;
}

// The records of a text file as exiftool (default, -s, -G, several files) or DJI's tools print
// them, or bare "[date;]fx,..." lines. Unknown "key : value" lines are other tags (skipped); a
// line that is neither a tag nor a record is an error.
std::vector<DewarpRecord> TextRecords(const std::string& path, const std::string& text) {
  const std::vector<std::string> lines = SplitLines(text);
  std::vector<DewarpRecord> records;
  std::string file;
  int width = 0, height = 0, width_line = 0, height_line = 0;
  std::vector<std::string> design;
  // A block's width or height given again (exiftool prints Image Width and Exif Image Width) must
  // agree with the first: two values are an error, not the last one taken.
  const auto size = [&](const std::string& value,
                        const SourceRef& where,
                        const char* what,
                        int* slot,
                        int* slot_line) {
    const int v = static_cast<int>(internal::ParseNumber(value, where, what, 1e6));
    if (*slot != 0 && v != *slot)
      ThrowInputError(where,
                      std::string(what) + " " + std::to_string(v) + " contradicts " +
                          std::to_string(*slot) + " on line " + std::to_string(*slot_line));
    *slot = v;
    *slot_line = where.line;
  };
  const auto flush_block = [&] {  // sizes and design values printed after the record
    for (DewarpRecord& r : records)
      if (r.file == file) {
        if (r.width == 0) r.width = width, r.height = height;
        if (r.design.empty()) r.design = design;
      }
  };
  for (size_t i = 0; i < lines.size(); ++i) {
    const SourceRef where{path, static_cast<int>(i + 1)};
    const std::string line = TrimBlanks(lines[i]);
    if (line.empty() || line[0] == '#') continue;
    if (line.rfind("========", 0) == 0) {
      flush_block();
      file = TrimBlanks(line.substr(8));
      width = height = width_line = height_line = 0;
      design.clear();
      continue;
    }
    static const std::regex kSummary(
        R"(\d+ (image |directories |)files? .*|\d+ directories scanned)");
    if (std::regex_match(line, kSummary)) continue;  // exiftool's "2 image files read"
    const size_t colon = line.find(':');
    const size_t semicolon = line.find(';');
    const bool tag =
        colon != std::string::npos && (semicolon == std::string::npos || colon < semicolon);
    const std::string key = tag ? KeyOf(line.substr(0, colon)) : "dewarpdata";
    const std::string value = tag ? TrimBlanks(line.substr(colon + 1)) : line;
    if (!tag && line.find(',') == std::string::npos)
      ThrowInputError(where, "neither a DewarpData record nor an exiftool 'Tag : value' line");
    if (key == "dewarpdata" || key == "dewarpdatak6") {
      records.push_back({file, value, where.line, 0, 0, {}});
    } else if (key == "imagewidth" || key == "exifimagewidth") {
      size(value, where, "image width", &width, &width_line);
    } else if (key == "imageheight" || key == "exifimageheight" || key == "imagelength") {
      size(value, where, "image height", &height, &height_line);
    } else if (key == "calibratedfocallength" || key == "calibratedopticalcenterx" ||
               key == "calibratedopticalcentery") {
      design.push_back(TrimBlanks(line.substr(0, colon)) + " = " + value +
                       " px (design value, not used)");
    }
  }
  flush_block();
  return records;
}

}  // namespace

CameraFile ReadDjiDewarpData(const std::string& path, const CameraReadOptions& options) {
  const std::string bytes = ReadTextFile(path);
  int file_width = 0, file_height = 0;
  const bool image = IsJpegOrTiff(bytes);
  std::vector<DewarpRecord> records;
  if (const std::optional<XmpPacket> xmp =
          XmpOfCameraFile(bytes, path, &file_width, &file_height)) {
    // A JPEG's or TIFF's XMP packet, or a sidecar: properties by namespace URI, not by prefix.
    const XmpProperty* data = xmp->Find(xmp_ns::kDji, "DewarpDataK6");
    if (!data) data = xmp->Find(xmp_ns::kDji, "DewarpData");
    if (!data)
      ThrowInputError(
          {path, image ? 0 : 1},
          std::string("no DewarpData of namespace ") + xmp_ns::kDji + " in the file's XMP");
    DewarpRecord r{"", data->value, image ? 0 : data->where.line, 0, 0, {}};
    for (const char* design :
         {"CalibratedFocalLength", "CalibratedOpticalCenterX", "CalibratedOpticalCenterY"})
      if (const XmpProperty* p = xmp->Find(xmp_ns::kDji, design))
        r.design.push_back(std::string(design) + " = " + p->value + " px (design value, not used)");
    const XmpProperty* w = xmp->Find(xmp_ns::kTiff, "ImageWidth");
    const XmpProperty* h = xmp->Find(xmp_ns::kTiff, "ImageLength");
    if (!image && w && h) {
      file_width = static_cast<int>(internal::ParseNumber(w->value, w->where, w->qualified, 1e6));
      file_height = static_cast<int>(internal::ParseNumber(h->value, h->where, h->qualified, 1e6));
    }
    r.width = file_width, r.height = file_height;
    records.push_back(r);
  } else {
    records = TextRecords(path, bytes);
    if (records.empty()) ThrowInputError({path, 1}, "no DewarpData record");
  }
  // Several records: --camera names one (its exiftool file name, its date or its 1-based number);
  // without it, records that are all the same are one camera (said), else the list is an error.
  const DewarpRecord* picked = &records.front();
  std::string ids;
  for (size_t k = 0; k < records.size(); ++k) {
    const DewarpRecord& r = records[k];
    const std::string id = !r.file.empty()         ? r.file
                           : !Date(r.data).empty() ? Date(r.data)
                                                   : std::to_string(k + 1);
    ids += (ids.empty() ? "" : ", ") + std::to_string(k + 1) + " (" + id + ")";
  }
  if (!options.camera_id.empty()) {
    picked = nullptr;
    for (size_t k = 0; k < records.size() && !picked; ++k)
      if (records[k].file == options.camera_id || Date(records[k].data) == options.camera_id ||
          std::to_string(k + 1) == options.camera_id)
        picked = &records[k];
    if (!picked)
      ThrowInputError({path, 1},
                      "no DewarpData record " + options.camera_id + " (records: " + ids + ")");
  } else if (records.size() > 1) {
    for (const DewarpRecord& r : records)
      if (r.data != records.front().data)
        ThrowInputError({path, r.line},
                        "holds " + std::to_string(records.size()) +
                            " different DewarpData records: name one with --camera (" + ids + ")");
  }
  const SourceRef where{path, picked->line};
  CameraFile file;
  if (picked->width == 0 && picked->height == 0 &&
      (options.width_px == 0 || options.height_px == 0))
    ThrowInputError(where, "the file gives no image size: pass --width and --height");
  internal::ResolveFormat(&file, options, where, picked->width, picked->height, 0.0);
  const PixelFrame frame = file.camera.frame;
  file.camera = DjiDewarpDataCamera(picked->data, where, frame.width_px, frame.height_px);
  file.camera.frame = frame;
  file.name = !Date(picked->data).empty() ? Date(picked->data) : "dji";
  file.chosen_by_camera_id = !options.camera_id.empty();
  file.notes = picked->design;
  if (records.size() > 1 && options.camera_id.empty())
    file.notes.push_back(std::to_string(records.size()) +
                         " DewarpData records, all the same: one camera");
  return file;
}

void WriteDjiDewarpData(const std::string& path, const CameraFile& file) {
  using O = OpenCvModel;
  AEROCAL_CHECK(file.camera.model == O::kId) << "not opencv";
  const std::vector<double>& p = file.camera.params;
  const PixelFrame& f = file.camera.frame;
  const bool k6 = p[O::kK4] != 0 || p[O::kK5] != 0 || p[O::kK6] != 0;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  // The record's date survives (our name for a DJI camera is its date).
  if (std::regex_match(file.name, std::regex(R"(\d{4}-\d{2}-\d{2})"))) out << file.name << ";";
  out << n(p[O::kFx]) << "," << n(p[O::kFy]) << "," << n(p[O::kCx] - 0.5 * f.width_px) << ","
      << n(p[O::kCy] - 0.5 * f.height_px) << "," << n(p[O::kK1]) << "," << n(p[O::kK2]) << ","
      << n(p[O::kP1]) << "," << n(p[O::kP2]) << "," << n(p[O::kK3]);
  if (k6) out << "," << n(p[O::kK4]) << "," << n(p[O::kK5]) << "," << n(p[O::kK6]);
  // An XMP sidecar: what a DJI JPEG carries, readable by this reader and by XMP tools.
  WriteFileAtomically(
      path,
      std::string("<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n <rdf:RDF "
                  "xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n"
                  "  <rdf:Description xmlns:drone-dji=\"http://www.dji.com/drone-dji/1.0/\"\n"
                  "    xmlns:tiff=\"http://ns.adobe.com/tiff/1.0/\"\n"
                  "    tiff:ImageWidth=\"") +
          std::to_string(f.width_px) + "\" tiff:ImageLength=\"" + std::to_string(f.height_px) +
          "\"\n    drone-dji:" + (k6 ? "DewarpDataK6" : "DewarpData") + "=\"" + out.str() +
          "\"/>\n </rdf:RDF>\n</x:xmpmeta>\n");
}

}  // namespace aerocal::calib
