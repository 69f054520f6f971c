// DBAT camera XML (Börlin & Grussenmeyer's Damped Bundle Adjustment Toolbox; the same parameters
// as Australis / PhotoModeler: c, principal point, K1-K3, P1, P2 in mm): document/cameras/camera
// with <name>, <sensor> W,H mm (or "auto,H": square pixels), <image> W,H px, <cc> (or <focal>),
// <pp> mm from the top-left CORNER with y DOWN, <K>, <P>, <aspect>, <skew>. DBAT's backward model
// 3 is our correction form, so it maps onto brown_fraser_10 exactly:
//   x0 = px - W p / 2, y0 = H p / 2 - py (photo frame: format centre, y up), K and P unchanged.
// `cc` or `pp` of 0 mean "not known": the focal length and the format centre are used (said).
// DBAT's pixel aspect (the sensor width over the image width against the pixel height, or
// 2 - <aspect> with an "auto" width; the report's `as` = 1 - aspect) scales DBAT's x: read as
// B1 = s - 1 with x0 = px / s - W p / 2; not exact (DBAT's K, P act on the scaled x), the
// difference measured over the format and said. A fragment (<cameras> or <camera> without
// <document>) is read too; several cameras need --camera ID.
// Also DBAT's text report (report.txt: "Cameras:" ... "Camera1 (simple)", then per parameter a
// title line and "Value:" / "Deviation:" lines: Camera Constant, px, py, Format width/height,
// K1-K3, P1, P2, as (off-unit aspect: pixel width = pixel height (1 + as)), sk, Image
// width/height): the same mapping, 6 significant digits as printed, the deviations as a diagonal
// covariance; a non-zero skew is an error (not modelled). --camera CameraN picks one of several.
// Read with an XML parser (comments, CDATA and nesting handled), the camera's DIRECT children only
// (a <pp> inside <std> is a sigma, not the principal point).
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <cmath>
#include <filesystem>
#include <sstream>
#include <tinyxml2.h>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

struct XmlCamera {
  std::string path;
  const tinyxml2::XMLElement* camera = nullptr;

  SourceRef Where(const tinyxml2::XMLElement* e) const {
    return {path, e ? e->GetLineNum() : camera->GetLineNum()};
  }
  // The one <tag> of the camera (nullptr: none); a second one is an error, not the first taken.
  const tinyxml2::XMLElement* Child(const char* tag) const {
    const tinyxml2::XMLElement* e = camera->FirstChildElement(tag);
    if (const tinyxml2::XMLElement* again = e ? e->NextSiblingElement(tag) : nullptr)
      ThrowInputError(Where(again),
                      std::string("<") + tag + "> occurs twice in <camera> (first on line " +
                          std::to_string(e->GetLineNum()) + ")");
    return e;
  }
  // Text of <tag> split on commas, trimmed; empty when the tag is absent. A tag present but empty
  // is an error (not "no values": an empty <K> is no statement of zero distortion).
  std::vector<std::string> List(const char* tag) const {
    const tinyxml2::XMLElement* e = Child(tag);
    if (!e) return {};
    if (!e->GetText()) ThrowInputError(Where(e), std::string("<") + tag + "> is empty");
    return SplitCommaList(e->GetText(), {true, true});
  }
  // Numbers of <tag> within [-bound, bound]; at least min_size of them when the tag is required.
  std::vector<double> Numbers(const char* tag, size_t min_size, double bound) const {
    std::vector<double> out;
    for (const auto& s : List(tag)) {
      const auto v = ParseDouble(s);
      if (!v || !(std::abs(*v) <= bound))
        ThrowInputError(Where(Child(tag)),
                        std::string("<") + tag + "> must hold numbers within +-" +
                            FormatNumber(bound) + " (got '" + s + "')");
      out.push_back(*v);
    }
    if (out.size() < min_size)
      ThrowInputError(Where(Child(tag)),
                      std::string("<") + tag + "> needs " + std::to_string(min_size) + " values");
    return out;
  }
};

