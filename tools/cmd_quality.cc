// aerocal quality: dynamic image resolution. `quality mtf` measures slanted edges (ISO 12233
// e-SFR, stitch/quality/slanted_edge.h) in regions of one image and writes their MTF, MTF50 with
// its GUM budget, and the same in lp/mm and as a ground resolved distance; `quality bars` the
// contrast transfer of bar groups and the limiting frequency at a threshold
// (stitch/quality/bar_target.h); `quality star` the same per radius of a Siemens star
// (stitch/quality/siemens_star.h). stitch/quality/README.md.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "stitch/image_io/image_io.h"
#include "stitch/quality/bar_target.h"
#include "stitch/quality/quality_json.h"
#include "stitch/quality/siemens_star.h"
#include "stitch/quality/slanted_edge.h"
#include "tools/command_registry.h"
#include "tools/edge_target_regions.h"
#include "tools/option_ranges.h"
#include "tools/resampling_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>
#include <sstream>

namespace aerocal::tools {
namespace {

// The units of the report, for the options every `quality` command shares.
struct GroundArgs {
  double gsd_m = 0.0, gsd_sigma_m = 0.0, pixel_mm = 0.0;
  void Add(CLI::App* app) {
    app->add_option(
           "--pixel-size-mm", pixel_mm, "Pixel size (mm): frequencies also in line pairs per mm")
        ->check(PositiveUpTo(1));
    app->add_option("--gsd-m",
                    gsd_m,
                    "Ground sample distance (m): frequencies as a ground resolved distance")
        ->check(PositiveUpTo(1e4));
    app->add_option(
           "--gsd-sigma-m", gsd_sigma_m, "Standard uncertainty of the GSD (m), from the adjustment")
        ->check(FiniteRange(0, 1e4));
  }
  void Check() const {
    if (gsd_sigma_m > 0.0 && gsd_m <= 0.0) throw ConfigError("--gsd-sigma-m needs --gsd-m");
  }
  void Write(nlohmann::json* doc) const {
    if (pixel_mm > 0.0) (*doc)["pixel_size_mm"] = pixel_mm;
    if (gsd_m > 0.0) (*doc)["gsd_m"] = gsd_m, (*doc)["gsd_sigma_m"] = gsd_sigma_m;
  }
};

struct MtfArgs {
  std::string image, out, flight_axis;
  std::string sub_image;  // the raw sub-image / head the image shows ("" = not a raw image)
  bool virtual_image = false;
  std::vector<std::string> rois;
  double gamma = 1.0;
  int oversampling = 4;
  GroundArgs ground;
  // --targets: the regions from edge targets and the image's adjusted orientation.
  std::string targets, camera, orientation, image_id, origin;  // origin: "" when not given
  std::vector<std::string> only_targets;
  // --sub-image with --targets: the mappings into the raw sub-image, the virtual image's file.
  std::string mapping, frame, virtual_file, virtual_origin = "0,0";
  double target_length_px = 64.0, target_half_width_px = 32.0;
};

// One region to measure: how the user or the target file named it, and what the target adds.
struct MtfRegion {
  std::string label;  // "--roi TEXT" or "target ID"
  stitch::PixelRegion region;
  nlohmann::json extra = nlohmann::json::object();
  std::optional<FoundEdgeRegion> found;  // a target's: compared with the virtual image when raw
};

// What --targets found beyond the regions: the raw sub-image's mapping (with --sub-image) and the
// virtual image's file to measure the same edges in.
struct TargetContext {
  std::optional<calib::SubimageMapping> subimage;
  std::optional<stitch::GrayImage> virtual_image;
  VirtualWindow window;
};

struct StarArgs {
  std::string image, out, centre;
  int cycles = 0, steps_per_octave = 12;
  double outer_radius_px = 0.0, inner_radius_px = 0.0, gamma = 1.0, threshold = 0.1;
  GroundArgs ground;
};

struct BarsArgs {
  std::string image, out, bright, dark;
  std::vector<std::string> groups;
  double gamma = 1.0, threshold = 0.1;
  GroundArgs ground;
};

// "col,row,width,height" in px; ConfigError naming `option` otherwise.
stitch::PixelRegion ParseRegion(const std::string& text, const std::string& option = "--roi") {
  stitch::PixelRegion region;
  std::istringstream in(text);
  char c1 = 0, c2 = 0, c3 = 0;
  std::string rest;
  if (!(in >> region.col >> c1 >> region.row >> c2 >> region.width >> c3 >> region.height) ||
      c1 != ',' || c2 != ',' || c3 != ',' || (in >> rest))
    throw ConfigError(option + ": expected col,row,width,height in px (got '" + text + "')");
  return region;
}

// "frequency,col,row,width,height[,x|y]": a bar group (frequency in cycles/px, axis across the
// bars, x by default); ConfigError naming --group otherwise.
stitch::BarGroup ParseGroup(const std::string& text) {
  const size_t comma = text.find(',');
  stitch::BarGroup group;
  std::string rest = comma == std::string::npos ? "" : text.substr(comma + 1);
  char* end = nullptr;
  group.frequency_cy_px = std::strtod(text.c_str(), &end);
  if (comma == std::string::npos || end != text.c_str() + comma || !(group.frequency_cy_px > 0.0) ||
      group.frequency_cy_px > 0.5)
    throw ConfigError(
        "--group: expected frequency (0 < f <= 0.5 cycles/px),col,row,width,height[,x|y] (got '" +
        text + "')");
  if (rest.size() > 2 &&
      (rest.substr(rest.size() - 2) == ",x" || rest.substr(rest.size() - 2) == ",y")) {
    group.axis = rest.back() == 'x' ? stitch::MtfAxis::kX : stitch::MtfAxis::kY;
    rest.resize(rest.size() - 2);
  }
  group.region = ParseRegion(rest, "--group " + text);
  return group;
}

// The flight direction's image axis names an edge's direction: an MTF along it is along track.
std::string Direction(stitch::MtfAxis axis, const std::string& flight_axis) {
  if (flight_axis.empty()) return "";
  return std::string(stitch::MtfAxisName(axis)) == flight_axis ? "along_track" : "across_track";
}

// `prefix`_lp_per_mm and `prefix`_resolved_distance_m of frequency f (cycles/px); with `u` (the
// frequency's standard uncertainty, >= 0) also their U (k = 2); without (u < 0) none.
void AddGround(
    const GroundArgs& args, double f, double u, const std::string& prefix, nlohmann::json* json) {
  if (!std::isfinite(f) || f <= 0.0) return;
  const stitch::GroundResolution g =
      stitch::ToGroundResolution(f, std::max(u, 0.0), args.pixel_mm, args.gsd_m, args.gsd_sigma_m);
  if (args.pixel_mm > 0.0) {
    (*json)[prefix + "_lp_per_mm"] = g.lp_per_mm;
    if (u >= 0.0) (*json)[prefix + "_lp_per_mm_expanded"] = 2.0 * g.lp_per_mm_u;
  }
  if (args.gsd_m > 0.0) {
    (*json)[prefix + "_resolved_distance_m"] = g.resolved_distance_m;
    if (u >= 0.0) (*json)[prefix + "_resolved_distance_expanded_m"] = 2.0 * g.resolved_distance_u_m;
  }
}

// "col,row" in px (sub-pixel); ConfigError naming `option` otherwise.
Eigen::Vector2d ParsePoint(const std::string& text, const std::string& option) {
  std::istringstream in(text);
  double col = 0, row = 0;
  char comma = 0;
  std::string rest;
  if (!(in >> col >> comma >> row) || comma != ',' || (in >> rest) || !std::isfinite(col) ||
      !std::isfinite(row))
    throw ConfigError(option + ": expected col,row in px (got '" + text + "')");
  return {col, row};
}

// "col,row" in whole pixels within +-1e7 (a file's top-left pixel in a larger image).
Eigen::Vector2i WholePixels(const std::string& text, const std::string& option) {
  const Eigen::Vector2d origin = ParsePoint(text, option);
  if (origin != origin.array().round().matrix() || origin.cwiseAbs().maxCoeff() > 1e7)
    throw ConfigError(option + ": whole pixels within +-1e7 expected (got '" + text + "')");
  return origin.cast<int>();
}

// --image-origin, 0,0 when not given (the file is the whole image).
Eigen::Vector2i ImageOrigin(const MtfArgs& args) {
  return args.origin.empty() ? Eigen::Vector2i(0, 0) : WholePixels(args.origin, "--image-origin");
}

void CheckTargetArgs(const MtfArgs& args) {
  if (args.rois.empty() && args.targets.empty())
    throw ConfigError("quality mtf: give the edge regions with --roi or --targets");
  const bool raw_targets = !args.targets.empty() && !args.sub_image.empty();
  if (!raw_targets && !(args.mapping.empty() && args.frame.empty() && args.virtual_file.empty()))
    throw ConfigError("--mapping, --frame and --virtual-image need --targets and --sub-image");
  if (!args.frame.empty() && args.mapping.empty()) throw ConfigError("--frame needs --mapping");
  if (args.targets.empty()) return;
  if (args.camera.empty() || args.orientation.empty() || args.image_id.empty())
    throw ConfigError("--targets needs --camera, --orientation and --image-id");
  ImageOrigin(args);
  WholePixels(args.virtual_origin, "--virtual-origin");
}

// The raw sub-image --sub-image names, in the camera with --mapping's mappings; ConfigError naming
// --sub-image for an id the camera lacks.
calib::SubimageMapping RawSubimage(const MtfArgs& args, const calib::Camera& camera) {
  const calib::Camera mapped =
      args.mapping.empty() ? camera : CameraWithMappings(camera, args.mapping, args.frame);
  const int k = mapped.SubimageIndex(args.sub_image);
  if (k < 0) {
    std::string ids;
    for (const auto& s : mapped.subimages) ids += (ids.empty() ? "" : ", ") + s.id;
    throw ConfigError("--sub-image: no sub-image '" + args.sub_image + "' in " + args.camera +
                      " (it has " + (ids.empty() ? "none" : ids) + ")");
  }
  return mapped.subimages[k];
}

// `doc`'s `targets` table: the inputs, how many were found, the skipped by name (also printed).
void WriteTargetTable(const MtfArgs& args,
                      const FoundEdgeRegions& found,
                      const ExposureOrientation& orientation,
                      nlohmann::json* doc) {
  nlohmann::json skipped = nlohmann::json::array();
  for (const auto& [id, reason] : found.skipped) {
    skipped.push_back({{"id", id}, {"reason", reason}});
    std::printf("target %s skipped: %s\n", id.c_str(), reason.c_str());
  }
  const Eigen::Vector2i origin = ImageOrigin(args);
  (*doc)["targets"] = {{"file", args.targets},
                       {"camera", args.camera},
                       {"orientation", args.orientation},
                       {"image_id", args.image_id},
                       {"image_origin_px", {origin.x(), origin.y()}},
                       {"length_px", args.target_length_px},
                       {"half_width_px", args.target_half_width_px},
                       {"found", found.found.size()},
                       {"skipped_count", found.skipped.size()},
                       {"skipped", skipped}};
  if (!orientation.adjustment.empty()) (*doc)["targets"]["adjustment"] = orientation.adjustment;
  if (!args.mapping.empty()) (*doc)["targets"]["mapping"] = args.mapping;
  if (!args.frame.empty()) (*doc)["targets"]["frame"] = args.frame;
}

// The regions of --targets in `image` (the virtual image, or with --sub-image that raw sub-image
// through --mapping), each with its target's id, projected edge, local GSD and its position in
// the virtual image; the skipped targets by name into `doc`'s `targets` table.
std::vector<MtfRegion> TargetRegions(const MtfArgs& args,
                                     const stitch::GrayImage& image,
                                     TargetContext* context,
                                     nlohmann::json* doc) {
  const std::vector<stitch::EdgeTarget> targets = ReadEdgeTargets(args.targets);
  const calib::Camera camera = calib::ReadCamera(args.camera);
  if (!args.sub_image.empty()) context->subimage = RawSubimage(args, camera);
  const ExposureOrientation orientation = ReadExposureOrientation(args.orientation, args.image_id);
  stitch::EdgeTargetRegionOptions options;
  options.max_length_px = args.target_length_px;
  options.half_width_px = args.target_half_width_px;
  const FoundEdgeRegions found = FindEdgeRegions(camera,
                                                 orientation,
                                                 targets,
                                                 args.only_targets,
                                                 ImageOrigin(args),
                                                 static_cast<int>(image.cols()),
                                                 static_cast<int>(image.rows()),
                                                 options,
                                                 context->subimage ? &*context->subimage : nullptr);
  std::vector<MtfRegion> regions;
  for (const FoundEdgeRegion& f : found.found) {
    const nlohmann::json extra = {
        {"target", f.target.id},
        {"projected_start_px", {f.target.start_px.x(), f.target.start_px.y()}},
        {"projected_end_px", {f.target.end_px.x(), f.target.end_px.y()}},
        {"projected_offset_px", f.projected_offset_px},
        {"target_gsd_m", f.target.gsd_m},
        {"position_virtual_px", RegionCentreJson(f.in_virtual.region, {0, 0})}};
    regions.push_back({"target " + f.target.id, f.region, extra, f});
  }
  WriteTargetTable(args, found, orientation, doc);
  (*doc)["virtual_format_px"] = {camera.width_px, camera.height_px};
  return regions;
}

// One region measured: the edge's JSON with its region, target, direction, ground units and,
// for a raw sub-image's target edge, the comparison with the virtual image.
nlohmann::json MeasureRegion(const MtfArgs& args,
                             const stitch::GrayImage& image,
                             const MtfRegion& region,
                             const stitch::SlantedEdgeOptions& options,
                             const TargetContext& context,
                             stitch::SlantedEdgeResult* result) {
  try {
    *result = stitch::MeasureSlantedEdge(image, region.region, options);
  } catch (const InputError& e) {
    throw InputError(region.label + ": " + args.image + ": " + e.what());
  }
  const stitch::SlantedEdgeResult& r = *result;
  nlohmann::json edge = stitch::SlantedEdgeToJson(r);
  const stitch::PixelRegion& roi = region.region;
  edge["roi"] = {roi.col, roi.row, roi.width, roi.height};
  edge.update(region.extra);
  // A --roi of the virtual image: its place in the format (the file's origin added). Only with
  // --image-origin: a file of patches cut from several exposures (a mosaic) has no one place.
  if (args.virtual_image && !region.found && !args.origin.empty())
    edge["position_virtual_px"] = RegionCentreJson(roi, ImageOrigin(args));
  if (context.subimage && region.found)
    edge["resampling"] =
        ResamplingComparisonJson(r, *region.found, *context.subimage, context.window, options);
  const std::string direction = Direction(r.axis, args.flight_axis);
  if (!direction.empty()) edge["direction"] = direction;
  AddGround(args.ground, r.mtf50_cy_px, r.mtf50_u_cy_px, "mtf50", &edge);
  std::printf(
      "%s: MTF along %s, slant %.2f deg, MTF50 %.4f +- %.4f cycles/px (U, k = 2), "
      "MTF at Nyquist %.3f\n",
      region.label.c_str(),
      std::string(stitch::MtfAxisName(r.axis)).c_str(),
      r.angle_deg,
      r.mtf50_cy_px,
      r.mtf50_expanded_cy_px,
      r.mtf_nyquist);
  return edge;
}

int RunMtf(const MtfArgs& args) {
  CheckOutputFile(args.out, "--out");
  std::vector<MtfRegion> regions;
  for (const auto& text : args.rois)
    regions.push_back({"--roi " + text, ParseRegion(text), nlohmann::json::object(), std::nullopt});
  CheckTargetArgs(args);
  args.ground.Check();
  stitch::SlantedEdgeOptions options;
  options.gamma = args.gamma;
  options.oversampling = args.oversampling;
  const stitch::GrayImage image = stitch::ReadGrayImage(args.image);
  nlohmann::json doc = nlohmann::json::object();
  TargetContext context;
  if (!args.targets.empty())
    for (MtfRegion& r : TargetRegions(args, image, &context, &doc)) regions.push_back(std::move(r));
  if (!args.virtual_file.empty()) {
    context.virtual_image = stitch::ReadGrayImage(args.virtual_file);
    context.window = {&*context.virtual_image,
                      args.virtual_file,
                      WholePixels(args.virtual_origin, "--virtual-origin")};
  }

  nlohmann::json edges = nlohmann::json::array();
  std::vector<stitch::SlantedEdgeResult> per_axis[2];
  bool determined = true;
  for (const MtfRegion& region : regions) {
    stitch::SlantedEdgeResult r;
    edges.push_back(MeasureRegion(args, image, region, options, context, &r));
    determined = determined && std::isfinite(r.mtf50_cy_px);
    if (std::isfinite(r.mtf50_cy_px)) per_axis[r.axis == stitch::MtfAxis::kX ? 0 : 1].push_back(r);
  }
  nlohmann::json axes = nlohmann::json::object();
  for (int a = 0; a < 2; ++a) {
    if (per_axis[a].size() < 2) continue;
    const stitch::MtfAxis axis = a == 0 ? stitch::MtfAxis::kX : stitch::MtfAxis::kY;
    const stitch::EdgeMtfCombination c = stitch::CombineEdgeMeasurements(per_axis[a]);
    nlohmann::json combined = stitch::EdgeCombinationToJson(c);
    const std::string direction = Direction(axis, args.flight_axis);
    if (!direction.empty()) combined["direction"] = direction;
    AddGround(args.ground, c.mtf50_cy_px, c.mtf50_u_cy_px, "mtf50", &combined);
    axes[std::string(stitch::MtfAxisName(axis))] = combined;
  }
  // An image where every target was skipped measured nothing: not determined (exit 3).
  determined = determined && !regions.empty();
  doc.update({{"image", args.image},
              {"width_px", image.cols()},
              {"height_px", image.rows()},
              {"method", "ISO 12233:2017 e-SFR (slanted edge)"},
              {"options", {{"gamma", args.gamma}, {"oversampling", args.oversampling}}},
              {"edges", edges},
              {"axes", axes},
              {"determined", determined}});
  args.ground.Write(&doc);
  if (!args.flight_axis.empty()) doc["flight_axis"] = args.flight_axis;
  // Which image of a multi-CCD / multi-head camera: the resampling loss (virtual against the raw
  // sub-images' mean, tools/dynamic_resolution.h) compares results by it.
  if (!args.sub_image.empty()) doc["image_kind"] = "raw", doc["sub_image"] = args.sub_image;
  if (args.virtual_image) doc["image_kind"] = "virtual";
  WriteResult(args.out, "quality_mtf", doc);
  return determined ? kExitOk : kExitNotConverged;
}

int RunBars(const BarsArgs& args) {
  CheckOutputFile(args.out, "--out");
  std::vector<stitch::BarGroup> groups;
  for (const auto& text : args.groups) groups.push_back(ParseGroup(text));
  const stitch::PixelRegion bright = ParseRegion(args.bright, "--bright");
  const stitch::PixelRegion dark = ParseRegion(args.dark, "--dark");
  args.ground.Check();
  stitch::BarTargetOptions options;
  options.gamma = args.gamma;
  options.threshold = args.threshold;
  const stitch::GrayImage image = stitch::ReadGrayImage(args.image);
  stitch::BarTargetResult r;
  try {
    r = stitch::MeasureBarTarget(image, groups, bright, dark, options);
  } catch (const InputError& e) {
    throw InputError("--group/--bright/--dark: " + args.image + ": " + e.what());
  }
  nlohmann::json out_groups = nlohmann::json::array();
  for (const auto& g : r.groups) {
    nlohmann::json j = {{"frequency_cy_px", g.frequency_cy_px},
                        {"modulation", g.modulation},
                        {"contrast_transfer", g.contrast_transfer}};
    AddGround(args.ground, g.frequency_cy_px, -1.0, "frequency", &j);
    out_groups.push_back(j);
    std::printf("bars at %.4f cycles/px: modulation %.4f, contrast transfer %.4f\n",
                g.frequency_cy_px,
                g.modulation,
                g.contrast_transfer);
  }
  const bool determined = std::isfinite(r.limiting_frequency_cy_px);
  nlohmann::json doc = {{"image", args.image},
                        {"method", "bar target contrast transfer, limit at a threshold"},
                        {"options", {{"gamma", args.gamma}, {"threshold", args.threshold}}},
                        {"reference_modulation", r.reference_modulation},
                        {"groups", out_groups},
                        {"limit_in_range", r.limit_in_range},
                        {"determined", determined}};
  doc["limiting_frequency_cy_px"] =
      determined ? nlohmann::json(r.limiting_frequency_cy_px) : nlohmann::json();
  if (determined)
    AddGround(args.ground, r.limiting_frequency_cy_px, -1.0, "limiting", &doc);  // no U yet
  args.ground.Write(&doc);
  WriteResult(args.out, "quality_bars", doc);
  if (determined)
    std::printf("limiting frequency at %.0f %% contrast transfer: %.4f cycles/px%s\n",
                100.0 * args.threshold,
                r.limiting_frequency_cy_px,
                r.limit_in_range ? "" : " (or higher: every group resolved)");
  else
    std::printf("no group reaches %.0f %% contrast transfer\n", 100.0 * args.threshold);
  return determined ? kExitOk : kExitNotConverged;
}

int RunStar(const StarArgs& args) {
  CheckOutputFile(args.out, "--out");
  args.ground.Check();
  stitch::SiemensStar star;
  star.centre_px = ParsePoint(args.centre, "--centre");
  star.cycles = args.cycles;
  star.outer_radius_px = args.outer_radius_px;
  star.inner_radius_px = args.inner_radius_px;
  stitch::SiemensStarOptions options;
  options.gamma = args.gamma;
  options.threshold = args.threshold;
  options.steps_per_octave = args.steps_per_octave;
  const stitch::GrayImage image = stitch::ReadGrayImage(args.image);
  stitch::SiemensStarResult r;
  try {
    r = stitch::MeasureSiemensStar(image, star, options);
  } catch (const InputError& e) {
    throw InputError("--centre/--cycles/--outer-radius-px: " + args.image + ": " + e.what());
  }
  nlohmann::json rings = nlohmann::json::array();
  for (const auto& ring : r.rings) {
    nlohmann::json j = {{"radius_px", ring.radius_px},
                        {"frequency_cy_px", ring.frequency_cy_px},
                        {"modulation", ring.modulation},
                        {"contrast_transfer", ring.contrast_transfer},
                        {"pixels", ring.pixels}};
    AddGround(args.ground, ring.frequency_cy_px, -1.0, "frequency", &j);
    rings.push_back(j);
  }
  const bool determined = std::isfinite(r.limiting_frequency_cy_px);
  nlohmann::json doc = {
      {"image", args.image},
      {"method", "Siemens star: fundamental modulation per ring, limit at a threshold"},
      {"star",
       {{"centre_px", {star.centre_px.x(), star.centre_px.y()}},
        {"cycles", star.cycles},
        {"outer_radius_px", star.outer_radius_px},
        {"inner_radius_px", star.inner_radius_px}}},
      {"options",
       {{"gamma", args.gamma},
        {"threshold", args.threshold},
        {"steps_per_octave", args.steps_per_octave}}},
      {"reference_modulation", r.reference_modulation},
      {"step_ratio", r.step_ratio},
      {"rings", rings},
      {"limit_in_range", r.limit_in_range},
      {"determined", determined}};
  doc["limiting_frequency_cy_px"] =
      determined ? nlohmann::json(r.limiting_frequency_cy_px) : nlohmann::json();
  if (determined) {
    AddGround(args.ground, r.limiting_frequency_cy_px, -1.0, "limiting", &doc);
    doc["limiting_radius_px"] = star.cycles / (2.0 * M_PI * r.limiting_frequency_cy_px);
  }
  args.ground.Write(&doc);
  WriteResult(args.out, "quality_star", doc);
  if (determined)
    std::printf(
        "limiting frequency at %.0f %% modulation transfer: %.4f cycles/px (radius %.1f px)%s\n",
        100.0 * args.threshold,
        r.limiting_frequency_cy_px,
        star.cycles / (2.0 * M_PI * r.limiting_frequency_cy_px),
        r.limit_in_range ? "" : " (or higher: every ring resolved)");
  else
    std::printf("no ring reaches %.0f %% modulation transfer\n", 100.0 * args.threshold);
  return determined ? kExitOk : kExitNotConverged;
}

// `quality star`'s options.
CLI::App* AddStar(CLI::App& app, StarArgs* star) {
  CLI::App* s = app.add_subcommand("star",
                                   "Siemens star: modulation transfer per radius (frequency) and "
                                   "the limiting frequency at a threshold");
  s->option_defaults()->always_capture_default();
  s->add_option("--image", star->image, "Grey-value image (8 or 16 bit)")->required();
  s->add_option("--centre", star->centre, "The star's centre col,row (px, sub-pixel)")->required();
  s->add_option("--cycles", star->cycles, "Bright + dark sector pairs round the star")
      ->check(FiniteRange(4, 10000))
      ->required();
  s->add_option("--outer-radius-px",
                star->outer_radius_px,
                "Largest radius measured, inside the star (px; 12 px or more per sector there)")
      ->check(PositiveUpTo(1e5))
      ->required();
  s->add_option("--inner-radius-px",
                star->inner_radius_px,
                "Smallest radius measured (px; 0: down to 0.5 cycles/px)")
      ->check(FiniteRange(0, 1e5));
  s->add_option("--steps-per-octave", star->steps_per_octave, "Radii per halving of the radius")
      ->check(FiniteRange(2, 96));
  s->add_option("--threshold",
                star->threshold,
                "Modulation transfer defining the limiting frequency, 0 < T < 1")
      ->check(FiniteRange(1e-6, 1.0 - 1e-6));
  s->add_option(
       "--gamma", star->gamma, "Linearisation: value = DN^gamma (1: linear data), 0 < G <= 10")
      ->check(FiniteRange(1e-6, 10.0));
  star->ground.Add(s);
  s->add_option(
       "--out", star->out, "Output file: the result JSON (kind quality_star, written atomically)")
      ->required();
  return s;
}

// `quality mtf --targets`'s options: the edge targets projected into the image, from the virtual
// image into a raw sub-image through a stitch result's mappings.
void AddMtfTargetOptions(CLI::App* m, MtfArgs* mtf) {
  m->add_option(
      "--targets",
      mtf->targets,
      "Edge targets' ground ends (targets.csv, docs/formats.md): the regions are found by "
      "projecting each edge with --camera and the image's orientation from --orientation");
  m->add_option("--camera", mtf->camera, "--targets: the adjusted camera file (YAML)");
  m->add_option("--orientation",
                mtf->orientation,
                "--targets: adjust or flight result.json holding the image's exterior orientation");
  m->add_option("--image-id", mtf->image_id, "--targets: the image's id in --orientation");
  m->add_option("--image-origin",
                mtf->origin,
                "The file's top-left pixel col,row in the full (virtual) image, for a file that "
                "is a window of it (default 0,0); with --virtual and --roi it gives each region "
                "its place in the virtual image (the report's MTF50 map), without it none");
  m->add_option("--target", mtf->only_targets, "--targets: measure only this edge id; repeat");
  m->add_option("--mapping",
                mtf->mapping,
                "--targets with --sub-image: the stitch result (or a flight result, its stitching) "
                "whose sub-image mappings carry each edge from the virtual image into the raw "
                "sub-image (default: the --camera file's own mappings)");
  m->add_option("--frame",
                mtf->frame,
                "--mapping: the mappings of this frame (exposure) of the stitch result (default: "
                "the top level's, a flight's mean)");
  m->add_option("--virtual-image",
                mtf->virtual_file,
                "--mapping: the virtual image resampled from the sub-image (or a window of it): "
                "each edge is measured there too and the resampling loss stated per edge");
  m->add_option("--virtual-origin",
                mtf->virtual_origin,
                "--virtual-image: the file's top-left pixel col,row in the full virtual image");
  m->add_option(
       "--target-length-px", mtf->target_length_px, "--targets: region length along the edge (px)")
      ->check(FiniteRange(16, 1e4));
  m->add_option("--target-half-width-px",
                mtf->target_half_width_px,
                "--targets: region width each side of the edge (px)")
      ->check(FiniteRange(8, 1e4));
}

// `quality mtf`'s options.
CLI::App* AddMtf(CLI::App& app, MtfArgs* mtf) {
  CLI::App* m = app.add_subcommand(
      "mtf",
      "Slanted-edge MTF (ISO 12233 e-SFR) of edge regions: MTF50, MTF at Nyquist, U (k = 2)");
  m->option_defaults()->always_capture_default();
  m->add_option(
       "--image", mtf->image, "Grey-value image (8 or 16 bit; colour is converted to grey)")
      ->required();
  m->add_option(
      "--roi",
      mtf->rois,
      "Edge region col,row,width,height (px, at least 16 x 16), one edge slanted by 1..35 "
      "deg; repeat for more edges (or --targets)");
  AddMtfTargetOptions(m, mtf);
  m->add_option(
       "--gamma", mtf->gamma, "Linearisation: value = DN^gamma (1: linear data), 0 < G <= 10")
      ->check(FiniteRange(1e-6, 10.0))
      ->capture_default_str();
  m->add_option("--oversampling", mtf->oversampling, "ESF bins per pixel (ISO 12233: 4)")
      ->check(FiniteRange(2, 16))
      ->capture_default_str();
  mtf->ground.Add(m);
  m->add_option("--flight-axis",
                mtf->flight_axis,
                "Image axis of the flight direction (x or y): names "
                "each MTF along or across track")
      ->check(CLI::IsMember({"x", "y"}));
  CLI::Option* sub_image = m->add_option(
      "--sub-image",
      mtf->sub_image,
      "The image is a raw sub-image (CCD) or head of this id: its MTF50 enters the raw mean the "
      "resampling loss is taken from");
  m->add_flag("--virtual",
              mtf->virtual_image,
              "The image is the stitched / resampled virtual image: its MTF50 is compared with the "
              "raw sub-images' mean (the resampling loss)")
      ->excludes(sub_image);
  m->add_option(
       "--out", mtf->out, "Output file: the result JSON (kind quality_mtf, written atomically)")
      ->required();
  return m;
}

// `quality bars`'s options.
CLI::App* AddBars(CLI::App& app, BarsArgs* bars) {
  CLI::App* b = app.add_subcommand(
      "bars",
      "Bar targets: contrast transfer per bar group and the limiting frequency at a threshold");
  b->option_defaults()->always_capture_default();
  b->add_option("--image", bars->image, "Grey-value image (8 or 16 bit)")->required();
  b->add_option(
       "--group",
       bars->groups,
       "Bar group frequency,col,row,width,height[,x|y]: its frequency in this image (cycles/px, "
       "<= 0.5), its region (two periods or more across the bars) and the axis across the bars "
       "(x: vertical bars, the default); repeat per group")
      ->required();
  b->add_option("--bright", bars->bright, "Large bright reference area col,row,width,height")
      ->required();
  b->add_option("--dark", bars->dark, "Large dark reference area col,row,width,height")->required();
  b->add_option("--threshold",
                bars->threshold,
                "Contrast transfer defining the limiting frequency, 0 < T < 1")
      ->check(FiniteRange(1e-6, 1.0 - 1e-6))
      ->capture_default_str();
  b->add_option(
       "--gamma", bars->gamma, "Linearisation: value = DN^gamma (1: linear data), 0 < G <= 10")
      ->check(FiniteRange(1e-6, 10.0))
      ->capture_default_str();
  bars->ground.Add(b);
  b->add_option(
       "--out", bars->out, "Output file: the result JSON (kind quality_bars, written atomically)")
      ->required();
  return b;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto mtf = std::make_shared<MtfArgs>();
  CLI::App* m = AddMtf(app, mtf.get());
  auto bars = std::make_shared<BarsArgs>();
  CLI::App* b = AddBars(app, bars.get());
  auto star = std::make_shared<StarArgs>();
  CLI::App* s = AddStar(app, star.get());
  return [mtf, m, bars, b, star, s] {
    if (m->parsed()) return RunMtf(*mtf);
    if (b->parsed()) return RunBars(*bars);
    if (s->parsed()) return RunStar(*star);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    quality,
    "quality",
    "Dynamic image resolution: slanted-edge MTF (ISO 12233 e-SFR) with GUM uncertainty, bar "
    "targets, Siemens stars",
    Setup);

}  // namespace aerocal::tools
