// Agisoft Metashape / PhotoScan camera calibration, in every form the programs write it:
// - the calibration export (Tools > Camera Calibration > Export, "Agisoft Camera Calibration
//   (*.xml)"): <calibration> with <projection>frame</projection>, <width>, <height>, Metashape
//   >= 1.3 <f>, <cx>, <cy> (offsets from the image centre), <b1>, <b2>, <k1>-<k4>, <p1>-<p4>
//   (absent = 0), and after an adjustment <covariance><params>f cx cy
//   ...</params><coeffs>row-major</coeffs>;
// - PhotoScan <= 1.2's form of the same element: <fx>, <fy>, ABSOLUTE <cx>, <cy> (pixels from the
//   image corner), <skew>, <k1>-<k4>, <p1>, <p2> (no <f>). As Metashape's model it is
//   f = fy, b1 = fx - fy, b2 = skew, cx - W / 2, cy - H / 2 (the corner origin and the pixel
//   centres are those of Metashape's Appendix C; a <covariance> of fx fy ... is carried through the
//   same linear map); said in a note;
// - a <sensor id label> holding <calibration class="adjusted"> and/or class="initial" (the adjusted
//   one is read, the choice said), its size as <resolution width height/>, the pixel size as
//   <property name="pixel_width"/"pixel_height">, a <covariance> inside the calibration or beside
//   it in the sensor (Metashape 1.5+ cameras export, EasyIDP's tests), on its own or inside
//   <sensors>, <chunk>, <document> at any depth (cameras export, a project's doc.xml);
// - a project: a .psz (or .zip) archive holding doc.xml (and, in Metashape, each chunk's
//   <chunk path="0/chunk.zip"> whose doc.xml holds the sensors), or a .psx file whose chunks are
//   <name>.files/<path> archives. The archive is read in place (zip_archive.h).
// Several sensors: --camera ID (a sensor id, or CHUNK/ID when several chunks hold sensors); an
// unknown or missing id lists the ids and labels. Rules of issue 37: a duplicated element, a
// duplicated calibration class, an empty or non-finite number, a pixel size <= 0 are errors
// naming the file (or archive member) and line. Parameters in models/metashape.h's conventions.
#include "calib/camera/formats/camera_formats.h"
#include "calib/camera/formats/zip_archive.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <cmath>
#include <filesystem>
#include <functional>
#include <sstream>
#include <tinyxml2.h>
#include <utility>

