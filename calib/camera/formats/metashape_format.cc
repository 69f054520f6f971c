// Agisoft Metashape calibration XML (Tools > Camera Calibration > Export, "Agisoft Camera
// Calibration (*.xml)": <calibration> with <projection>frame</projection>, <width>, <height>, <f>,
// <cx>, <cy>, <b1>, <b2>, <k1>-<k4>, <p1>-<p4> (absent = 0) and, after an adjustment,
// <covariance><params>f cx cy ...</params><coeffs>row-major values</coeffs></covariance>), and
// the cameras/project XML that holds the same <calibration class="adjusted"> inside
// <sensor id="..."> (its size as <resolution width= height=/>, the pixel size as
// <property name="pixel_width">). Parameters in models/metashape.h's units and conventions.
#include <cmath>
#include <functional>
#include <sstream>

#include <tinyxml2.h>

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::calib {
namespace {

using M = MetashapeFrameModel;

const tinyxml2::XMLElement* FindCalibration(const tinyxml2::XMLElement* sensor) {
  const tinyxml2::XMLElement* first = nullptr;
  for (auto* c = sensor->FirstChildElement("calibration"); c; c = c->NextSiblingElement("calibration")) {
    const char* cls = c->Attribute("class");
    if (cls && std::string(cls) == "adjusted") return c;
    if (!first) first = c;
  }
  return first;
}

void CollectSensors(const tinyxml2::XMLElement* e, std::vector<const tinyxml2::XMLElement*>* out) {
  for (auto* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (std::string(c->Name()) == "sensor") out->push_back(c);
    else CollectSensors(c, out);
  }
}

std::vector<std::string> Words(const char* text) {
  std::istringstream in(text ? text : "");
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

}  // namespace

CameraFile ReadMetashapeCalibration(const std::string& path, const CameraReadOptions& options) {
  const std::string text = ReadTextFile(path);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    ThrowInputError({path, doc.ErrorLineNum()}, std::string("invalid XML: ") + doc.ErrorName());
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (!root) ThrowInputError({path, 1}, "empty XML document");
  const auto where = [&](const tinyxml2::XMLElement* e) { return SourceRef{path, e->GetLineNum()}; };
  CameraFile file;
  const tinyxml2::XMLElement* calibration = nullptr;
  const tinyxml2::XMLElement* sensor = nullptr;
  if (std::string(root->Name()) == "calibration") {
    calibration = root;
  } else {
    std::vector<const tinyxml2::XMLElement*> sensors;
    CollectSensors(root, &sensors);
    std::string ids;
    for (const auto* s : sensors) {
      const char* id = s->Attribute("id");
      const std::string sid = id ? id : "";
      ids += (ids.empty() ? "" : ", ") + sid;
      if (sid == options.camera_id || (options.camera_id.empty() && sensors.size() == 1)) sensor = s;
    }
    if (!sensor)
      ThrowInputError(where(root), sensors.empty()
                                       ? "no <calibration> or <sensor> element (not a Metashape "
                                         "calibration file)"
                                       : options.camera_id.empty()
                                             ? "holds " + std::to_string(sensors.size()) +
                                                   " sensors: name one with --camera (" + ids + ")"
                                             : "no sensor id " + options.camera_id + " (sensors: " +
                                                   ids + ")");
    calibration = FindCalibration(sensor);
    if (!calibration) ThrowInputError(where(sensor), "the sensor has no <calibration>");
    const char* label = sensor->Attribute("label");
    file.name = label ? label : "";
  }
  const auto child_text = [&](const tinyxml2::XMLElement* parent, const char* tag) -> const tinyxml2::XMLElement* {
    return parent ? parent->FirstChildElement(tag) : nullptr;
  };
  // The projection: <projection> text (calibration file) or the type attribute (project).
  std::string projection = "frame";
  if (const auto* p = child_text(calibration, "projection"); p && p->GetText()) projection = p->GetText();
  else if (const char* type = calibration->Attribute("type")) projection = type;
  if (projection != "frame")
    ThrowInputError(where(calibration), "projection '" + projection +
                                            "' is not supported (only Metashape's frame camera)");
  int width = 0, height = 0;
  const auto integer = [&](const tinyxml2::XMLElement* e, const char* text, const char* what) {
    const double v = internal::ParseNumber(text ? text : "", where(e), what, 1e6);
    if (!(v >= 1) || v != std::floor(v))
      ThrowInputError(where(e), std::string(what) + " must be a positive integer");
    return static_cast<int>(v);
  };
  if (const auto* w = child_text(calibration, "width")) width = integer(w, w->GetText(), "<width>");
  if (const auto* h = child_text(calibration, "height")) height = integer(h, h->GetText(), "<height>");
  for (const auto* holder : {calibration, sensor})
    if (const auto* r = child_text(holder, "resolution"); r && width == 0) {
      width = integer(r, r->Attribute("width"), "resolution width");
      height = integer(r, r->Attribute("height"), "resolution height");
    }
  double pixel_size = 0;
  if (sensor)
    for (auto* p = sensor->FirstChildElement("property"); p; p = p->NextSiblingElement("property"))
      if (p->Attribute("name") && std::string(p->Attribute("name")) == "pixel_width" && p->Attribute("value"))
        pixel_size = internal::ParseNumber(p->Attribute("value"), where(p), "pixel_width", 1.0);
  file.camera.model = M::kId;
  file.camera.params.assign(M::kNumParams, 0.0);
  for (int i = 0; i < M::kNumParams; ++i) {
    const std::string tag(M::kParams[i].name);
    if (const auto* e = child_text(calibration, tag.c_str()))
      file.camera.params[i] = internal::ParseNumber(e->GetText() ? e->GetText() : "", where(e),
                                                    "<" + tag + ">", 1e7);
  }
  if (!child_text(calibration, "f")) ThrowInputError(where(calibration), "missing <f>");
  if (!(file.camera.params[M::kF] > 0))
    ThrowInputError(where(child_text(calibration, "f")), "<f> must be > 0 px");
  if (const auto* cov = child_text(calibration, "covariance")) {
    const auto* params = child_text(cov, "params");
    const auto* coeffs = child_text(cov, "coeffs");
    if (!params || !coeffs) ThrowInputError(where(cov), "<covariance> needs <params> and <coeffs>");
    const std::vector<std::string> names = Words(params->GetText());
    const std::vector<std::string> values = Words(coeffs->GetText());
    if (values.size() != names.size() * names.size())
      ThrowInputError(where(coeffs), "<coeffs> must hold " + std::to_string(names.size()) + "^2 = " +
                                         std::to_string(names.size() * names.size()) +
                                         " values (got " + std::to_string(values.size()) + ")");
    std::vector<int> index;
    for (const std::string& n : names) {
      const int k = IndexOfParam(M::kParams, n);
      if (k < 0) ThrowInputError(where(params), "unknown parameter '" + n + "' in <params>");
      index.push_back(k);
    }
    Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(M::kNumParams, M::kNumParams);
    for (size_t r = 0; r < names.size(); ++r)
      for (size_t c = 0; c < names.size(); ++c)
        covariance(index[r], index[c]) =
            internal::ParseNumber(values[r * names.size() + c], where(coeffs), "<coeffs>", 1e20);
    for (size_t r = 0; r < names.size(); ++r)
      if (!(covariance(index[r], index[r]) >= 0))
        ThrowInputError(where(coeffs), "negative variance of " + names[r]);
    file.covariance = covariance;
    file.notes.push_back("covariance of " + std::to_string(names.size()) + " parameters read");
  }
  internal::ResolveFormat(&file, options, where(calibration), width, height, pixel_size);
  return file;
}

void WriteMetashapeCalibration(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == M::kId) << "not metashape_frame";
  std::ostringstream out;
  out.precision(17);
  const std::vector<double>& p = file.camera.params;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<calibration>\n"
      << "  <projection>frame</projection>\n"
      << "  <width>" << file.camera.frame.width_px << "</width>\n"
      << "  <height>" << file.camera.frame.height_px << "</height>\n";
  std::vector<int> written;
  for (int i = 0; i < M::kNumParams; ++i) {
    // f, cx, cy always; the others where they are not 0 (as Metashape writes them).
    if (i > M::kCy && p[i] == 0.0 && !(file.covariance && (*file.covariance)(i, i) > 0)) continue;
    out << "  <" << M::kParams[i].name << ">" << p[i] << "</" << M::kParams[i].name << ">\n";
    written.push_back(i);
  }
  if (file.covariance) {
    std::vector<int> with;
    for (int i : written)
      if ((*file.covariance)(i, i) > 0) with.push_back(i);
    out << "  <covariance>\n    <params>";
    for (size_t k = 0; k < with.size(); ++k) out << (k ? " " : "") << M::kParams[with[k]].name;
    out << "</params>\n    <coeffs>";
    for (size_t r = 0; r < with.size(); ++r)
      for (size_t c = 0; c < with.size(); ++c)
        out << (r + c ? " " : "") << (*file.covariance)(with[r], with[c]);
    out << "</coeffs>\n  </covariance>\n";
  }
  out << "</calibration>\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
