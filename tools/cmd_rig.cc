// aerocal rig: multi-head rigs (stitch/rig/). `rig stitch`: the per-exposure self-calibrating
// stitching of a rig block (stitch/rig/self_calibration.h) from a project's head observations.
// `rig convert`: the head images of one exposure -> the virtual image (stitch/rig/rig_convert.h).
// `rig error-analysis`: the conversion error analysis of the virtual image
// (stitch/rig/error_analysis.h) at one target or over a grid of targets, result.json plus histogram
// / bound-map CSV files and, through tools/report/rig_error_plots.py (matplotlib), their PNG plots.

#include "calib/camera/camera_model_json.h"
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/finding.h"
#include "calib/core/progress.h"
#include "calib/core/result_file.h"
#include "stitch/image_io/image_io.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/rig/dem_grid.h"
#include "stitch/rig/error_analysis.h"
#include "stitch/rig/error_analysis_json.h"
#include "stitch/rig/rig_conversion.h"
#include "stitch/rig/rig_convert.h"
#include "stitch/rig/rig_design.h"
#include "stitch/rig/rig_tie_matching.h"
#include "stitch/rig/self_calibration.h"
#include "stitch/rig/self_calibration_json.h"
#include "stitch/rig/stitched_image.h"
#include "tools/command_registry.h"
#include "tools/image_sources.h"
#include "tools/option_ranges.h"
#include "tools/output_set.h"
#include "tools/python_script.h"
#include "tools/rig_design_document.h"
#include "tools/rig_error_analysis_run.h"
#include "tools/rig_stitch_run.h"
#include "tools/rig_stitched_image_run.h"
#include "tools/suspect_effect_option.h"
#include "triangulation/block/block_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

// The command's options: the request and the outputs.
struct ErrorAnalysisArgs {
  RigErrorAnalysisRequest request;
  std::string out;
  bool no_plots = false;
};

std::string PlotScript() {
  if (const char* env = std::getenv("AEROCAL_RIG_PLOT_SCRIPT")) return env;
  return (fs::path(AEROCAL_REPORT_SCRIPT).parent_path() / "rig_error_plots.py").string();
}

// The summary for people: the target's error per source, the worst case, the linear and the
// Monte-Carlo bounds, the grid.
void PrintErrorAnalysis(const RigErrorAnalysisRequest& args,
                        const calib::Rig& rig,
                        double height_m,
                        const stitch::TargetAnalysis& target,
                        const stitch::GridAnalysis* grid) {
  std::printf(
      "conversion error at virtual pixel (%.2f, %.2f) = head %s pixel (%.2f, %.2f), "
      "H = %g m\n",
      target.virtual_px.x(),
      target.virtual_px.y(),
      rig.heads[target.head].id.c_str(),
      target.head_px.x(),
      target.head_px.y(),
      height_m);
  std::printf("%-12s %10s %10s %10s %10s   (px, ex = d col, ey = -d row)\n",
              "source",
              "+ex",
              "+ey",
              "-ex",
              "-ey");
  for (const auto& row : target.per_source)
    std::printf("%-12s %10.4f %10.4f %10.4f %10.4f\n",
                row.source.c_str(),
                row.plus_px.x(),
                row.plus_px.y(),
                row.minus_px.x(),
                row.minus_px.y());
  const auto& all = target.worst_cases.back();
  std::printf("maximum error (all sources, worst corner): |ex| %.3f |ey| %.3f radial %.3f px\n",
              all.max_abs_px.x(),
              all.max_abs_px.y(),
              all.max_radial_px);
  std::printf("linear: sigma %.4f %.4f px, 99.75 %% bound %.3f %.3f px, radial %.3f px\n",
              target.linear.sigma_px.x(),
              target.linear.sigma_px.y(),
              target.linear.bound_px.x(),
              target.linear.bound_px.y(),
              target.linear.bound_radial_px);
  if (target.monte_carlo)
    std::printf(
        "monte-carlo (n %d, seed %llu): sigma %.4f %.4f px, 99.75 %% bound %.3f %.3f px, "
        "radial %.3f px, largest %.3f px\n",
        target.monte_carlo->n,
        static_cast<unsigned long long>(args.seed),
        target.monte_carlo->sigma_px.x(),
        target.monte_carlo->sigma_px.y(),
        target.monte_carlo->bound_px.x(),
        target.monte_carlo->bound_px.y(),
        target.monte_carlo->bound_radial_px,
        target.monte_carlo->max_radial_px);
  if (grid)
    std::printf("grid %d x %d: %zu targets, worst shown above; %zu grid points unseen\n",
                args.grid,
                args.grid,
                grid->points.size(),
                grid->unseen.size());
}

