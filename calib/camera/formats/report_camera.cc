// The camera of a DBAT or PhotoModeler text report (camera_formats.h internal::ReadReportCamera).
// Both print a camera block ("Camera1 (simple)" in DBAT 0.9, "Camera1: <name>" in PhotoModeler's
// status / calibration report and DBAT's PhotoModeler-style report) whose parameters are a title
// line ("Camera Constant:", "Focal Length", "Xp - principal point x", "K1 - radial distortion 1",
// ...) followed by "Value: X unit" and "Deviation: [Name:] Y unit" lines. Titles are keyed by
// their short name (the text before " - "); DBAT's and PhotoModeler's names of the same term are
// both read: c (Camera Constant | Focal Length), px | Xp, py | Yp (mm from the upper-left corner,
// y down), Format width/height | Fw/Fh (mm), K1-K3, P1, P2, as (DBAT's off-unit aspect: pixel
// width = pixel height (1 + as)), sk (skew: not modelled, must be 0), Image width/height | Iw/Ih.
// Blocks of the same camera in several sections are merged; a parameter printed twice with other
// values is an error.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/csv.h"

#include <cmath>
#include <map>
#include <regex>

namespace aerocal::calib::internal {
namespace {

using Model = BrownFraser10Model;

struct ReportEntry {
  double value = 0, deviation = 0;
  int line = 0;
};
using ReportBlock = std::map<std::string, ReportEntry>;

std::vector<std::pair<std::string, ReportBlock>> ReportCameras(
    const std::string& path, const std::vector<std::string>& lines) {
  std::vector<std::pair<std::string, ReportBlock>> cameras;
  static const std::regex kCamera(R"(\s*(Camera\d+)(?: \(.*\)|:.*)?\s*)");
  static const std::regex kValue(
      R"(\s*(Value|Deviation):\s*(?:[A-Za-z][A-Za-z0-9 ]*:\s*)?(\S+).*)");
  ReportBlock* block = nullptr;
  std::string title;
  size_t indent = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    std::string line = lines[i];
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const size_t at = line.find_first_not_of(' ');
    std::smatch m;
    if (std::regex_match(line, m, kCamera)) {
      block = nullptr;
      for (auto& c : cameras)
        if (c.first == m[1]) block = &c.second;
      if (!block) {
        cameras.push_back({m[1], {}});
        block = &cameras.back().second;
      }
      indent = at;
      title.clear();
      continue;
    }
    if (!block || at == std::string::npos) continue;
    if (at <= indent) {  // the end of the camera block
      block = nullptr;
      continue;
    }
    const SourceRef where{path, static_cast<int>(i + 1)};
    if (std::regex_match(line, m, kValue)) {
      if (title.empty()) continue;
      const double v = ParseNumber(m[2], where, title + " " + std::string(m[1]), 1e7);
      ReportEntry& e = (*block)[title];
      if (m[1] == "Value") {
        if (e.line != 0 && e.value != v)
          ThrowInputError(where,
                          title + " printed twice with other values (" + FormatNumber(e.value) +
                              " at line " + std::to_string(e.line) + ")");
        e.value = v;
        e.line = where.line;
      } else {
        e.deviation = v;
      }
    } else if (line.back() == ':' || line.find(':') == std::string::npos) {
      title = line.substr(at, line.size() - at - (line.back() == ':' ? 1 : 0));
      title = title.substr(0, title.find(" - "));  // "K1 - radial distortion 1" -> "K1"
    } else {
      title.clear();
    }
  }
  return cameras;
}

}  // namespace

double AspectAsB1ResidualPx(const ModelCamera& ours, double s) {
  const PixelFrame& f = ours.frame;
  std::vector<double> dbat = ours.params;
  dbat[Model::kX0] = dbat[Model::kY0] = dbat[Model::kB1] = dbat[Model::kB2] = 0.0;
  double worst = 0.0;
  for (int j = 0; j <= 20; ++j)
    for (int i = 0; i <= 20; ++i) {
      const double xy[2] = {(i / 20.0 - 0.5) * f.width_px * f.pixel_size_mm,
                            (0.5 - j / 20.0) * f.height_px * f.pixel_size_mm};
      const double xy_scaled[2] = {s * (xy[0] - ours.params[Model::kX0]),
                                   xy[1] - ours.params[Model::kY0]};
      double a[2], b[2];
      Model::IdealFromMeasured(ours.params.data(), xy, a);
      Model::IdealFromMeasured(dbat.data(), xy_scaled, b);
      worst = std::max(worst, std::hypot(a[0] - b[0], a[1] - b[1]) / f.pixel_size_mm);
    }
  return worst;
}

