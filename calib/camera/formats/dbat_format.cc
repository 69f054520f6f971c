// DBAT camera XML (Börlin & Grussenmeyer's Damped Bundle Adjustment Toolbox; the same parameters
// as Australis / PhotoModeler: c, principal point, K1-K3, P1, P2 in mm): document/cameras/camera
// with <name>, <sensor> W,H mm (or "auto,H": square pixels), <image> W,H px, <cc> (or <focal>),
// <pp> mm from the top-left CORNER with y DOWN, <K>, <P>, <aspect>, <skew>. DBAT's backward model
// 3 is our correction form, so it maps onto brown_fraser_10 exactly:
//   x0 = px - W p / 2, y0 = H p / 2 - py (photo frame: format centre, y up), K and P unchanged.
// `cc` or `pp` of 0 mean "not known": the focal length and the format centre are used. <aspect>
// (DBAT's affinity) is not modelled: an aspect other than 1 is reported as a note. Read with an
// XML parser (comments, CDATA and nesting handled), the camera's DIRECT children only (a <pp>
// inside <std> is a sigma, not the principal point).
#include <cmath>
#include <filesystem>
#include <sstream>

#include <tinyxml2.h>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

struct XmlCamera {
  std::string path;
  const tinyxml2::XMLElement* camera = nullptr;

  const tinyxml2::XMLElement* Child(const char* tag) const { return camera->FirstChildElement(tag); }
  SourceRef Where(const tinyxml2::XMLElement* e) const {
    return {path, e ? e->GetLineNum() : camera->GetLineNum()};
  }
  // Text of <tag> split on commas, trimmed; empty when the tag is absent.
  std::vector<std::string> List(const char* tag) const {
    const tinyxml2::XMLElement* e = Child(tag);
    if (!e || !e->GetText()) return {};
    return SplitCommaList(e->GetText(), {true, true});
  }
  // Numbers of <tag> within [-bound, bound]; at least min_size of them when the tag is required.
  std::vector<double> Numbers(const char* tag, size_t min_size, double bound) const {
    std::vector<double> out;
    for (const auto& s : List(tag)) {
      const auto v = ParseDouble(s);
      if (!v || !(std::abs(*v) <= bound))
        ThrowInputError(Where(Child(tag)), std::string("<") + tag + "> must hold numbers within +-" +
                                               FormatNumber(bound) + " (got '" + s + "')");
      out.push_back(*v);
    }
    if (out.size() < min_size)
      ThrowInputError(Where(Child(tag)), std::string("<") + tag + "> needs " +
                                             std::to_string(min_size) + " values");
    return out;
  }
};

}  // namespace

