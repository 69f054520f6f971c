// aerocal camera: camera files in other tools' languages (issue 15).
// `camera convert --from F --to G IN OUT`: read IN in format F into that format's own model,
// express it in G's model (exact where the models are equivalent, else a least-squares fit over the
// format whose residual is printed and reported), carry a covariance through, write OUT in format
// G. `camera show --from F IN`: the parameters, a table in our convention (CONVENTIONS.md) and the
// distortion over the format (a profile table; --plot writes an SVG plot).
#include "calib/camera/camera_model_json.h"
#include "calib/camera/convert_camera.h"
#include "calib/camera/distortion_folding.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/log.h"
#include "calib/core/result_file.h"
#include "calib/core/svg.h"
#include "tools/camera_formats.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"
#include "tools/output_set.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

namespace aerocal::tools {
namespace {

using calib::CameraFile;

struct ReadArgs {
  std::string from, in, camera_id;
  mutable std::string used;  // the format read (--from, or what auto detected)
  int width = 0, height = 0;
  double pixel_mm = 0;
  void Add(CLI::App* app) {
    app->add_option("--from",
                    from,
                    "Format of IN: " + CameraFormatNames() +
                        ", or auto (the one format the content looks like)")
        ->required();
    app->add_option("--camera",
                    camera_id,
                    "Which camera of a file holding several (COLMAP id, Metashape sensor id, "
                    "OpenSfM/Kalibr key, rig head, OpenCV stereo 1/2, Pix4D image, DJI record "
                    "file/date/number, DBAT id or report CameraN)");
    app->add_option("--width",
                    width,
                    "Image width in px where the file has none (checked "
                    "against the file where it has one)")
        ->check(FiniteRange(1, 1000000));
    app->add_option("--height", height, "Image height in px, as --width")
        ->check(FiniteRange(1, 1000000));
    app->add_option("--pixel-size-mm", pixel_mm, "Pixel size in mm where the file has none")
        ->check(FiniteRange(1e-5, 1.0));
  }
  CameraFile Read() const {
    calib::CameraReadOptions options;
    options.camera_id = camera_id;
    options.width_px = width;
    options.height_px = height;
    options.pixel_size_mm = pixel_mm;
    CameraFile file = calib::ReadCameraFileAs(from, in, options, &used);
    if (from == "auto") std::printf("%s: read as %s (--from auto)\n", in.c_str(), used.c_str());
    return file;
  }
};

// Without --max-residual-px a conversion is still refused when its fit misses by more than a
// pixel somewhere on the format (issue 37 class 3): such a camera is not the one read, whatever
// format holds it. Given, --max-residual-px replaces this limit and also chooses the coefficients.
constexpr double kDefaultMaxResidualPx = 1.0;

struct ConvertArgs {
  ReadArgs read;
  std::string to, out, model, report;
  double max_residual_px = kDefaultMaxResidualPx;
  bool max_residual_given = false;  // chooses the fewest coefficients meeting it (else 0.01 px)
  int max_coefficients = kDefaultMaxCoefficients;
};

// --model: one of the models the format writes (its registry row), by name (brown10 =
// brown_fraser_10); ConfigError naming the option, the format and the model otherwise.
calib::FormatTarget ModelTarget(const CameraFormat& to, const std::string& model) {
  const std::string name = model == "brown10" ? "brown_fraser_10" : model;
  const auto id = calib::CameraModelFromName(name);
  if (!id)
    throw ConfigError("--model: unknown camera model '" + model + "' (expected " +
                      calib::CameraModelNames() + ")");
  try {
    return calib::TargetInModel(to, *id);
  } catch (const InputError& e) {
    throw ConfigError("--model " + model + ": " + e.what());
  }
}

// OUT and --report must be writable and differ from each other and from IN (exit 2 otherwise).
void CheckConvertOutputs(const ConvertArgs& a) {
  CheckOutputFile(a.out, "OUT");
  CheckDistinctPath(a.out, "OUT", a.read.in, "IN");
  if (!a.report.empty()) {
    CheckOutputFile(a.report, "--report");
    CheckDistinctPath(a.report, "--report", a.out, "OUT");
    CheckDistinctPath(a.report, "--report", a.read.in, "IN");
  }
}

// Keeps of the converted file's covariance what the target format holds (full, standard
// deviations only, or nothing) and says in `notes` what was dropped.
void FitCovarianceToFormat(const CameraFormat& to,
                           const std::string& to_name,
                           CameraFile* written,
                           std::vector<std::string>* notes) {
  if (!written->covariance) return;
  switch (calib::CovarianceHeld(to, written->camera.model)) {
    case calib::CovarianceForm::kFull:
      break;
    case calib::CovarianceForm::kSigmas:
      notes->push_back("covariance written as standard deviations (" + to_name +
                       " holds no correlations: dropped)");
      break;
    case calib::CovarianceForm::kNone:
      notes->push_back("covariance dropped: " + to_name + " (" +
                       std::string(calib::CameraModelName(written->camera.model)) + ") holds none");
      written->covariance.reset();
  }
}

// The conversion's summary on stdout: source and target (file, format, model), how it was
// converted, the residual and the notes.
void PrintConversion(const ConvertArgs& a,
                     const CameraFile& source,
                     const calib::ConversionResult& r,
                     const std::vector<std::string>& notes) {
  const std::string model(calib::CameraModelName(r.camera.model));
  std::printf("%s (%s, %s) -> %s (%s, %s): %s\n",
              a.read.in.c_str(),
              a.read.used.c_str(),
              std::string(calib::CameraModelName(source.camera.model)).c_str(),
              a.out.c_str(),
              a.to.c_str(),
              model.c_str(),
              r.exact ? "exact (closed form)" : "least-squares fit over the format");
  std::printf("%s\n", DescribeConversion(r).c_str());
  for (const auto& note : notes) std::printf("note: %s\n", note.c_str());
}

// The `camera_conversion` result (--report): formats, models, the fit's residual over the
// format, the notes and the coefficient choices tried.
nlohmann::json ConversionReportJson(const ConvertArgs& a,
                                    const CameraFile& source,
                                    const calib::ConversionResult& r,
                                    bool acceptable,
                                    const std::vector<std::string>& notes,
                                    const std::vector<std::string>& tried) {
  return {{"from", a.read.used},
          {"to", a.to},
          {"source_model", std::string(calib::CameraModelName(source.camera.model))},
          {"model", std::string(calib::CameraModelName(r.camera.model))},
          {"exact", r.exact},
          {"acceptable", acceptable},
          {"fit_iterations", r.fit_iterations},
          {"residual_px",
           {{"rms", r.residual.rms_px},
            {"max", r.residual.max_px},
            {"max_at", {r.residual.max_at_px.x(), r.residual.max_at_px.y()}},
            {"max_inner80", r.residual.max_inner80_px},
            {"points", r.residual.points},
            {"failed_points", r.residual.failed_points}}},
          {"notes", notes},
          {"coefficient_choices", tried},
          {"source_camera_model", calib::CameraModelTableToJson(source.camera.model)},
          {"camera_model", calib::CameraModelTableToJson(r.camera.model)}};
}

// The warning of a conversion whose residual exceeds the limit (OUT is not written).
std::string ConversionResidualWarning(const ConvertArgs& a, const calib::ConversionResult& r) {
  return "conversion_residual: " + DescribeConversion(r) +
         (r.residual.failed_points
              ? " (" + std::to_string(r.residual.failed_points) + " points not invertible)"
              : "") +
         " exceeds " + (a.max_residual_given ? "--max-residual-px " : "the default limit ") +
         FormatNumber(a.max_residual_px) + " px; " + a.out + " not written" +
         (a.max_residual_given ? "" : " (a larger --max-residual-px accepts it)");
}

int RunConvert(const ConvertArgs& a) {
  CheckConvertOutputs(a);
  const CameraFormat& to = FindCameraFormat(a.to, "--to");
  const CameraFile source = a.read.Read();
  const calib::FormatTarget target =
      a.model.empty() ? to.target(source.camera) : ModelTarget(to, a.model);
  calib::ConvertOptions options;
  options.max_residual_px =
      a.max_residual_given ? a.max_residual_px : std::numeric_limits<double>::infinity();
  std::vector<std::string> tried;
  const calib::FileConversion conversion =
      calib::ConvertCameraFileSimplest(source, target, options, a.max_coefficients, &tried);
  const calib::ConversionResult& r = conversion.result;
  const bool acceptable = r.acceptable && r.residual.max_px <= a.max_residual_px;
  for (const std::string& line : tried) std::printf("  %s\n", line.c_str());
  std::vector<std::string> notes = source.notes;
  notes.insert(notes.end(), conversion.notes.begin(), conversion.notes.end());
  CameraFile written = conversion.file;
  FitCovarianceToFormat(to, a.to, &written, &notes);
  PrintConversion(a, source, r, notes);
  const nlohmann::json report = ConversionReportJson(a, source, r, acceptable, notes, tried);
  // OUT and the report are one set (tools/output_set.h): neither replaces its previous file
  // unless both were written. A conversion that is not acceptable writes the report alone (it
  // says why OUT was not written).
  OutputSet set(std::filesystem::path(a.out).parent_path().string());
  if (!a.report.empty()) WriteResult(set.StagePath(a.report), "camera_conversion", report);
  if (!acceptable) {
    if (!a.report.empty()) set.Commit({});
    LogWarning(ConversionResidualWarning(a, r));
    return kExitNotConverged;
  }
  calib::WriteCameraFileVerified(to, set.StagePath(a.out), written);
  set.Commit({});
  return kExitOk;
}

// ---- show ----

struct ShowArgs {
  ReadArgs read;
  std::string plot;
};

// Distortion at a measured pixel: the pixel minus the pinhole image of the same ray (principal
// distance, principal point of the model's OpenCV form, no affinity), px.
Eigen::Vector2d DistortionAt(const calib::ModelCamera& camera,
                             const Eigen::Vector2d& pp,
                             const Eigen::Vector2d& pixel,
                             bool* ok) {
  Eigen::Vector2d ideal;
  *ok = camera.IdealFromPixel(pixel, &ideal);
  const double p = camera.frame.pixel_size_mm;
  return pixel - (pp + Eigen::Vector2d(ideal.x() / p, -ideal.y() / p));
}

std::string Svg(const calib::ModelCamera& camera,
                const Eigen::Vector2d& pp,
                const std::vector<std::pair<double, double>>& profile,
                const std::string& title) {
  std::ostringstream s;
  const double W = camera.frame.width_px, H = camera.frame.height_px;
  double max_d = 1e-12, max_r = 1e-12;
  for (const auto& [r, d] : profile) max_d = std::max(max_d, d), max_r = std::max(max_r, r);
  s << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"920\" height=\"460\" "
       "font-family=\"sans-serif\" font-size=\"12\">\n"
    << "<text x=\"10\" y=\"18\">" << SvgEscape(title) << "</text>\n";
  // Left: |distortion| (px) against the distance from the principal point (px), on axes.
  SvgPanel panel;
  panel.left = 70, panel.bottom = 390, panel.width = 330, panel.height = 320;
  panel.x_lo = 0, panel.x_hi = max_r, panel.y_lo = 0, panel.y_hi = max_d;
  s << SvgAxes(panel,
               "distance from the principal point (px; to the farthest corner)",
               "|distortion| (px)")
    << "<polyline fill=\"none\" stroke=\"blue\" points=\"";
  for (const auto& [r, d] : profile) s << panel.X(r) << "," << panel.Y(d) << " ";
  s << "\"/>\n";
  // Right: distortion vectors over the format (x right, y down as the pixels), scaled so the
  // longest is one cell; the format's pixels on axes and a scale bar of the vectors.
  const double fw = 400, fh = fw * H / W;
  SvgPanel format;
  format.left = 490, format.bottom = 60 + fh, format.width = fw, format.height = fh;
  format.x_lo = 0, format.x_hi = W, format.y_lo = H, format.y_hi = 0;  // row 0 at the top
  s << SvgAxes(format, "column (px)", "row (px)");
  const int nx = 15, ny = std::max(3, static_cast<int>(std::lround(15 * H / W)));
  std::vector<std::pair<Eigen::Vector2d, Eigen::Vector2d>> arrows;
  double longest = 1e-12;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Eigen::Vector2d pixel((W - 1) * (i + 0.5) / nx, (H - 1) * (j + 0.5) / ny);
      bool ok = false;
      const Eigen::Vector2d d = DistortionAt(camera, pp, pixel, &ok);
      if (!ok) continue;
      arrows.emplace_back(pixel, d);
      longest = std::max(longest, d.norm());
    }
  const double cell = fw / nx, scale = cell / longest;  // SVG px per distortion px
  for (const auto& [pixel, d] : arrows) {
    const double ax = format.X(pixel.x()), ay = format.Y(pixel.y());
    s << "<line x1=\"" << ax << "\" y1=\"" << ay << "\" x2=\"" << ax + d.x() * scale << "\" y2=\""
      << ay + d.y() * scale << "\" stroke=\"red\"/>\n<circle cx=\"" << ax << "\" cy=\"" << ay
      << "\" r=\"1.5\"/>\n";
  }
  s << SvgScaleBar(format.left, format.bottom + 60, 1.0 / scale, 2 * cell, "px of distortion")
    << "<text x=\"" << format.left + 2.2 * cell << "\" y=\"" << format.bottom + 64
    << "\">distortion vectors (longest " << FormatNumber(longest, 4)
    << " px = one cell)</text>\n</svg>\n";
  return s.str();
}

int RunShow(const ShowArgs& a) {
  if (!a.plot.empty()) CheckOutputFile(a.plot, "--plot");
  const CameraFile file = a.read.Read();
  const calib::ModelCamera& camera = file.camera;
  const calib::PixelFrame& f = camera.frame;
  const std::string model(calib::CameraModelName(camera.model));
  std::printf("camera %s: %s, %d x %d px, pixel %s\n",
              file.name.c_str(),
              model.c_str(),
              f.width_px,
              f.height_px,
              file.pixel_size_known ? (FormatNumber(f.pixel_size_mm) + " mm").c_str()
                                    : "unknown (mm values below are in units of 0.001 mm)");
  const std::vector<calib::ParamInfo> table = calib::CameraModelParams(camera.model);
  std::printf("%-6s %24s %-6s %s\n", "param", "value", "unit", file.covariance ? "sigma" : "");
  for (size_t i = 0; i < table.size(); ++i) {
    std::string sigma;
    if (file.covariance && (*file.covariance)(i, i) > 0)
      sigma = FormatNumber(std::sqrt((*file.covariance)(i, i)), 6);
    std::printf("%-6s %24s %-6s %s\n",
                std::string(table[i].name).c_str(),
                FormatNumber(camera.params[i], 15).c_str(),
                std::string(table[i].unit).c_str(),
                sigma.c_str());
  }
  // A lens whose distortion folds inside its format maps two image points to one ray: the table
  // below would jump there without a word (issue 37 class 6).
  const std::string folding = calib::DistortionFoldingWarning(calib::FindDistortionFolding(camera));
  if (!folding.empty()) std::fprintf(stderr, "warning: %s\n", folding.c_str());
  calib::OpenCvParams cv;
  calib::VisitCameraModel(
      camera.model, [&](auto m) { return decltype(m)::ToOpenCv(camera.params.data(), f, &cv); });
  using O = calib::OpenCvModel;
  const Eigen::Vector2d pp(cv[O::kCx], cv[O::kCy]);
  const double p = f.pixel_size_mm;
  std::printf("our convention (docs/conventions.md: photo frame at the format centre, y up):\n");
  std::printf("  c  = %s mm (%s px)\n",
              FormatNumber(camera.PrincipalDistanceMm(), 10).c_str(),
              FormatNumber(camera.PrincipalDistanceMm() / p, 10).c_str());
  std::printf("  x0 = %s mm (%s px from the centre)\n",
              FormatNumber((pp.x() - 0.5 * (f.width_px - 1)) * p, 10).c_str(),
              FormatNumber(pp.x() - 0.5 * (f.width_px - 1), 10).c_str());
  std::printf("  y0 = %s mm (%s px, y up)\n",
              FormatNumber(-(pp.y() - 0.5 * (f.height_px - 1)) * p, 10).c_str(),
              FormatNumber(-(pp.y() - 0.5 * (f.height_px - 1)), 10).c_str());
  std::printf("  fx / fy - 1 = %s (our B1 after a conversion)\n",
              FormatNumber(cv[O::kFx] / cv[O::kFy] - 1.0, 6).c_str());
  // Profile: along the lines from the principal point to the four corners.
  std::printf(
      "distortion (pixel minus the pinhole image of its ray), max over the 4 corner "
      "directions:\n  %-8s %12s %12s\n",
      "r/r_max",
      "r px",
      "|d| px");
  std::vector<std::pair<double, double>> profile;
  const Eigen::Vector2d corners[4] = {
      {0, 0}, {f.width_px - 1.0, 0}, {0, f.height_px - 1.0}, {f.width_px - 1.0, f.height_px - 1.0}};
  double r_max = 0;
  for (const auto& c : corners) r_max = std::max(r_max, (c - pp).norm());
  for (int k = 0; k <= 40; ++k) {
    const double t = k / 40.0;
    double d_max = 0;
    for (const auto& c : corners) {
      const Eigen::Vector2d dir = (c - pp).normalized();
      const double r = std::min(t * r_max, (c - pp).norm());
      bool ok = false;
      const Eigen::Vector2d d = DistortionAt(camera, pp, pp + r * dir, &ok);
      if (ok) d_max = std::max(d_max, d.norm());
    }
    profile.emplace_back(t * r_max, d_max);
    if (k % 4 == 0) std::printf("  %-8.2f %12.1f %12.4f\n", t, t * r_max, d_max);
  }
  for (const auto& note : file.notes) std::printf("note: %s\n", note.c_str());
  if (!a.plot.empty()) {
    WriteFileAtomically(a.plot, Svg(camera, pp, profile, file.name + " (" + model + ")"));
    std::printf("plot: %s\n", a.plot.c_str());
  }
  return kExitOk;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto convert = std::make_shared<ConvertArgs>();
  CLI::App* cv =
      app.add_subcommand("convert",
                         "A camera file in another tool's format: exact where the models are "
                         "equivalent, else a least-squares fit with its residual");
  cv->option_defaults()->always_capture_default();
  convert->read.Add(cv);
  cv->add_option("--to", convert->to, "Format of OUT: " + CameraFormatNames())->required();
  cv->add_option("IN", convert->read.in, "Input camera file")->required();
  cv->add_option("OUT", convert->out, "Output camera file (written atomically)")->required();
  cv->add_option("--model",
                 convert->model,
                 "The registry model to write, one the --to format writes (any with aerocal, "
                 "e.g. brown10 = brown_fraser_10, opencv, metashape_frame; colmap_* with colmap; "
                 "opencv or opencv_fisheye with ros); default: the source's own model where the "
                 "format writes it, else the format's");
  cv->add_option("--report",
                 convert->report,
                 "JSON: {exact, acceptable, residual_px: {rms, max, max_at, max_inner80}, notes}");
  cv->add_option("--max-residual-px",
                 convert->max_residual_px,
                 "A conversion leaving more (max over the format, px) does not fit: exit 3, OUT "
                 "not written; given, it also chooses the fewest coefficients meeting it")
      ->check(PositiveUpTo(1e6))
      ->each([convert](const std::string&) { convert->max_residual_given = true; });
  cv->add_option("--max-coefficients",
                 convert->max_coefficients,
                 "OpenCV-form targets (opencv, ros, dji, colmap) reached by a fit: at most this "
                 "many distortion coefficients, 4 (k1 k2 p1 p2), 5 (+ k3) or 8 (+ k4-k6); the "
                 "fewest meeting --max-residual-px are written, each choice's residual printed")
      ->check(FiniteRange(4, 8))
      ->check(CLI::IsMember({4, 5, 8}));
  auto show = std::make_shared<ShowArgs>();
  CLI::App* sh = app.add_subcommand(
      "show", "A camera file as a table in our convention plus its distortion (profile, SVG plot)");
  sh->option_defaults()->always_capture_default();
  show->read.Add(sh);
  sh->add_option("IN", show->read.in, "Camera file")->required();
  sh->add_option("--plot", show->plot, "SVG plot: distortion profile and vectors over the format");
  return [convert, cv, show, sh] {
    if (cv->parsed()) return RunConvert(*convert);
    if (sh->parsed()) return RunShow(*show);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(camera,
                         "camera",
                         "Camera files in other tools' formats: convert (with how exact) and show",
                         Setup);

}  // namespace aerocal::tools