namespace aerocal::calib {
namespace {

using M = MetashapeFrameModel;
using tinyxml2::XMLElement;

// One parsed XML text and the name its messages use (a path, or ARCHIVE!MEMBER).
struct XmlSource {
  std::string where;
  std::unique_ptr<tinyxml2::XMLDocument> doc = std::make_unique<tinyxml2::XMLDocument>();
  SourceRef At(const XMLElement* e) const { return {where, e ? e->GetLineNum() : 1}; }
};

XmlSource Parse(const std::string& text, const std::string& where) {
  XmlSource source;
  source.where = where;
  if (source.doc->Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    ThrowInputError({where, source.doc->ErrorLineNum()},
                    std::string("invalid XML: ") + source.doc->ErrorName());
  if (!source.doc->RootElement()) ThrowInputError({where, 1}, "empty XML document");
  return source;
}

// The only child `tag` of `parent` (nullptr when absent); a second one is an error.
const XMLElement* Only(const XmlSource& s, const XMLElement* parent, const char* tag) {
  if (!parent) return nullptr;
  const XMLElement* first = parent->FirstChildElement(tag);
  if (first && first->NextSiblingElement(tag))
    ThrowInputError(s.At(first->NextSiblingElement(tag)),
                    std::string("<") + tag + "> occurs twice in <" + parent->Name() + ">");
  return first;
}

// The XML documents of a file: itself, or the doc.xml of an archive, plus the chunk documents a
// project refers to (<chunk path="...">: inside the same archive, or in a .psx's .files folder).
std::vector<XmlSource> LoadDocuments(const std::string& path) {
  const std::string bytes = ReadTextFile(path);
  std::vector<XmlSource> docs;
  const bool archive = internal::LooksLikeZip(bytes);
  docs.push_back(archive ? Parse(internal::ReadZipMember(bytes, "doc.xml", path), path + "!doc.xml")
                         : Parse(bytes, path));
  std::vector<std::pair<std::string, int>> chunk_paths;
  const XMLElement* root = docs[0].doc->RootElement();
  if (std::string(root->Name()) == "document")
    if (const XMLElement* chunks = Only(docs[0], root, "chunks"))
      for (auto* c = chunks->FirstChildElement("chunk"); c; c = c->NextSiblingElement("chunk"))
        if (const char* p = c->Attribute("path")) chunk_paths.emplace_back(p, c->GetLineNum());
  for (const auto& [chunk_path, line] : chunk_paths) {
    std::string chunk_bytes, where;
    if (archive) {
      chunk_bytes = internal::ReadZipMember(bytes, chunk_path, path);
      where = path + "!" + chunk_path;
    } else {
      const std::filesystem::path p(path);
      const std::filesystem::path file =
          p.parent_path() / (p.stem().string() + ".files") / chunk_path;
      if (!std::filesystem::is_regular_file(file))
        ThrowInputError({path, line},
                        "the project's chunk " + file.string() +
                            " is missing (a .psx needs its .files folder)");
      chunk_bytes = ReadTextFile(file.string());
      where = file.string();
    }
    if (internal::LooksLikeZip(chunk_bytes)) {
      docs.push_back(
          Parse(internal::ReadZipMember(chunk_bytes, "doc.xml", where), where + "!doc.xml"));
    } else {
      docs.push_back(Parse(chunk_bytes, where));
    }
  }
  return docs;
}

void CollectSensors(const XMLElement* e, std::vector<const XMLElement*>* out) {
  if (std::string(e->Name()) == "sensor") {
    out->push_back(e);
    return;
  }
  for (auto* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) CollectSensors(c, out);
}

struct Chosen {
  const XmlSource* source = nullptr;
  const XMLElement* sensor = nullptr;  // nullptr: a bare <calibration> file
  const XMLElement* calibration = nullptr;
};

// The sensor --camera names (or the only one) of all documents.
Chosen ChooseSensor(const std::vector<XmlSource>& docs,
                    const std::string& path,
                    const CameraReadOptions& options) {
  struct Entry {
    const XmlSource* source;
    const XMLElement* sensor;
    std::string key;
  };
  std::vector<Entry> entries;
  int documents_with_sensors = 0;
  for (const XmlSource& d : docs) {
    std::vector<const XMLElement*> sensors;
    CollectSensors(d.doc->RootElement(), &sensors);
    documents_with_sensors += !sensors.empty();
    for (const XMLElement* s : sensors)
      entries.push_back({&d, s, s->Attribute("id") ? s->Attribute("id") : ""});
  }
  if (documents_with_sensors > 1)
    for (Entry& e : entries) {
      int k = 0;
      for (const XmlSource& d : docs) {
        if (&d == e.source) break;
        ++k;
      }
      e.key = std::to_string(k) + "/" + e.key;
    }
  if (entries.empty()) {
    const XMLElement* root = docs[0].doc->RootElement();
    if (std::string(root->Name()) == "calibration") return {&docs[0], nullptr, root};
    ThrowInputError(docs[0].At(root),
                    "no <calibration> or <sensor> element (not a Metashape "
                    "calibration, cameras or project file)");
  }
  std::string ids;
  const Entry* found = nullptr;
  for (const Entry& e : entries) {
    const char* label = e.sensor->Attribute("label");
    ids += (ids.empty() ? "" : ", ") + e.key + (label ? std::string(" (") + label + ")" : "");
    if (e.key == options.camera_id || (options.camera_id.empty() && entries.size() == 1)) {
      if (found) ThrowInputError(e.source->At(e.sensor), "sensor id " + e.key + " occurs twice");
      found = &e;
    }
  }
  if (!found)
    ThrowInputError({path, 1},
                    options.camera_id.empty()
                        ? "holds " + std::to_string(entries.size()) +
                              " sensors: name one with --camera (" + ids + ")"
                        : "no sensor id " + options.camera_id + " (sensors: " + ids + ")");
  return {found->source, found->sensor, nullptr};
}

// The adjusted calibration of a sensor, else the initial one (said).
const XMLElement* ChooseCalibration(const XmlSource& s,
                                    const XMLElement* sensor,
                                    std::vector<std::string>* notes) {
  const XMLElement *adjusted = nullptr, *initial = nullptr, *other = nullptr;
  for (auto* c = sensor->FirstChildElement("calibration"); c;
       c = c->NextSiblingElement("calibration")) {
    const std::string cls = c->Attribute("class") ? c->Attribute("class") : "";
    const XMLElement*& slot = cls == "adjusted" ? adjusted : cls == "initial" ? initial : other;
    if (slot)
      ThrowInputError(s.At(c),
                      "a second <calibration" + (cls.empty() ? "" : " class=\"" + cls + "\"") +
                          "> in the sensor");
    slot = c;
  }
  if (adjusted && initial)
    notes->push_back("the adjusted calibration read (the sensor also holds the initial one)");
  if (!adjusted && initial)
    notes->push_back("no adjusted calibration: the INITIAL (pre-alignment) calibration read");
  const XMLElement* chosen = adjusted ? adjusted : initial ? initial : other;
  if (!chosen) ThrowInputError(s.At(sensor), "the sensor has no <calibration>");
  return chosen;
}

std::vector<std::string> Words(const char* text) {
  std::istringstream in(text ? text : "");
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// The projection: <projection> text (calibration file) or the type attribute (project); only
// Metashape's frame camera is read.
void CheckFrameProjection(const XmlSource& s, const XMLElement* calibration) {
  std::string projection = "frame";
  if (const auto* p = Only(s, calibration, "projection"))
    projection = p->GetText() ? p->GetText() : "";
  else if (const char* type = calibration->Attribute("type"))
    projection = type;
  if (projection != "frame")
    ThrowInputError(
        s.At(calibration),
        "projection '" + projection + "' is not supported (only Metashape's frame camera)");
}

int PositiveInteger(const XmlSource& s, const XMLElement* e, const char* text, const char* what) {
  const double v = internal::ParseNumber(text ? text : "", s.At(e), what, 1e6);
  if (!(v >= 1) || v != std::floor(v))
    ThrowInputError(s.At(e), std::string(what) + " must be a positive integer");
  return static_cast<int>(v);
}

// The image size: <width>, <height> of the calibration and/or <resolution> of the calibration or
// the sensor, which must agree; 0 x 0 when none is given.
std::pair<int, int> ReadImageSize(const XmlSource& s,
                                  const XMLElement* calibration,
                                  const XMLElement* sensor) {
  int width = 0, height = 0;
  if (const auto* w = Only(s, calibration, "width"))
    width = PositiveInteger(s, w, w->GetText(), "<width>");
  if (const auto* h = Only(s, calibration, "height"))
    height = PositiveInteger(s, h, h->GetText(), "<height>");
  for (const auto* holder : {calibration, sensor})
    if (const auto* r = Only(s, holder, "resolution")) {
      const int w = PositiveInteger(s, r, r->Attribute("width"), "resolution width");
      const int h = PositiveInteger(s, r, r->Attribute("height"), "resolution height");
      if (width != 0 && (w != width || h != height))
        ThrowInputError(s.At(r),
                        "resolution " + std::to_string(w) + " x " + std::to_string(h) +
                            " contradicts the calibration's " + std::to_string(width) + " x " +
                            std::to_string(height));
      width = w, height = h;
    }
  return {width, height};
}

// The sensor's pixel size (mm): its pixel_width property (pixel_height only compared with it);
// 0 when not given.
double ReadPixelSize(const XmlSource& s,
                     const XMLElement* sensor,
                     std::vector<std::string>* notes) {
  if (!sensor) return 0.0;
  double pixel_size = 0, pixel_height = 0;
  for (auto* p = sensor->FirstChildElement("property"); p; p = p->NextSiblingElement("property")) {
    const std::string name = p->Attribute("name") ? p->Attribute("name") : "";
    if (name != "pixel_width" && name != "pixel_height") continue;
    const double v = internal::ParseNumber(
        p->Attribute("value") ? p->Attribute("value") : "", s.At(p), name, 1.0);
    if (!(v > 0)) ThrowInputError(s.At(p), name + " must be > 0 mm");
    double& slot = name == "pixel_width" ? pixel_size : pixel_height;
    if (slot) ThrowInputError(s.At(p), name + " occurs twice");
    slot = v;
  }
  if (pixel_height > 0 && pixel_size > 0 && std::abs(pixel_height - pixel_size) > 1e-9 * pixel_size)
    notes->push_back("pixel_height " + FormatNumber(pixel_height) +
                     " mm differs from pixel_width " + FormatNumber(pixel_size) +
                     " mm: pixel_width used (the rest is b1)");
  if (pixel_size == 0 && pixel_height > 0)
    ThrowInputError(s.At(sensor), "the sensor gives pixel_height but no pixel_width");
  return pixel_size;
}

double ReadNumber(const XmlSource& s, const XMLElement* e, const std::string& what) {
  return internal::ParseNumber(e->GetText() ? e->GetText() : "", s.At(e), what, 1e7);
}

// The parameters into file->camera (Metashape's model): Metashape >= 1.3's <f> and offsets, or
// PhotoScan <= 1.2's <fx>, <fy>, absolute <cx>, <cy>, <skew> mapped to it (f = fy, b1 = fx - fy,
// b2 = skew, cx - W/2, cy - H/2; said in a note). Returns true for PhotoScan's form.
bool ReadParameters(
    const XmlSource& s, const XMLElement* calibration, int width, int height, CameraFile* file) {
  const XMLElement* f = Only(s, calibration, "f");
  const XMLElement* fx = Only(s, calibration, "fx");
  const XMLElement* fy = Only(s, calibration, "fy");
  const bool old_form = fx || fy;
  if (f && old_form)
    ThrowInputError(s.At(fx ? fx : fy), "both <f> and <fx>/<fy>: not one of Metashape's forms");
  if (!f && !(fx && fy))
    ThrowInputError(s.At(calibration), "missing <f> (or PhotoScan's <fx> and <fy>)");
  file->camera.model = M::kId;
  file->camera.params.assign(M::kNumParams, 0.0);
  std::vector<double>& p = file->camera.params;
  for (int i = 0; i < M::kNumParams; ++i) {
    const std::string tag(M::kParams[i].name);
    if (i == M::kF || (old_form && (i == M::kB1 || i == M::kB2))) continue;
    if (const auto* e = Only(s, calibration, tag.c_str())) p[i] = ReadNumber(s, e, "<" + tag + ">");
  }
  if (!old_form) {
    p[M::kF] = ReadNumber(s, f, "<f>");
    if (!(p[M::kF] > 0)) ThrowInputError(s.At(f), "<f> must be > 0 px");
    return false;
  }
  if (width == 0)
    ThrowInputError(s.At(calibration), "PhotoScan's absolute cx, cy need the <resolution>");
  const double fx_px = ReadNumber(s, fx, "<fx>"), fy_px = ReadNumber(s, fy, "<fy>");
  if (!(fx_px > 0 && fy_px > 0)) ThrowInputError(s.At(fx), "<fx>, <fy> must be > 0 px");
  p[M::kF] = fy_px;
  p[M::kB1] = fx_px - fy_px;
  if (const auto* skew = Only(s, calibration, "skew")) p[M::kB2] = ReadNumber(s, skew, "<skew>");
  p[M::kCx] -= 0.5 * width;
  p[M::kCy] -= 0.5 * height;
  for (const char* tag : {"b1", "b2", "p3", "p4"})
    if (Only(s, calibration, tag))
      ThrowInputError(s.At(Only(s, calibration, tag)),
                      std::string("<") + tag + "> beside <fx>: not one of Metashape's forms");
  file->notes.push_back(
      "PhotoScan <= 1.2 calibration (fx, fy, absolute cx, cy, skew) read as "
      "f = fy, b1 = fx - fy, b2 = skew, cx - W/2, cy - H/2");
  return true;
}

// The covariance's element: in the calibration, or beside it in the sensor (it belongs to the
// adjusted calibration: not read with the initial one, said in a note); nullptr when none.
const XMLElement* FindCovariance(const XmlSource& s,
                                 const XMLElement* calibration,
                                 const XMLElement* sensor,
                                 std::vector<std::string>* notes) {
  if (const XMLElement* cov = Only(s, calibration, "covariance")) return cov;
  if (!sensor || !Only(s, sensor, "covariance")) return nullptr;
  if (calibration->Attribute("class") &&
      std::string(calibration->Attribute("class")) == "initial") {
    notes->push_back(
        "the sensor's covariance (of the adjusted calibration) not read with the initial one");
    return nullptr;
  }
  return Only(s, sensor, "covariance");
}

// The linear map from the file's parameter names to Metashape's model (identity but for
// PhotoScan's fx, fy, skew: f = fy, b1 = fx - fy, b2 = skew); a name twice or unknown: InputError.
Eigen::MatrixXd ParamsFromFileNames(const XmlSource& s,
                                    const XMLElement* params,
                                    const std::vector<std::string>& names,
                                    bool old_form) {
  const size_t n = names.size();
  Eigen::MatrixXd map = Eigen::MatrixXd::Zero(M::kNumParams, n);
  for (size_t j = 0; j < n; ++j) {
    for (size_t i = 0; i < j; ++i)
      if (names[i] == names[j])
        ThrowInputError(s.At(params), "'" + names[j] + "' twice in <params>");
    if (old_form && names[j] == "fx")
      map(M::kB1, j) = 1;
    else if (old_form && names[j] == "fy")
      map(M::kF, j) = 1, map(M::kB1, j) = -1;
    else if (old_form && names[j] == "skew")
      map(M::kB2, j) = 1;
    else if (const int k = IndexOfParam(M::kParams, names[j]); k >= 0)
      map(k, j) = 1;
    else
      ThrowInputError(s.At(params), "unknown parameter '" + names[j] + "' in <params>");
  }
  return map;
}

// <covariance><params>names</params><coeffs>row-major</coeffs> carried into the model's order.
void ReadCovariance(const XmlSource& s, const XMLElement* cov, bool old_form, CameraFile* file) {
  const auto* params = Only(s, cov, "params");
  const auto* coeffs = Only(s, cov, "coeffs");
  if (!params || !coeffs) ThrowInputError(s.At(cov), "<covariance> needs <params> and <coeffs>");
  const std::vector<std::string> names = Words(params->GetText());
  const std::vector<std::string> values = Words(coeffs->GetText());
  const size_t n = names.size();
  if (n == 0 || values.size() != n * n)
    ThrowInputError(s.At(coeffs),
                    "<coeffs> must hold " + std::to_string(n) + "^2 = " + std::to_string(n * n) +
                        " values (got " + std::to_string(values.size()) + ")");
  const Eigen::MatrixXd map = ParamsFromFileNames(s, params, names, old_form);
  Eigen::MatrixXd c(n, n);
  for (size_t r = 0; r < n; ++r)
    for (size_t k = 0; k < n; ++k)
      c(r, k) = internal::ParseNumber(values[r * n + k], s.At(coeffs), "<coeffs>", 1e20);
  for (size_t r = 0; r < n; ++r)
    if (!(c(r, r) >= 0)) ThrowInputError(s.At(coeffs), "negative variance of " + names[r]);
  file->covariance = map * c * map.transpose();
  file->notes.push_back("covariance of " + std::to_string(n) + " parameters read");
}

}  // namespace

CameraFile ReadMetashapeCalibration(const std::string& path, const CameraReadOptions& options) {
  const std::vector<XmlSource> docs = LoadDocuments(path);
  CameraFile file;
  const Chosen chosen = ChooseSensor(docs, path, options);
  const XmlSource& s = *chosen.source;
  const XMLElement* sensor = chosen.sensor;
  const XMLElement* calibration =
      sensor ? ChooseCalibration(s, sensor, &file.notes) : chosen.calibration;
  if (sensor && sensor->Attribute("label")) file.name = sensor->Attribute("label");
  file.chosen_by_camera_id = sensor && !options.camera_id.empty();
  CheckFrameProjection(s, calibration);
  const auto [width, height] = ReadImageSize(s, calibration, sensor);
  const double pixel_size = ReadPixelSize(s, sensor, &file.notes);
  const bool old_form = ReadParameters(s, calibration, width, height, &file);
  if (const XMLElement* cov = FindCovariance(s, calibration, sensor, &file.notes))
    ReadCovariance(s, cov, old_form, &file);
  internal::ResolveFormat(&file, options, s.At(calibration), width, height, pixel_size);
  return file;
}

void WriteMetashapeCalibration(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == M::kId) << "not metashape_frame";
  std::ostringstream out;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  const std::vector<double>& p = file.camera.params;
  out << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<calibration>\n"
      << "  <projection>frame</projection>\n"
      << "  <width>" << file.camera.frame.width_px << "</width>\n"
      << "  <height>" << file.camera.frame.height_px << "</height>\n";
  std::vector<int> written;
  for (int i = 0; i < M::kNumParams; ++i) {
    // f, cx, cy always; the others where they are not 0 (as Metashape writes them).
    if (i > M::kCy && p[i] == 0.0 && !(file.covariance && (*file.covariance)(i, i) > 0)) continue;
    out << "  <" << M::kParams[i].name << ">" << n(p[i]) << "</" << M::kParams[i].name << ">\n";
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
        out << (r + c ? " " : "") << n((*file.covariance)(with[r], with[c]));
    out << "</coeffs>\n  </covariance>\n";
  }
  out << "</calibration>\n";
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