namespace {

/// The camera block named by options.camera_id, or the only one with values; its name in *name.
const ReportBlock& ChooseReportCamera(
    const std::string& path,
    const std::vector<std::pair<std::string, ReportBlock>>& cameras,
    const CameraReadOptions& options,
    const std::string& tool,
    std::string* name) {
  std::string ids;
  const ReportBlock* found = nullptr;
  int with_values = 0;
  for (const auto& c : cameras) {
    if (c.second.empty()) continue;  // a camera listed without parameters
    ++with_values;
    ids += (ids.empty() ? "" : ", ") + c.first;
    if (c.first == options.camera_id || options.camera_id.empty())
      found = &c.second, *name = c.first;
  }
  if (!found || (options.camera_id.empty() && with_values > 1))
    ThrowInputError(
        {path, 1},
        with_values == 0
            ? "no camera block with parameter values (CameraN) in the " + tool + " report"
        : options.camera_id.empty() ? "holds " + std::to_string(with_values) +
                                          " cameras: name one with --camera (" + ids + ")"
                                    : "no camera " + options.camera_id + " (cameras: " + ids + ")");
  return *found;
}

/// The entry under either tool's name; `required` false: absent is 0 (a term the report's model
/// does not have).
ReportEntry ReportValue(const std::string& path,
                        const std::string& name,
                        const ReportBlock& block,
                        std::initializer_list<const char*> titles,
                        bool required) {
  for (const char* t : titles)
    if (const auto it = block.find(t); it != block.end() && it->second.line != 0) return it->second;
  if (required)
    ThrowInputError({path, 1}, name + ": the report has no '" + *titles.begin() + "' value");
  return ReportEntry{};
}

/// Image width / height as printed; 0 when not printed (then --width / --height).
int ReportInteger(const std::string& path, const ReportEntry& e, const char* what) {
  if (e.line == 0) return 0;
  if (!(e.value >= 1 && e.value <= 1e6) || e.value != std::floor(e.value))
    ThrowInputError({path, e.line}, std::string(what) + " must be a positive integer");
  return static_cast<int>(e.value);
}

/// The report's terms other than the distortion, under either tool's name.
struct ReportTerms {
  ReportEntry c, px, py, fh, iw, ih, as;
};

/// Reads the terms (the first missing required one is the error) and refuses the terms that are
/// not modelled: skew and the aspect-ratio form (sk, B1, B2) must be 0.
ReportTerms ReadReportTerms(const std::string& path,
                            const std::string& name,
                            const ReportBlock& block,
                            const std::string& tool) {
  const auto get = [&](std::initializer_list<const char*> titles, bool required) {
    return ReportValue(path, name, block, titles, required);
  };
  ReportTerms t;
  t.c = get({"Camera Constant", "Focal Length"}, true);
  t.px = get({"px", "Xp"}, true);
  t.py = get({"py", "Yp"}, true);
  t.fh = get({"Format height", "Fh"}, true);
  t.iw = get({"Image width", "Iw"}, false);
  t.ih = get({"Image height", "Ih"}, false);
  t.as = get({"as"}, false);
  const ReportEntry sk = get({"sk"}, false), b1 = get({"B1"}, false), b2 = get({"B2"}, false);
  for (const ReportEntry* e : {&sk, &b1, &b2})
    if (e->value != 0)
      ThrowInputError({path, e->line},
                      tool + " term = " + FormatNumber(e->value) +
                          " (skew / aspect-ratio form) is not modelled");
  return t;
}

/// The report's interior values in the 10-parameter model: c, the principal point (mm from the
/// upper-left corner, y down, to the centre-based photo frame; x over `x_scale`), B1 = s - 1 and
/// K1-K3, P1, P2; the deviations as a diagonal covariance.
void SetReportParameters(const std::string& path,
                         const std::string& name,
                         const ReportBlock& block,
                         const ReportTerms& t,
                         double pixel,
                         double x_scale,
                         double s,
                         CameraFile* file) {
  const ReportEntry &c = t.c, &px = t.px, &py = t.py, &as = t.as;
  const int width = file->camera.frame.width_px, height = file->camera.frame.height_px;
  std::vector<double>& q = file->camera.params;
  q.assign(Model::kNumParams, 0.0);
  file->camera.model = Model::kId;
  q[Model::kC] = c.value;
  q[Model::kX0] = px.value / x_scale - width * pixel / 2;
  q[Model::kY0] = height * pixel / 2 - py.value;
  q[Model::kB1] = s - 1.0;
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(Model::kNumParams, Model::kNumParams);
  const char* terms[] = {"K1", "K2", "K3", "P1", "P2"};
  const int index[] = {Model::kK1, Model::kK2, Model::kK3, Model::kP1, Model::kP2};
  for (int k = 0; k < 5; ++k) {
    const ReportEntry e = ReportValue(path, name, block, {terms[k]}, k < 2);
    q[index[k]] = e.value;
    covariance(index[k], index[k]) = e.deviation * e.deviation;
  }
  covariance(Model::kC, Model::kC) = c.deviation * c.deviation;
  covariance(Model::kX0, Model::kX0) = px.deviation * px.deviation / (s * s);
  covariance(Model::kY0, Model::kY0) = py.deviation * py.deviation;
  covariance(Model::kB1, Model::kB1) = as.deviation * as.deviation;
  if (covariance.diagonal().maxCoeff() > 0) {
    file->covariance = covariance;
    file->notes.push_back(
        "the report's deviations as a diagonal covariance (correlations are "
        "printed only over 95 %: not read)");
  }
}

}  // namespace