int RunErrorAnalysis(const ErrorAnalysisArgs& args) {
  CheckOutputFile(args.out, "--out");
  const fs::path out(args.out);
  const RigErrorAnalysisRun run =
      RunRigErrorAnalysis(args.request, out.stem().string(), !args.no_plots);
  const stitch::ErrorAnalysisFiles& files = run.files;
  const stitch::TargetAnalysis& target = run.target;
  const calib::Rig& rig = run.rig;
  const nlohmann::json& doc = run.document;
  // The JSON, its CSV files and plots are one set (tools/output_set.h): staged, then moved into
  // place together; a failing plot replaces nothing of an earlier analysis.
  OutputSet set(out.parent_path().string());
  std::vector<std::string> parts = {out.filename().string()};
  for (const std::string& name :
       {files.histogram_csv, files.bound_map_csv, files.histogram_png, files.bound_map_png})
    if (!name.empty()) parts.push_back(name);
  if (!files.histogram_csv.empty())
    WriteFileAtomically(set.Staged(files.histogram_csv),
                        stitch::HistogramCsv(*target.monte_carlo, args.request.bins));
  if (!files.bound_map_csv.empty())
    WriteFileAtomically(set.Staged(files.bound_map_csv), stitch::BoundMapCsv(rig, *run.grid));
  const std::string staged_json = set.Staged(out.filename().string());
  WriteResult(staged_json, "rig_error_analysis", doc);
  const bool plots =
      !args.no_plots && !(files.histogram_png.empty() && files.bound_map_png.empty());
  if (plots && !RunPythonScript(PlotScript(), {staged_json})) {
    std::fprintf(stderr,
                 "error: the plots could not be drawn (%s); nothing written, an earlier "
                 "analysis in the folder is left as it was\n",
                 PythonCommandLine(PlotScript(), {args.out}).c_str());
    return kExitInternal;
  }
  set.Commit(parts);

  PrintErrorAnalysis(args.request, rig, run.height_m, target, run.grid.get());
  return kExitOk;
}

// --tile-px of the TIFF outputs: 0 (strips) or the TIFF tile rule.
void CheckTilePx(int tile_px) {
  if (tile_px != 0 && !(tile_px % 16 == 0 && tile_px >= 16 && tile_px <= 4096))
    throw ConfigError("--tile-px must be 0 (strips) or a multiple of 16 in 16..4096 (got " +
                      std::to_string(tile_px) + ")");
}

struct ConvertArgs {
  std::string camera, images, opk_deg = "0,0,0", out, interp = "bilinear";
  double height_m = 0.0;  // 0: the rig file's virtual.height_m
  double fill = 0.0;
  double relief_m = 100.0;
  int strip_rows = 256;
  bool bigtiff = false;
  int tile_px = 0;  // > 0: tiled TIFF, tiles of tile_px x tile_px
  std::string dem;  // ESRI ASCII grid: the rectification surface instead of the plane
};