// The camera the options name among the document's: a whole file (<document><cameras><camera>) or
// a fragment (<cameras> or one <camera>); several cameras need --camera ID.
XmlCamera FindCamera(const std::string& path,
                     const tinyxml2::XMLElement* root,
                     const CameraReadOptions& options) {
  const std::string root_name = root ? root->Name() : "";
  const tinyxml2::XMLElement* cameras = root_name == "cameras" ? root
                                        : root                 ? root->FirstChildElement("cameras")
                                                               : nullptr;
  XmlCamera xml{path,
                root_name == "camera" ? root
                : cameras             ? cameras->FirstChildElement("camera")
                                      : nullptr};
  std::string ids;
  int count = 0;
  for (XmlCamera c = xml; c.camera; c.camera = c.camera->NextSiblingElement("camera"), ++count)
    ids += (ids.empty() ? "" : ", ") + (c.List("id").empty() ? std::string("?") : c.List("id")[0]);
  if (!options.camera_id.empty()) {
    while (xml.camera && !(xml.List("id").size() == 1 && xml.List("id")[0] == options.camera_id))
      xml.camera = xml.camera->NextSiblingElement("camera");
  } else if (count > 1) {
    ThrowInputError(
        {path, root->GetLineNum()},
        "holds " + std::to_string(count) + " cameras: name one with --camera (" + ids + ")");
  }
  if (!xml.camera)
    ThrowInputError(
        {path, root ? root->GetLineNum() : 0},
        options.camera_id.empty()
            ? "no <document><cameras><camera> element (not a DBAT camera file)"
            : "no camera with <id>" + options.camera_id + "</id> (cameras: " + ids + ")");
  return xml;
}

// The format in mm and DBAT's pixel aspect s (x scale: pixel width over pixel height).
struct DbatSensor {
  double w_mm = 0, h_mm = 0, s = 1.0;
};

// <image> W,H px and <sensor> W,H mm (or auto,H) into the file's format (our pixel: the pixel
// height); the aspect from the sensor width, or 1 + as = 2 - <aspect> where the width is "auto"
// (DBAT's report: pixel width = pixel height (1 + as), the XML's aspect = 1 - as).
DbatSensor ReadFormat(const XmlCamera& xml, const CameraReadOptions& options, CameraFile* file) {
  const auto image = xml.Numbers("image", 2, 1e6);
  if (!(image[0] >= 1 && image[1] >= 1) || image[0] != std::floor(image[0]) ||
      image[1] != std::floor(image[1]))
    ThrowInputError(xml.Where(xml.Child("image")),
                    "<image> must be two positive integers W,H (px), at most 1e6");
  const int width = static_cast<int>(image[0]), height = static_cast<int>(image[1]);
  const auto sensor = xml.List("sensor");
  if (sensor.size() != 2)
    ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> must be W,H or auto,H (mm)");
  const auto height_mm = ParseDouble(sensor[1]);
  if (!height_mm || !(*height_mm > 0 && *height_mm <= 1000))
    ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> height must be > 0 and <= 1000 mm");
  const double pixel = *height_mm / height;  // our pixel: the pixel height
  internal::ResolveFormat(file, options, xml.Where(xml.Child("image")), width, height, pixel);
  DbatSensor f{width * pixel, *height_mm, 1.0};
  if (sensor[0] != "auto") {
    const auto sensor_w = ParseDouble(sensor[0]);
    if (!sensor_w || !(*sensor_w > 0 && *sensor_w <= 1000))
      ThrowInputError(xml.Where(xml.Child("sensor")),
                      "<sensor> width must be > 0 and <= 1000 mm (or auto)");
    f.s = (*sensor_w / width) / pixel;
  }
  if (xml.Child("aspect")) {
    const double aspect = xml.Numbers("aspect", 1, 10)[0];
    if (!(aspect > 0)) ThrowInputError(xml.Where(xml.Child("aspect")), "<aspect> must be > 0");
    if (sensor[0] == "auto")
      f.s = 2.0 - aspect;
    else if (std::abs(f.s - (2.0 - aspect)) > 1e-6)
      ThrowInputError(xml.Where(xml.Child("aspect")),
                      "<aspect> " + FormatNumber(aspect) +
                          " contradicts the sensor width (pixel "
                          "width / height " +
                          FormatNumber(f.s) + ")");
  }
  return f;
}

