// aerocal quality: dynamic image resolution. `quality mtf` measures slanted edges (ISO 12233
// e-SFR, stitch/quality/slanted_edge.h) in regions of one image and writes their MTF, MTF50 with
// its GUM budget, and the same in lp/mm and as a ground resolved distance (stitch/quality/README.md).
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "stitch/image_io/image_io.h"
#include "stitch/quality/quality_json.h"
#include "stitch/quality/slanted_edge.h"
#include "tools/command_registry.h"

namespace aerocal::tools {
namespace {

struct MtfArgs {
  std::string image, out, flight_axis;
  std::vector<std::string> rois;
  double gamma = 1.0, gsd_m = 0.0, gsd_sigma_m = 0.0, pixel_mm = 0.0;
  int oversampling = 4;
};

// "col,row,width,height" in px; ConfigError naming --roi otherwise.
stitch::PixelRegion ParseRegion(const std::string& text) {
  stitch::PixelRegion region;
  std::istringstream in(text);
  char c1 = 0, c2 = 0, c3 = 0;
  std::string rest;
  if (!(in >> region.col >> c1 >> region.row >> c2 >> region.width >> c3 >> region.height) || c1 != ',' ||
      c2 != ',' || c3 != ',' || (in >> rest))
    throw ConfigError("--roi: expected col,row,width,height in px (got '" + text + "')");
  return region;
}

// The flight direction's image axis names an edge's direction: an MTF along it is along track.
std::string Direction(stitch::MtfAxis axis, const std::string& flight_axis) {
  if (flight_axis.empty()) return "";
  return std::string(stitch::MtfAxisName(axis)) == flight_axis ? "along_track" : "across_track";
}

void AddGround(const MtfArgs& args, double f, double u, const std::string& prefix, nlohmann::json* json) {
  if (!std::isfinite(f) || f <= 0.0) return;
  const stitch::GroundResolution g = stitch::ToGroundResolution(f, u, args.pixel_mm, args.gsd_m, args.gsd_sigma_m);
  if (args.pixel_mm > 0.0) {
    (*json)[prefix + "_lp_per_mm"] = g.lp_per_mm;
    (*json)[prefix + "_lp_per_mm_expanded"] = 2.0 * g.lp_per_mm_u;
  }
  if (args.gsd_m > 0.0) {
    (*json)[prefix + "_resolved_distance_m"] = g.resolved_distance_m;
    (*json)[prefix + "_resolved_distance_expanded_m"] = 2.0 * g.resolved_distance_u_m;
  }
}

int RunMtf(const MtfArgs& args) {
  CheckOutputFile(args.out, "--out");
  std::vector<stitch::PixelRegion> regions;
  for (const auto& text : args.rois) regions.push_back(ParseRegion(text));
  if (args.gsd_sigma_m > 0.0 && args.gsd_m <= 0.0) throw ConfigError("--gsd-sigma-m needs --gsd-m");
  stitch::SlantedEdgeOptions options;
  options.gamma = args.gamma;
  options.oversampling = args.oversampling;
  const stitch::GrayImage image = stitch::ReadGrayImage(args.image);

  nlohmann::json edges = nlohmann::json::array();
  std::vector<stitch::SlantedEdgeResult> per_axis[2];
  bool determined = true;
  for (size_t i = 0; i < regions.size(); ++i) {
    stitch::SlantedEdgeResult r;
    try {
      r = stitch::MeasureSlantedEdge(image, regions[i], options);
    } catch (const InputError& e) {
      throw InputError("--roi " + args.rois[i] + ": " + args.image + ": " + e.what());
    }
    nlohmann::json edge = stitch::SlantedEdgeToJson(r);
    edge["roi"] = {regions[i].col, regions[i].row, regions[i].width, regions[i].height};
    const std::string direction = Direction(r.axis, args.flight_axis);
    if (!direction.empty()) edge["direction"] = direction;
    AddGround(args, r.mtf50_cy_px, r.mtf50_u_cy_px, "mtf50", &edge);
    edges.push_back(edge);
    determined = determined && std::isfinite(r.mtf50_cy_px);
    if (std::isfinite(r.mtf50_cy_px)) per_axis[r.axis == stitch::MtfAxis::kX ? 0 : 1].push_back(r);
    std::printf("roi %s: MTF along %s, slant %.2f deg, MTF50 %.4f +- %.4f cycles/px (U, k = 2), "
                "MTF at Nyquist %.3f\n",
                args.rois[i].c_str(), std::string(stitch::MtfAxisName(r.axis)).c_str(), r.angle_deg,
                r.mtf50_cy_px, r.mtf50_expanded_cy_px, r.mtf_nyquist);
  }
  nlohmann::json axes = nlohmann::json::object();
  for (int a = 0; a < 2; ++a) {
    if (per_axis[a].size() < 2) continue;
    const stitch::MtfAxis axis = a == 0 ? stitch::MtfAxis::kX : stitch::MtfAxis::kY;
    const stitch::EdgeMtfCombination c = stitch::CombineEdgeMeasurements(per_axis[a]);
    nlohmann::json combined = stitch::EdgeCombinationToJson(c);
    const std::string direction = Direction(axis, args.flight_axis);
    if (!direction.empty()) combined["direction"] = direction;
    AddGround(args, c.mtf50_cy_px, c.mtf50_u_cy_px, "mtf50", &combined);
    axes[std::string(stitch::MtfAxisName(axis))] = combined;
  }
  nlohmann::json doc = {{"image", args.image},
                        {"width_px", image.cols()},
                        {"height_px", image.rows()},
                        {"method", "ISO 12233:2017 e-SFR (slanted edge)"},
                        {"options", {{"gamma", args.gamma}, {"oversampling", args.oversampling}}},
                        {"edges", edges},
                        {"axes", axes},
                        {"determined", determined}};
  if (args.pixel_mm > 0.0) doc["pixel_size_mm"] = args.pixel_mm;
  if (args.gsd_m > 0.0) doc["gsd_m"] = args.gsd_m, doc["gsd_sigma_m"] = args.gsd_sigma_m;
  if (!args.flight_axis.empty()) doc["flight_axis"] = args.flight_axis;
  WriteResult(args.out, "quality_mtf", doc);
  return determined ? kExitOk : kExitNotConverged;
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto mtf = std::make_shared<MtfArgs>();
  CLI::App* m = app.add_subcommand(
      "mtf", "Slanted-edge MTF (ISO 12233 e-SFR) of edge regions: MTF50, MTF at Nyquist, U (k = 2)");
  m->option_defaults()->always_capture_default();
  m->add_option("--image", mtf->image, "Grey-value image (8 or 16 bit; colour is converted to grey)")
      ->required();
  m->add_option("--roi", mtf->rois,
                "Edge region col,row,width,height (px, at least 16 x 16), one edge slanted by 1..35 "
                "deg; repeat for more edges")
      ->required();
  m->add_option("--gamma", mtf->gamma, "Linearisation: value = DN^gamma (1: linear data), 0 < G <= 10")
      ->check(CLI::Range(1e-6, 10.0))
      ->capture_default_str();
  m->add_option("--oversampling", mtf->oversampling, "ESF bins per pixel (ISO 12233: 4)")
      ->check(CLI::Range(2, 16))
      ->capture_default_str();
  m->add_option("--pixel-mm", mtf->pixel_mm, "Pixel size (mm): MTF50 also in line pairs per mm")
      ->check(CLI::PositiveNumber);
  m->add_option("--gsd-m", mtf->gsd_m, "Ground sample distance (m): MTF50 as a ground resolved distance")
      ->check(CLI::PositiveNumber);
  m->add_option("--gsd-sigma-m", mtf->gsd_sigma_m, "Standard uncertainty of the GSD (m), from the adjustment")
      ->check(CLI::NonNegativeNumber);
  m->add_option("--flight-axis", mtf->flight_axis, "Image axis of the flight direction (x or y): names "
                "each MTF along or across track")
      ->check(CLI::IsMember({"x", "y"}));
  m->add_option("--out", mtf->out, "Result JSON (kind quality_mtf, written atomically)")->required();
  return [mtf, m] {
    if (m->parsed()) return RunMtf(*mtf);
    return kExitInternal;
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(quality, "quality",
                         "Dynamic image resolution: slanted-edge MTF (ISO 12233 e-SFR) with GUM uncertainty",
                         Setup);

}  // namespace aerocal::tools