int RunConvert(const ConvertArgs& args) {
  // One output, the TIFF: written to a temporary file beside --out and renamed when complete
  // (stitch::TiffWriter), so a failure replaces nothing and leaves no temporary file.
  CheckOutputFile(args.out, "--out");
  CheckDistinctPath(args.out, "--out", args.dem, "--dem");
  CheckTilePx(args.tile_px);
  const calib::Rig rig = calib::ReadRig(args.camera);
  const double height_m = FlyingHeight(rig, args.height_m, args.camera);
  stitch::RigExposure exposure;
  const std::vector<std::string> angles = SplitCommaList(args.opk_deg, {true, true});
  for (int i = 0; i < 3; ++i) {
    const auto value = angles.size() == 3 ? ParseDouble(angles[i]) : std::nullopt;
    if (!value)
      throw ConfigError("--opk-deg: expected OMEGA,PHI,KAPPA in degrees (got '" + args.opk_deg +
                        "')");
    exposure.rig_opk_rad[i] = *value * M_PI / 180.0;
  }
  stitch::ResampleOptions options;
  options.interpolation = stitch::ParseInterpolation(args.interp);
  options.fill = args.fill;
  options.strip_rows = args.strip_rows;
  if (options.strip_rows < 1) throw ConfigError("--strip-rows must be > 0");
  const stitch::RigConverter converter(
      rig, exposure, stitch::MakeRectificationPlane(rig, exposure, height_m));
  const calib::Camera as_camera = stitch::RigExposureAsSubimageCamera(converter);
  std::vector<std::string> ids;
  for (const auto& head : rig.heads) ids.push_back(head.id);
  const auto owned = OpenImages(args.images, ids, "head", args.camera);
  std::vector<stitch::RasterSource*> sources;
  for (const auto& source : owned) sources.push_back(source.get());
  const stitch::RasterInfo info = sources.front()->Info();
  if (!(args.fill >= 0 && args.fill <= (info.bits == 8 ? 255.0 : 65535.0)))
    throw ConfigError("--fill must fit the " + std::to_string(info.bits) + "-bit images");
  stitch::TiffWriteOptions tiff;
  tiff.description = stitch::MappingDescription(
      as_camera,
      args.camera + " at H = " + FormatNumber(height_m) +
          " m (plane homographies; heads with distortion add correction grids)");
  tiff.force_bigtiff = args.bigtiff;
  tiff.tile_px = args.tile_px;
  std::optional<stitch::DemGrid> dem;  // read before the writer opens --out
  if (!args.dem.empty()) dem = stitch::ReadDemAscii(args.dem);
  stitch::TiffWriter writer(
      args.out, {as_camera.width_px, as_camera.height_px, info.bands, info.bits}, tiff);
  stitch::HeadMapCorrections corrections;
  const stitch::ResampleReport report = stitch::ConvertRigExposure(
      converter, sources, &writer, options, &corrections, dem ? &*dem : nullptr);
  writer.Commit();
  if (corrections.finest_step_px > 0)
    std::printf(
        "%s: correction grids down to %d px, largest interpolation error %.4f px against "
        "the exact map\n",
        dem ? "DEM surface" : "heads with distortion",
        corrections.finest_step_px,
        corrections.max_error_px);
  std::printf(
      "virtual image %d x %d px from %zu heads at H = %g m: %ld px covered, %ld in "
      "overlaps, %ld filled, %.2f s\n",
      as_camera.width_px,
      as_camera.height_px,
      rig.heads.size(),
      height_m,
      report.covered,
      report.overlap,
      report.filled,
      report.seconds);
  // Where the plane is not the terrain: relief displaces points between heads.
  const int reference = rig.ReferenceIndex();
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k)
    if (k != reference && args.relief_m < height_m)
      std::printf("relief of %g m off the plane: %.3f px between heads %s and %s\n",
                  args.relief_m,
                  stitch::ReliefDisplacementPx(rig, reference, k, height_m, args.relief_m),
                  rig.reference_head.c_str(),
                  rig.heads[k].id.c_str());
  return kExitOk;
}

