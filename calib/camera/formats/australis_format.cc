// Australis (Photometrix) camera: the "Camera Parameters" result of an Australis bundle adjustment,
// as the program prints it (a public example: wiki.cis.rit.edu/pub/LIAS/WaspLTCameraCalibrations/
// Camera3-2006-report.txt, "Australis Bundle Adjustment Results: Camera Parameters"):
//   Sensor Size  Pixel Size (mm)
//   H <width px>  <pixel width mm>
//   V <height px> <pixel height mm>
//   Camera Variable | Initial Value | Total Adjustment | Final Value | Initial Std. Error | Final
//   Std. Error C  ... (mm)   XP ... (mm)   YP ... (mm)   K1 K2 K3 P1 P2 B1 B2
// Australis's model is Fraser's (1997) 10-parameter correction form, the one ours is
// (brown_fraser_10, CONVENTIONS.md): c, the principal point offset (xp, yp) from the format centre
// in mm with y up, K1-K3 (mm^-2, mm^-4, mm^-6), P1, P2 (mm^-1), B1, B2 (1), the correction added to
// the measured coordinates reduced to the principal point. So x0 = XP, y0 = YP and every term maps
// one to one (exact). The final standard errors become a diagonal covariance (Australis prints no
// correlations here); an Initial Std. Error of 1.0e+003 is Australis's "free". The report is read
// as whitespace-separated tokens (its columns are aligned with spaces): the line that starts with
// H and the one that starts with V, each followed by pixels and pixel size, then the line of each
// parameter, its name followed by its five numbers. Each of these lines is given once (a second
// one is an error, not the first one taken) and its numbers must read (a `nan` or a missing
// number is an error at its line, never a 0); a parameter without a line is 0, said in the notes
// (C is required). H and V pixel sizes that differ are not modelled (square pixels of V's size,
// said). Written in the same layout, Initial = Final and Total Adjustment 0.
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>

namespace aerocal::calib {
namespace {

using Model = BrownFraser10Model;

struct Token {
  std::string text;
  int line;
};

constexpr double kFreeSigma = 1000.0;  // Australis prints 1.0e+003 for a free parameter

// The Australis name of each parameter of our table, in table order.
constexpr const char* kAustralisNames[Model::kNumParams] = {
    "C", "XP", "YP", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};

// The report as whitespace-separated tokens with their line numbers.
struct Report {
  std::string path;
  std::vector<Token> tokens;