CameraFile ReadReportCamera(const std::string& path,
                            const std::vector<std::string>& lines,
                            const CameraReadOptions& options,
                            const std::string& tool) {
  const auto cameras = ReportCameras(path, lines);
  std::string name;
  const ReportBlock& found = ChooseReportCamera(path, cameras, options, tool, &name);
  const ReportTerms t = ReadReportTerms(path, name, found, tool);
  const ReportEntry &fh = t.fh, &as = t.as;
  CameraFile file;
  file.name = name;
  file.chosen_by_camera_id = !options.camera_id.empty();
  const int file_width = ReportInteger(path, t.iw, "Image width"),
            file_height = ReportInteger(path, t.ih, "Image height");
  if (!(fh.value > 0)) ThrowInputError({path, fh.line}, "Format height must be > 0 mm");
  ResolveFormat(&file, options, {path, fh.line}, file_width, file_height, 0.0);
  const int width = file.camera.frame.width_px, height = file.camera.frame.height_px;
  const double pixel = fh.value / height;  // our pixel: the pixel height
  ResolveFormat(&file, options, {path, fh.line}, width, height, pixel);
  // DBAT's pixel aspect (pixel width = pixel height (1 + as)) becomes B1; PhotoModeler's x scale
  // (format width against the square pixel) is not modelled, as its Bundle Soln reader does: the
  // principal point is kept in pixels (ppx over PhotoModeler's mm per pixel along x).
  const double s = 1.0 + as.value;
  const ReportEntry fw = ReportValue(path, name, found, {"Format width", "Fw"}, false);
  const double x_scale = as.line == 0 && fw.line != 0 ? fw.value / (width * pixel) : s;
  if (!(x_scale > 0)) ThrowInputError({path, fw.line}, "Format width must be > 0 mm");
  if (as.line == 0 && std::abs(x_scale - 1.0) > 1e-6)
    file.notes.push_back(
        "Format width " + FormatNumber(fw.value) + " mm is " + FormatNumber(width * pixel) +
        " mm at the square pixel of the format "
        "height: x scale " +
        FormatNumber(x_scale - 1.0) + " not modelled (the principal point is kept in pixels)");
  SetReportParameters(path, name, found, t, pixel, x_scale, s, &file);
  if (s != 1.0)
    file.notes.push_back(tool + " as = " + FormatNumber(as.value) + " read as B1: not exact, " +
                         FormatNumber(AspectAsB1ResidualPx(file.camera, s), 3) +
                         " px max over the format (the report's K, P act on the scaled x)");
  file.notes.push_back("values as the report prints them (its significant digits)");
  return file;
}

}  // namespace aerocal::calib::internal