struct StitchArgs {
  std::string camera, project, mode = "line", out;
  bool no_snooping = false;
  double alpha = 0.05;
  double increment_sigma_arcsec = 0.0;  // given only: weighted prior on every increment angle
  double dt_sigma_ms = 0.0;             // given only: weighted prior on every time offset
  double relief_m = 0.0;                // given only: relief of the block off the plane
  double standard_radius_px = 400.0;
  double max_sigma0 = 3.0;
  double suspect_effect_limit = 1.0;
  double default_sigma_px = 0.5;
  std::string images, stitched_out;  // head images <image>_<head>.tif; stitched images folder
  int tile_px = 256;
  bool bigtiff = false, no_balance = false;
  int feather_px = 64;
  bool match_ties = false;  // ties matched on the head images instead of observations.csv
  CLI::Option* increment_sigma_option = nullptr;
  CLI::Option* dt_sigma_option = nullptr;
  CLI::Option* relief_option = nullptr;
};

// The stitched image of every exposure with the refined increments and offsets (tools/
// rig_stitched_image_run.h): <image>.tif and <image>_mask.tif under --stitched-out; the figures as
// JSON.
nlohmann::json WriteStitchedImages(const StitchArgs& args,
                                   const RigStitchRun& run,
                                   OutputSet* set) {
  stitch::StitchedImageOptions options;
  options.balance = !args.no_balance;
  options.feather_px = args.feather_px;
  nlohmann::json out = nlohmann::json::array();
  Progress progress("stitched images", static_cast<long>(run.exposures.size()));
  for (const auto& e : run.exposures) {
    progress.Stage(e.image);
    if (RefinedExposure(run, e.image) == nullptr) continue;
    RigExposureImages heads = OpenRigExposureImages(run.rig, args.images, e.image);
    const calib::Camera& v = run.rig.virtual_camera.camera;
    stitch::TiffWriteOptions tiff;
    tiff.tile_px = args.tile_px;
    tiff.force_bigtiff = args.bigtiff;
    tiff.description = "aerocal rig stitch: stitched level virtual image of " + e.image + " (" +
                       args.camera + ", refined increments and offsets, z_ref " +
                       FormatNumber(e.z_ref_m) + " m)";
    const std::string image_path = args.stitched_out + "/" + e.image + ".tif";
    const std::string mask_path = args.stitched_out + "/" + e.image + "_mask.tif";
    stitch::TiffWriter image(
        set->StagePath(image_path), {v.width_px, v.height_px, 1, heads.bits()}, tiff);
    tiff.description = "aerocal rig stitch: valid-area mask of " + e.image + " (255 valid)";
    stitch::TiffWriter mask(set->StagePath(mask_path), {v.width_px, v.height_px, 1, 8}, tiff);
    const stitch::StitchedImageReport r =
        StitchRigExposure(run, e.image, heads, options, &image, &mask);
    image.Commit();
    mask.Commit();
    nlohmann::json entry = StitchedImageReportJson(r);
    entry.update({{"image", e.image},
                  {"file", image_path},
                  {"mask", mask_path},
                  {"bigtiff", image.bigtiff()},
                  {"tile_px", args.tile_px}});
    out.push_back(std::move(entry));
    std::printf(
        "stitched %s: %d x %d px, %ld valid, overlap disagreement %.3f DN RMS (head "
        "against head before blending, %ld px) -> %s\n",
        e.image.c_str(),
        r.width_px,
        r.height_px,
        r.valid_pixels,
        r.overall.rms_dn,
        r.overall.pixels,
        image_path.c_str());
    for (const auto& w : r.warnings)
      std::fprintf(stderr, "warning: %s: %s\n", e.image.c_str(), w.message.c_str());
    progress.Advance();
  }
  return out;
}