  // The token index of the one line at or after token `from` that starts with `name` (-1: none);
  // a second such line is an error.
  long Row(const std::string& name, size_t from) const {
    long found = -1;
    for (size_t i = from; i < tokens.size(); ++i) {
      if (tokens[i].text != name || (i > 0 && tokens[i - 1].line == tokens[i].line)) continue;
      if (found >= 0)
        ThrowInputError({path, tokens[i].line},
                        "a second '" + name + "' line (the first is line " +
                            std::to_string(tokens[found].line) + ")");
      found = static_cast<long>(i);
    }
    return found;
  }
  // The k-th number after the name at token `i`.
  double Number(long i, long k, const std::string& what, double bound) const {
    const size_t at = static_cast<size_t>(i + k);
    if (at >= tokens.size()) ThrowInputError({path, tokens[i].line}, what + " is missing");
    return internal::ParseNumber(tokens[at].text, {path, tokens[at].line}, what, bound);
  }
};

Report ReadReport(const std::string& path) {
  const std::vector<std::string> lines = SplitLines(ReadTextFile(path));
  Report report{path, {}};
  for (size_t i = 0; i < lines.size(); ++i) {
    std::istringstream in(lines[i]);
    for (std::string t; in >> t;) report.tokens.push_back({t, static_cast<int>(i + 1)});
  }
  bool australis = false;
  for (const std::string& line : lines) australis |= line.find("Australis") != std::string::npos;
  if (!australis)
    ThrowInputError({path, 1}, "not an Australis camera-parameter report (no 'Australis' line)");
  return report;
}

// The sensor size (lines H and V: pixels, pixel size mm) into the file's format (square pixels of
// V's size); returns the token after which the parameter lines start.
size_t ReadSensorSize(const Report& r, const CameraReadOptions& options, CameraFile* file) {
  const long h = r.Row("H", 0), v = r.Row("V", 0);
  if (h < 0 || v < 0)
    ThrowInputError({r.path, 1},
                    "no sensor size: lines 'H <pixels> <pixel size mm>' and "
                    "'V <pixels> <pixel size mm>'");
  const double width = r.Number(h, 1, "H pixels", 1e6), height = r.Number(v, 1, "V pixels", 1e6);
  const double pixel_h = r.Number(h, 2, "H pixel size", 1.0),
               pixel_v = r.Number(v, 2, "V pixel size", 1.0);
  if (!(width >= 1 && height >= 1 && width == std::floor(width) && height == std::floor(height)))
    ThrowInputError({r.path, r.tokens[h].line}, "H and V pixels must be positive integers");
  internal::ResolveFormat(file,
                          options,
                          {r.path, r.tokens[v].line},
                          static_cast<int>(width),
                          static_cast<int>(height),
                          pixel_v);
  if (std::abs(pixel_h / pixel_v - 1.0) > 1e-9)
    file->notes.push_back("Australis H pixel size " + FormatNumber(pixel_h) +
                          " mm differs from V " + FormatNumber(pixel_v) +
                          " mm: square pixels of V's size (not modelled)");
  return static_cast<size_t>(std::max(h, v)) + 1;
}

// Each parameter's line (name, initial, total adjustment, final, initial sigma, final sigma): the
// final value, and the final sigma as a diagonal covariance where both sigmas are > 0 (0: fixed).
void ReadParameters(const Report& r, size_t from, CameraFile* file) {
  file->camera.model = Model::kId;
  file->camera.params.assign(Model::kNumParams, 0.0);
  Eigen::MatrixXd covariance = Eigen::MatrixXd::Zero(Model::kNumParams, Model::kNumParams);
  bool any_sigma = false;
  for (int k = 0; k < Model::kNumParams; ++k) {
    const std::string name = kAustralisNames[k];
    const long i = r.Row(name, from);
    if (i < 0) {
      if (k == Model::kC)
        ThrowInputError({r.path, 1},
                        "no camera constant: a line 'C <initial> <adjustment> <final> "
                        "<initial sigma> <final sigma>'");
      file->notes.push_back(name + ": no line in the report, 0");
      continue;
    }
    r.Number(i, 1, name + " initial value", 1e12);
    r.Number(i, 2, name + " total adjustment", 1e12);
    file->camera.params[k] = r.Number(i, 3, name + " final value", k == Model::kC ? 1e4 : 1e3);
    const double initial_sigma = r.Number(i, 4, name + " initial std. error", 1e12);
    const double sigma = r.Number(i, 5, name + " final std. error", 1e12);
    if (sigma < 0) ThrowInputError({r.path, r.tokens[i].line}, name + " std. error must be >= 0");
    if (sigma > 0 && initial_sigma > 0) {
      covariance(k, k) = sigma * sigma;
      any_sigma = true;
    }
  }
  if (!(file->camera.params[Model::kC] > 0)) ThrowInputError({r.path, 1}, "C must be > 0 mm");
  if (any_sigma) {
    file->covariance = covariance;
    file->notes.push_back(
        "Australis final std. errors read as a diagonal covariance (the report "
        "prints no correlations)");
  }
}

}  // namespace

CameraFile ReadAustralisCamera(const std::string& path, const CameraReadOptions& options) {
  const Report report = ReadReport(path);
  if (!options.camera_id.empty())
    ThrowInputError({path, 1}, "--camera: one camera per Australis report is read");
  CameraFile file;
  file.name = std::filesystem::path(path).stem().string();
  const size_t parameters_from = ReadSensorSize(report, options, &file);
  ReadParameters(report, parameters_from, &file);
  return file;
}

void WriteAustralisCamera(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == Model::kId) << "not brown_fraser_10";
  const PixelFrame& f = file.camera.frame;
  const std::vector<double>& q = file.camera.params;
  const auto n = [](double v) { return internal::ShortestNumber(v); };
  std::ostringstream out;
  out << "Australis Bundle Adjustment Results: Camera Parameters\n"
      << "(written by aerocal: the camera only)\n\nResults for Camera 1\n"
      << (file.name.empty() ? "camera" : file.name) << "\n\n"
      << "Sensor Size  Pixel Size (mm)\nH " << f.width_px << " " << n(f.pixel_size_mm) << "\nV "
      << f.height_px << " " << n(f.pixel_size_mm) << "\n\n"
      << "Camera    Initial    Total       Final     Initial     Final\n"
      << "Variable  Value      Adjustment  Value     Std. Error  Std. Error\n";
  for (int k = 0; k < Model::kNumParams; ++k) {
    double sigma = 0;
    if (file.covariance && (*file.covariance)(k, k) > 0)
      sigma = std::sqrt((*file.covariance)(k, k));
    out << kAustralisNames[k] << " " << n(q[k]) << " 0 " << n(q[k]) << " "
        << n(sigma > 0 ? kFreeSigma : 0.0) << " " << n(sigma) << (k < 3 ? " (mm)" : "") << "\n";
  }
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::calib