CameraFile ReadDbatCameraXml(const std::string& path, const CameraReadOptions& options) {
  const std::string text = ReadTextFile(path);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    ThrowInputError({path, doc.ErrorLineNum()}, std::string("invalid XML: ") + doc.ErrorName());
  const tinyxml2::XMLElement* root = doc.RootElement();
  const tinyxml2::XMLElement* cameras = root ? root->FirstChildElement("cameras") : nullptr;
  XmlCamera xml{path, cameras ? cameras->FirstChildElement("camera") : nullptr};
  if (!options.camera_id.empty())
    while (xml.camera && !(xml.List("id").size() == 1 && xml.List("id")[0] == options.camera_id))
      xml.camera = xml.camera->NextSiblingElement("camera");
  if (!xml.camera)
    ThrowInputError({path, root ? root->GetLineNum() : 0},
                    options.camera_id.empty()
                        ? "no <document><cameras><camera> element (not a DBAT camera file)"
                        : "no camera with <id>" + options.camera_id + "</id>");
  CameraFile file;
  const auto name = xml.List("name");
  file.name = name.empty() ? std::filesystem::path(path).stem().string() : name.front();
  const auto image = xml.Numbers("image", 2, 1e6);
  if (!(image[0] >= 1 && image[1] >= 1) || image[0] != std::floor(image[0]) ||
      image[1] != std::floor(image[1]))
    ThrowInputError(xml.Where(xml.Child("image")),
                    "<image> must be two positive integers W,H (px), at most 1e6");
  const int width = static_cast<int>(image[0]), height = static_cast<int>(image[1]);
  const auto sensor = xml.List("sensor");
  if (sensor.size() < 2)
    ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> must be W,H or auto,H (mm)");
  const auto height_mm = ParseDouble(sensor[1]);
  if (!height_mm || !(*height_mm > 0 && *height_mm <= 1000))
    ThrowInputError(xml.Where(xml.Child("sensor")), "<sensor> height must be > 0 and <= 1000 mm");
  const double pixel = *height_mm / height;  // square pixels; "auto" width
  internal::ResolveFormat(&file, options, xml.Where(xml.Child("image")), width, height, pixel);
  const double w_mm = width * pixel, h_mm = *height_mm;
  double c = xml.Child("cc") ? xml.Numbers("cc", 1, 1e4)[0] : 0.0;
  if (c == 0) c = xml.Numbers("focal", 1, 1e4)[0];
  if (!(c > 0))
    ThrowInputError(xml.Where(xml.Child(xml.Child("cc") ? "cc" : "focal")), "<cc>/<focal> must be > 0 mm");
  auto pp = xml.Child("pp") ? xml.Numbers("pp", 2, 1e4) : std::vector<double>{0, 0};
  if (pp[0] == 0 && pp[1] == 0) pp = {w_mm / 2, h_mm / 2};
  file.camera.model = Model::kId;
  file.camera.params.assign(Model::kNumParams, 0.0);
  file.camera.params[Model::kC] = c;
  file.camera.params[Model::kX0] = pp[0] - w_mm / 2;
  file.camera.params[Model::kY0] = h_mm / 2 - pp[1];
  const auto k = xml.Numbers("K", 0, 1.0);
  for (size_t i = 0; i < k.size() && i < 3; ++i) file.camera.params[Model::kK1 + i] = k[i];
  const auto p = xml.Numbers("P", 0, 1.0);
  for (size_t i = 0; i < p.size() && i < 2; ++i) file.camera.params[Model::kP1 + i] = p[i];
  if (xml.Child("aspect")) {
    const double aspect = xml.Numbers("aspect", 1, 10)[0];
    if (aspect != 1.0)
      file.notes.push_back("DBAT aspect " + FormatNumber(aspect) +
                           " not modelled (square pixels from the sensor height)");
  }
  return file;
}

void WriteDbatCameraXml(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == Model::kId) << "not brown_fraser_10";
  internal::RequireZero(file.camera, {"B1", "B2"}, "DBAT");
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& q = file.camera.params;
  const double w_mm = f.width_px * f.pixel_size_mm, h_mm = f.height_px * f.pixel_size_mm;
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<document dbat_camera_version=\"1.0\">\n"
      << "   <cameras>\n      <camera>\n         <id>1</id>\n         <name>" << internal::XmlEscaped(internal::OneLine(file.name))
      << "</name>\n         <unit>mm</unit>\n         <calibrated>yes</calibrated>\n"
      << "         <sensor>" << w_mm << "," << h_mm << "</sensor>\n         <image>" << f.width_px
      << "," << f.height_px << "</image>\n         <aspect>1</aspect>\n         <focal>"
      << q[Model::kC] << "</focal>\n         <model>3</model>\n         <nK>3</nK>\n"
      << "         <nP>2</nP>\n         <cc>" << q[Model::kC] << "</cc>\n         <pp>"
      << q[Model::kX0] + w_mm / 2 << "," << h_mm / 2 - q[Model::kY0] << "</pp>\n"
      << "         <skew>0</skew>\n         <K>" << q[Model::kK1] << "," << q[Model::kK2] << ","
      << q[Model::kK3] << "</K>\n         <P>" << q[Model::kP1] << "," << q[Model::kP2]
      << "</P>\n      </camera>\n   </cameras>\n</document>\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