int RunStitch(const StitchArgs& args) {
  CheckOutputFile(args.out, "--out");
  if (!args.stitched_out.empty()) CheckOutputFolder(args.stitched_out, "--stitched-out");
  if (args.images.empty() && (!args.stitched_out.empty() || args.match_ties))
    throw ConfigError(std::string(args.match_ties ? "--match-ties" : "--stitched-out") +
                      " needs --images (the folder of the head images)");
  if (!args.images.empty() && args.stitched_out.empty() && !args.match_ties)
    throw ConfigError(
        "--images needs --stitched-out or --match-ties (what to do with the head "
        "images)");
  CheckTilePx(args.tile_px);
  if (!(args.feather_px >= 1 && args.feather_px <= 255))
    throw ConfigError("--feather-px must be within 1..255 (got " + std::to_string(args.feather_px) +
                      ")");
  if (!args.images.empty() && !fs::is_directory(args.images))
    throw ConfigError("--images must be a folder of head images (got '" + args.images + "')");
  RigStitchRequest request;
  request.camera = args.camera;
  request.project = args.project;
  request.mode = args.mode;
  request.no_snooping = args.no_snooping;
  request.alpha = args.alpha;
  if (args.increment_sigma_option->count() > 0)
    request.increment_sigma_arcsec = args.increment_sigma_arcsec;
  if (args.dt_sigma_option->count() > 0) request.dt_sigma_ms = args.dt_sigma_ms;
  if (args.relief_option->count() > 0) request.relief_m = args.relief_m;
  request.standard_radius_px = args.standard_radius_px;
  request.max_sigma0 = args.max_sigma0;
  request.suspect_effect_limit = args.suspect_effect_limit;
  request.default_sigma_px = args.default_sigma_px;
  request.images = args.images;
  request.match_ties = args.match_ties;
  request.need_head_images = !args.stitched_out.empty();
  RigStitchRun run = RunRigStitch(request);
  const stitch::RigStitchResult& result = run.result;
  nlohmann::json& json = run.json;
  std::fputs(run.printed.c_str(), stdout);
  // The JSON and the stitched images are one set (tools/output_set.h): a stitched image that
  // fails replaces neither the previous JSON nor any previous image.
  const fs::path out(args.out);
  OutputSet set(out.parent_path().string());
  if (!args.stitched_out.empty()) {
    if (result.failures.empty())
      json["stitched_images"] = WriteStitchedImages(args, run, &set);
    else
      std::fprintf(stderr, "error: no stitched images: the self-calibration is not valid\n");
  }
  WriteResult(set.Staged(out.filename().string()), "rig_stitch", json);
  set.Commit({out.filename().string()});
  if (result.failures.empty()) return kExitOk;
  for (const auto& f : result.failures) std::fprintf(stderr, "error: %s\n", f.c_str());
  std::fprintf(stderr, "error: %s written with valid: false\n", args.out.c_str());
  return kExitNotConverged;
}

struct DesignArgs {
  std::string camera, out, svg;
  double height_m = 0.0;  // 0: the rig file's virtual.height_m
  int grid_cells = 400;
};

int RunDesign(const DesignArgs& args) {
  const calib::Rig rig = calib::ReadRig(args.camera);
  const double height_m = FlyingHeight(rig, args.height_m, args.camera);
  if (args.grid_cells < 10 || args.grid_cells > 4000)
    throw ConfigError("--grid-cells must be within 10..4000 (got " +
                      std::to_string(args.grid_cells) + ")");
  const stitch::RigDesign d = stitch::DesignRig(rig, height_m, args.grid_cells);
  const calib::Camera& v = rig.virtual_camera.camera;
  const nlohmann::json doc = RigDesignDocument(rig, args.camera, height_m, d, args.svg);
  if (!args.svg.empty()) WriteFileAtomically(args.svg, stitch::RigDesignSvg(rig, d));
  if (!args.out.empty()) WriteResult(args.out, "rig_design", doc);

  std::printf(
      "rig %s at H = %g m (virtual GSD %.4f m)\n", rig.name.c_str(), height_m, d.virtual_gsd_m);
  std::printf(
      "%-6s %8s %10s   GSD ratio along / across the tilt: principal point, edges, corners\n",
      "head",
      "tilt",
      "nadir GSD");
  for (const auto& head : d.heads) {
    std::printf("%-6s %7.2f° %9.4fm  ", head.id.c_str(), head.tilt_deg, head.nadir_gsd_m);
    for (const auto& s : head.samples) std::printf(" %.3f/%.3f", s.ratio.x(), s.ratio.y());
    std::printf("\n");
  }
  std::printf(
      "virtual format needed %.0f x %.0f px (file: %d x %d); covered %.0f m^2; effective "
      "format %.0f x %.0f px (%.1f x %.1f m)\n",
      d.covered_box_px.Width(),
      d.covered_box_px.Height(),
      v.width_px,
      v.height_px,
      d.covered_area_m2,
      d.effective_px.Width(),
      d.effective_px.Height(),
      d.effective_px.Width() * d.virtual_gsd_m,
      d.effective_px.Height() * d.virtual_gsd_m);
  std::printf("overlap zones:");
  for (const auto& [zone, area] : d.zone_area_m2) std::printf(" %s %.0f m^2", zone.c_str(), area);
  std::printf("; %zu standard tie positions\n", d.standard_positions.size());
  return kExitOk;
}