// <cc> (or <focal>), <pp>, <K>, <P> into brown_fraser_10: x0 = px / s - W p / 2, y0 = H p / 2 -
// py, B1 = s - 1 (not exact where s != 1: the difference over the format said in a note).
void ReadInterior(const XmlCamera& xml, const DbatSensor& f, CameraFile* file) {
  double c = xml.Child("cc") ? xml.Numbers("cc", 1, 1e4)[0] : 0.0;
  if (c == 0) c = xml.Numbers("focal", 1, 1e4)[0];
  if (!(c > 0))
    ThrowInputError(xml.Where(xml.Child(xml.Child("cc") ? "cc" : "focal")),
                    "<cc>/<focal> must be > 0 mm");
  auto pp = xml.Child("pp") ? xml.Numbers("pp", 2, 1e4) : std::vector<double>{0, 0};
  if (pp[0] == 0 && pp[1] == 0) {
    pp = {f.s * f.w_mm / 2, f.h_mm / 2};
    file->notes.push_back("<pp> 0,0 (DBAT: not known): the format centre");
  }
  std::vector<double>& params = file->camera.params;
  file->camera.model = Model::kId;
  params.assign(Model::kNumParams, 0.0);
  params[Model::kC] = c;
  params[Model::kX0] = pp[0] / f.s - f.w_mm / 2;
  params[Model::kY0] = f.h_mm / 2 - pp[1];
  params[Model::kB1] = f.s - 1.0;
  const auto k = xml.Numbers("K", 0, 1.0);
  for (size_t i = 0; i < k.size() && i < 3; ++i) params[Model::kK1 + i] = k[i];
  const auto p = xml.Numbers("P", 0, 1.0);
  for (size_t i = 0; i < p.size() && i < 2; ++i) params[Model::kP1 + i] = p[i];
  if (f.s != 1.0)
    file->notes.push_back("DBAT pixel aspect (width / height " + FormatNumber(f.s) +
                          ") read as B1 = " + FormatNumber(f.s - 1.0) + ": not exact, " +
                          FormatNumber(internal::AspectAsB1ResidualPx(file->camera, f.s), 3) +
                          " px max over the format (DBAT's K, P act on the scaled x)");
}

}  // namespace

bool IsDbatReport(const std::string& head) {
  return head.find("Camera Constant:") != std::string::npos &&
         head.find("px - principal point x:") != std::string::npos;
}

CameraFile ReadDbatCameraXml(const std::string& path, const CameraReadOptions& options) {
  const std::string text = ReadTextFile(path);
  if (IsDbatReport(text))
    return internal::ReadReportCamera(path, SplitLines(text), options, "DBAT");
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    ThrowInputError({path, doc.ErrorLineNum()}, std::string("invalid XML: ") + doc.ErrorName());
  const XmlCamera xml = FindCamera(path, doc.RootElement(), options);
  CameraFile file;
  const auto name = xml.List("name");
  file.name = name.empty() ? std::filesystem::path(path).stem().string() : name.front();
  file.chosen_by_camera_id = !options.camera_id.empty();
  ReadInterior(xml, ReadFormat(xml, options, &file), &file);
  return file;
}

void WriteDbatCameraXml(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == Model::kId) << "not brown_fraser_10";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& q = file.camera.params;
  // B1 as DBAT's pixel aspect (the reader's rule backwards): sensor width and pp x scaled.
  const double s = 1.0 + q[Model::kB1];
  const double w_mm = f.width_px * f.pixel_size_mm * s, h_mm = f.height_px * f.pixel_size_mm;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<document dbat_camera_version=\"1.0\">\n"
      << "   <cameras>\n      <camera>\n         <id>1</id>\n         <name>"
      << internal::XmlEscaped(internal::OneLine(file.name))
      << "</name>\n         <unit>mm</unit>\n         <calibrated>yes</calibrated>\n"
      << "         <sensor>" << n(w_mm) << "," << n(h_mm) << "</sensor>\n         <image>"
      << f.width_px << "," << f.height_px << "</image>\n         <aspect>" << n(2.0 - s)
      << "</aspect>\n         <focal>" << n(q[Model::kC]) << "</focal>\n         <model>3</model>\n"
      << "         <nK>3</nK>\n         <nP>2</nP>\n         <cc>" << n(q[Model::kC])
      << "</cc>\n         <pp>" << n(s * (q[Model::kX0] + f.width_px * f.pixel_size_mm / 2)) << ","
      << n(h_mm / 2 - q[Model::kY0]) << "</pp>\n         <skew>0</skew>\n         <K>"
      << n(q[Model::kK1]) << "," << n(q[Model::kK2]) << "," << n(q[Model::kK3])
      << "</K>\n         <P>" << n(q[Model::kP1]) << "," << n(q[Model::kP2])
      << "</P>\n      </camera>\n   </cameras>\n</document>\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
