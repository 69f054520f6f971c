#include "tools/rig_error_analysis_run.h"

#include "calib/camera/rig_io.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "stitch/rig/rig_conversion.h"
#include "tools/option_ranges.h"
#include "tools/rig_design_document.h"
#include "tools/rig_stitch_run.h"

#include <optional>
#include <vector>

namespace aerocal::tools {
namespace {

// Monte-Carlo samples of a whole --grid analysis (about 20 min at ~1 us a sample).
constexpr double kMaxGridSamples = 1e9;

// "COL,ROW" -> pixel; ConfigError naming the option otherwise.
Eigen::Vector2d ParsePixel(const std::string& text, const std::string& option) {
  const std::vector<std::string> fields = SplitCommaList(text, {true, true});
  const auto col = fields.size() == 2 ? ParseDouble(fields[0]) : std::nullopt;
  const auto row = fields.size() == 2 ? ParseDouble(fields[1]) : std::nullopt;
  if (!col || !row) throw ConfigError(option + ": expected COL,ROW (got '" + text + "')");
  return {*col, *row};
}

// The relative flying height (FlyingHeight: --height-m or the rig file's), above the limits
// file's height limit.
double ErrorAnalysisHeight(const RigErrorAnalysisRequest& args,
                           const calib::Rig& rig,
                           const stitch::ErrorLimits& limits) {
  const double height_m = FlyingHeight(rig, args.height_m, args.camera);
  if (!(limits.height_m < height_m))
    throw InputError(args.limits + ": the height limit (" + FormatNumber(limits.height_m) +
                     " m) must be below the flying height (" + FormatNumber(height_m) + " m)");
  return height_m;
}

// The option ranges that depend on each other or on the height (CLI11 checks the rest).
void CheckErrorAnalysisOptions(const RigErrorAnalysisRequest& args, double height_m) {
  const int modes = !args.target.empty() + !args.virtual_px.empty() + (args.grid > 0);
  if (modes > 1) throw ConfigError("--target, --virtual and --grid exclude each other");
  // The command's CLI11 ranges again, for callers without the command line (Python).
  if (args.samples < 0 || args.samples > 10000000)
    throw ConfigError("--samples must be within 0..10000000");
  if (args.bins < 1 || args.bins > 10000) throw ConfigError("--bins must be within 1..10000");
  if (args.grid < 0 || args.grid > 200) throw ConfigError("--grid must be within 1..200");
  // Every grid target runs its own Monte-Carlo: the work is grid x grid x samples (x heads).
  if (double(args.grid) * args.grid * args.samples > kMaxGridSamples)
    throw ConfigError("--grid x --grid x --samples: " + std::to_string(args.grid) + " x " +
                      std::to_string(args.grid) + " x " + std::to_string(args.samples) +
                      " Monte-Carlo samples are more than 1e9 (fewer "
                      "--samples or a coarser --grid)");
  if (!(args.relief_m >= 0 && args.relief_m <= 1e4))
    throw ConfigError("--relief-m must be within 0..10000 m");
  if (!(args.relief_m < height_m))
    throw ConfigError("--relief-m: " + FormatNumber(args.relief_m) +
                      " m of relief reaches the flying height (" + FormatNumber(height_m) + " m)");
}

// Where the analysis looks: the head and the virtual pixel of --target, --virtual or the default
// (the format centre of the first non-reference head); head -1 with --grid.
struct AnalysisTarget {
  int head = -1;
  Eigen::Vector2d virtual_px = Eigen::Vector2d::Zero();
};

AnalysisTarget ChooseAnalysisTarget(const RigErrorAnalysisRequest& args,
                                    const calib::Rig& rig,
                                    double height_m) {
  const int reference = rig.ReferenceIndex();
  const stitch::RigExposure nadir;
  const stitch::RigConverter nominal(
      rig, nadir, stitch::MakeRectificationPlane(rig, nadir, height_m));
  int head = -1;
  Eigen::Vector2d virtual_px = Eigen::Vector2d::Zero();
  if (!args.target.empty()) {
    const auto colon = args.target.find(':');
    if (colon == std::string::npos)
      throw ConfigError("--target: expected HEAD:COL,ROW (got '" + args.target + "')");
    head = rig.HeadIndex(args.target.substr(0, colon));
    if (head < 0)
      throw ConfigError("--target: head '" + args.target.substr(0, colon) + "' is not in " +
                        args.camera);
    const auto v =
        nominal.VirtualFromHead(head, ParsePixel(args.target.substr(colon + 1), "--target"));
    if (!v) throw ConfigError("--target: the pixel does not reach the rectification plane");
    virtual_px = *v;
  } else if (!args.virtual_px.empty()) {
    virtual_px = ParsePixel(args.virtual_px, "--virtual");
    for (int k = 0; k < static_cast<int>(rig.heads.size()) && head < 0; ++k) {
      if (k == reference) continue;
      const auto p = nominal.HeadFromVirtual(k, virtual_px);
      if (p && nominal.InHeadFormat(k, *p)) head = k;
    }
    if (head < 0)
      throw ConfigError("--virtual: no non-reference head sees virtual pixel " + args.virtual_px);
  } else if (args.grid == 0) {
    // Default: the format centre of the first non-reference head.
    head = reference == 0 ? 1 : 0;
    const calib::Camera& camera = rig.heads[head].camera;
    const auto v =
        nominal.VirtualFromHead(head, {0.5 * (camera.width_px - 1), 0.5 * (camera.height_px - 1)});
    if (!v)
      throw InputError(args.camera + ": the centre of head " + rig.heads[head].id +
                       " does not reach the rectification plane");
    virtual_px = *v;
  }
  if (head == reference)
    throw ConfigError("--target: " + rig.reference_head +
                      " is the reference head, which realises the virtual camera (its conversion "
                      "error is zero by definition); choose another head");

  return {head, virtual_px};
}

// The analysis at the chosen target (Monte-Carlo and linear) or over the --grid, and the names
// of the files beside `stem` (CSV, PNG with `plots`; none without a stem).
void AnalyseErrors(const RigErrorAnalysisRequest& args,
                   const calib::Rig& rig,
                   const stitch::ErrorLimits& limits,
                   double height_m,
                   int head,
                   const Eigen::Vector2d& virtual_px,
                   const std::string& stem,
                   bool plots,
                   RigErrorAnalysisRun* run) {
  stitch::ErrorAnalysisFiles& files = run->files;
  std::unique_ptr<stitch::GridAnalysis>& grid = run->grid;
  stitch::TargetAnalysis& target = run->target;
  // A limit that breaks the conversion is a value of the limits file: the message names it.
  const auto named = [&](const InputError& e) {
    const std::string what = e.what();
    return what.find("breaks the conversion") == std::string::npos
               ? e
               : InputError(args.limits + ": " + what + " (rig " + args.camera +
                            ", H = " + FormatNumber(height_m) + " m)");
  };
  if (args.grid > 0) {
    try {
      grid = std::make_unique<stitch::GridAnalysis>(
          stitch::AnalyseGrid(rig, height_m, limits, args.grid, args.samples, args.seed));
    } catch (const InputError& e) {
      throw named(e);
    }
    if (grid->points.empty())
      throw InputError(args.camera + ": no grid point is seen by a non-reference head");
    target = grid->points[grid->worst];
    if (!stem.empty()) files.bound_map_csv = stem + "_bound_map.csv";
  } else {
    try {
      target = stitch::AnalyseTarget(
          rig, height_m, limits, head, virtual_px, args.samples, args.seed, true);
    } catch (const InputError& e) {
      throw named(e);
    }
    if (target.monte_carlo && !stem.empty()) files.histogram_csv = stem + "_histogram.csv";
  }
  if (plots) {
    if (!files.histogram_csv.empty()) files.histogram_png = stem + "_histogram.png";
    if (!files.bound_map_csv.empty()) files.bound_map_png = stem + "_bound_map.png";
  }
}

}  // namespace

RigErrorAnalysisRun RunRigErrorAnalysis(const RigErrorAnalysisRequest& request,
                                        const std::string& file_stem,
                                        bool plots) {
  RigErrorAnalysisRun run;
  run.rig = calib::ReadRig(request.camera);
  const calib::Rig& rig = run.rig;
  const stitch::ErrorLimits limits = stitch::ReadErrorLimits(request.limits);
  if (rig.heads.size() < 2)
    throw InputError(request.camera +
                     ": a rig of one head is an ordinary camera; it has no "
                     "conversion error to analyse");
  run.height_m = ErrorAnalysisHeight(request, rig, limits);
  CheckErrorAnalysisOptions(request, run.height_m);
  const auto [head, virtual_px] = ChooseAnalysisTarget(request, rig, run.height_m);
  AnalyseErrors(request, rig, limits, run.height_m, head, virtual_px, file_stem, plots, &run);
  run.document = stitch::ErrorAnalysisToJson(
      rig, run.height_m, limits, run.target, run.grid.get(), request.relief_m, run.files);
  run.document["camera_models"] = HeadCameraModels(rig);
  return run;
}

}  // namespace aerocal::tools