// `rig error-analysis` and its options.
CLI::App* AddErrorAnalysis(CLI::App& app, const std::shared_ptr<ErrorAnalysisArgs>& args) {
  CLI::App* ea = app.add_subcommand(
      "error-analysis",
      "Conversion error analysis of the rig's virtual image: maximum error, linear propagation, "
      "Monte-Carlo, at one target or over a grid");
  ea->option_defaults()->always_capture_default();
  ea->add_option("--camera", args->request.camera, "Rig camera file (YAML with a rig section)")
      ->required();
  ea->add_option("--limits",
                 args->request.limits,
                 "Limits file: limits {principal_point_px, principal_distance_px, angles_arcsec, "
                 "lever_arm_mm, height_m}, sigmas")
      ->required();
  ea->add_option("--height-m",
                 args->request.height_m,
                 "Relative flying height of the rectification plane, m (default: the rig file's "
                 "virtual.height_m)")
      ->check(FiniteRange(0, 1e5));
  ea->add_option("--target",
                 args->request.target,
                 "HEAD:COL,ROW: a pixel of a non-reference head, carried into the virtual image by "
                 "the nominal rig (default: the centre of the first non-reference head)");
  ea->add_option("--virtual",
                 args->request.virtual_px,
                 "COL,ROW: a virtual pixel, analysed in the first non-reference head that sees it");
  ea->add_option("--grid", args->request.grid, "N: an N x N grid of virtual pixels (bound map)")
      ->check(FiniteRange(0, 200));
  ea->add_option("--samples", args->request.samples, "Monte-Carlo samples per target (0: none)")
      ->check(FiniteRange(0, 1e7));
  ea->add_option(
        "--seed", args->request.seed, "Monte-Carlo seed (the first grid target; +1 per target)")
      ->check(SeedCheck());
  ea->add_option("--bins", args->request.bins, "Histogram bins")->check(FiniteRange(1, 10000));
  ea->add_option("--relief-m",
                 args->request.relief_m,
                 "Relief (m off the plane) whose displacement between heads is reported")
      ->check(FiniteRange(0, 1e4));
  ea->add_flag("--no-plots", args->no_plots, "Write JSON and CSV only (no PNG)");
  ea->add_option("--out",
                 args->out,
                 "Output file: the result JSON; STEM_histogram.csv/.png or STEM_bound_map.csv/.png "
                 "beside it")
      ->required();
  return ea;
}

// `rig convert` and its options.
CLI::App* AddConvert(CLI::App& app, const std::shared_ptr<ConvertArgs>& convert) {
  CLI::App* cv = app.add_subcommand(
      "convert", "The images of one rig exposure -> the single-centre virtual image (TIFF)");
  cv->option_defaults()->always_capture_default();
  cv->add_option("--camera", convert->camera, "Rig camera file (YAML with a rig section)")
      ->required();
  cv->add_option("--images", convert->images, "Head images: A=a.tif,B=b.tif,...")->required();
  cv->add_option("--height-m",
                 convert->height_m,
                 "Relative flying height of the rectification plane, m (default: the rig file's "
                 "virtual.height_m)")
      ->check(FiniteRange(0, 1e5));
  cv->add_option("--opk-deg",
                 convert->opk_deg,
                 "Rig attitude omega,phi,kappa in degrees (matters for orientation: level)");
  cv->add_option(
        "--out", convert->out, "Output file: the virtual image (TIFF; BigTIFF beyond 4 GB)")
      ->required();
  cv->add_option("--interp", convert->interp, "bilinear | bicubic");
  cv->add_option("--fill", convert->fill, "Grey value of pixels no head covers")
      ->check(FiniteRange(0, 65535));
  cv->add_option("--strip-rows", convert->strip_rows, "Rows per processing strip (memory bound)")
      ->check(FiniteRange(1, 65536));
  cv->add_option("--relief-m",
                 convert->relief_m,
                 "Relief (m off the plane) whose displacement between heads is reported")
      ->check(FiniteRange(0, 1e4));
  cv->add_flag("--bigtiff", convert->bigtiff, "Write BigTIFF even when classic TIFF would do");
  cv->add_option("--tile-px",
                 convert->tile_px,
                 "Tiled TIFF: square tiles of N x N px (a multiple of 16, 16..4096); 0: strips")
      ->check(FiniteRange(0, 4096));
  cv->add_option(
      "--dem",
      convert->dem,
      "DEM (ESRI ASCII grid, object frame of the exposure) as the rectification surface; "
      "the plane at --height-m stays the base of the maps");
  return cv;
}

// `rig design` and its options.
CLI::App* AddDesign(CLI::App& app, const std::shared_ptr<DesignArgs>& design) {
  CLI::App* ds = app.add_subcommand(
      "design",
      "Design figures: GSD change ratios of the tilted heads, virtual format, covered "
      "area, effective format, overlap zones, standard tie positions, footprint plot");
  ds->option_defaults()->always_capture_default();
  ds->add_option("--camera", design->camera, "Rig camera file (YAML with a rig section)")
      ->required();
  ds->add_option("--height-m",
                 design->height_m,
                 "Relative flying height, m (default: the rig file's virtual.height_m)")
      ->check(FiniteRange(0, 1e5));
  ds->add_option(
      "--out", design->out, "Output file: the result JSON (optional; the summary is printed)");
  ds->add_option("--svg", design->svg, "Footprint plot (SVG, ground metres)");
  ds->add_option(
        "--grid-cells", design->grid_cells, "Coverage grid cells along the longer side, 10..4000")
      ->check(FiniteRange(10, 4000));
  return ds;
}

// `rig stitch`'s options of the head images: tie matching on them, the stitched images.
void AddStitchedImageOptions(CLI::App* st, StitchArgs* stitching) {
  st->add_option(
      "--images",
      stitching->images,
      "Folder of the head images <image>_<head>.tif (simulate --rig --render-images writes "
      "them under images/); with --stitched-out");
  st->add_option("--stitched-out",
                 stitching->stitched_out,
                 "Folder for the stitched level image of every exposure (<image>.tif, resampled "
                 "once with the refined increments and offsets, balanced, blended) and its "
                 "valid-area mask (<image>_mask.tif)");
  st->add_flag("--match-ties",
               stitching->match_ties,
               "Match the ties on the head images under --images (Foerstner + least-squares "
               "matching per overlap zone, on the level plane of the ground calibration and the "
               "POS) instead of reading them from observations.csv (which must have no rows)");
  st->add_option(
        "--tile-px",
        stitching->tile_px,
        "Stitched images: square TIFF tiles of this size (multiple of 16, 16..4096; 0: strips)")
      ->check(FiniteRange(0, 4096));
  st->add_flag(
      "--bigtiff", stitching->bigtiff, "Stitched images: BigTIFF even when classic TIFF would do");
  st->add_flag("--no-balance",
               stitching->no_balance,
               "Stitched images: no radiometric balance (every head gain 1, offset 0)");
  st->add_option("--feather-px",
                 stitching->feather_px,
                 "Stitched images: width of the blending ramp at each head's border, 1..255 px")
      ->check(FiniteRange(1, 255));
}

// `rig stitch` and its options (the stitched images' options last).
CLI::App* AddStitch(CLI::App& app, const std::shared_ptr<StitchArgs>& stitching) {
  CLI::App* st = app.add_subcommand(
      "stitch",
      "Self-calibrating stitching of a rig block: per-exposure attitude increments and "
      "shutter offsets of the heads from the overlap ties, stitching RMS before/after");
  st->option_defaults()->always_capture_default();
  st->add_option("--camera",
                 stitching->camera,
                 "Rig camera file, the ground calibration (YAML with a rig section, virtual "
                 "orientation level)")
      ->required();
  st->add_option("--project",
                 stitching->project,
                 "Project YAML (or folder): exposures.csv with z_ref (and vX,vY,vZ), "
                 "observations.csv with the head column, points.csv (role check: check tie)")
      ->required();
  st->add_option("--mode",
                 stitching->mode,
                 "line (one dT per head for the flight, angles per exposure) | per-exposure "
                 "(everything per exposure; correlations reported) | angles (dT held at 0)");
  st->add_option("--out", stitching->out, "Output file: the result JSON (kind rig_stitch)")
      ->required();
  st->add_flag("--no-snooping", stitching->no_snooping, "No data snooping of the tie observations");
  st->add_option("--alpha", stitching->alpha, "Family-wise level of the snooping, (0, 1)")
      ->check(FiniteRange(0, 1, true));
  stitching->increment_sigma_option =
      st->add_option(
            "--increment-sigma-arcsec",
            stitching->increment_sigma_arcsec,
            "Weighted prior (towards 0) on every increment angle, arcsec > 0 (default: none)")
          ->check(PositiveUpTo(36000));
  stitching->dt_sigma_option =
      st->add_option("--dt-sigma-ms",
                     stitching->dt_sigma_ms,
                     "Weighted prior (towards 0) on every time offset, ms > 0 (default: none)")
          ->check(PositiveUpTo(1e4));
  stitching->relief_option =
      st->add_option(
            "--relief-m",
            stitching->relief_m,
            "Relief of the block off the plane (m); its displacement between heads is reported")
          ->check(FiniteRange(-1e4, 1e4));
  st->add_option("--standard-radius-px",
                 stitching->standard_radius_px,
                 "A tie this close (virtual px) to a standard position of its zone counts for it")
      ->check(PositiveUpTo(1e5));
  st->add_option("--max-sigma0", stitching->max_sigma0, "sigma0 above: exit 3 (absurd), > 0")
      ->check(PositiveUpTo(1e6));
  AddSuspectEffectOption(*st, &stitching->suspect_effect_limit);
  st->add_option("--sigma-px",
                 stitching->default_sigma_px,
                 "Tie sigma (px) where observations.csv gives none")
      ->check(PositiveUpTo(100));
  AddStitchedImageOptions(st, stitching.get());
  return st;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto args = std::make_shared<ErrorAnalysisArgs>();
  auto convert = std::make_shared<ConvertArgs>();
  auto design = std::make_shared<DesignArgs>();
  auto stitching = std::make_shared<StitchArgs>();
  CLI::App* ea = AddErrorAnalysis(app, args);
  CLI::App* cv = AddConvert(app, convert);
  CLI::App* ds = AddDesign(app, design);
  CLI::App* st = AddStitch(app, stitching);
  return [args, ea, convert, cv, design, ds, stitching, st] {
    if (st->parsed()) return RunStitch(*stitching);
    if (ds->parsed()) return RunDesign(*design);
    if (ea->parsed()) return RunErrorAnalysis(*args);
    if (cv->parsed()) return RunConvert(*convert);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(rig,
                         "rig",
                         "Multi-head rigs: self-calibrating stitching, conversion to the virtual "
                         "image, its error analysis, design figures",
                         Setup);

}  // namespace aerocal::tools
