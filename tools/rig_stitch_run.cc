#include "tools/rig_stitch_run.h"

#include "calib/camera/camera_model_json.h"
#include "calib/camera/rig_io.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/string_printf.h"
#include "stitch/image_io/image_io.h"
#include "stitch/rig/rig_design.h"
#include "stitch/rig/rig_tie_matching.h"
#include "triangulation/block/block_io.h"

#include <cmath>
#include <filesystem>
#include <map>

namespace aerocal::tools {

namespace fs = std::filesystem;

std::string HeadImagePath(const std::string& folder,
                          const std::string& image,
                          const std::string& head) {
  for (const char* ext : {".tif", ".tiff", ".png", ".jpg"}) {
    const std::string path = folder + "/" + image + "_" + head + ext;
    if (fs::exists(path)) return path;
  }
  throw InputError("--images: " + folder + "/" + image + "_" + head +
                   ".tif not found (the head images are <image>_<head>.tif)");
}

nlohmann::json HeadCameraModels(const calib::Rig& rig) {
  nlohmann::json models = nlohmann::json::object();
  for (const auto& head : rig.heads)
    models[head.id] = calib::CameraModelTableToJson(head.camera.model);
  return models;
}

namespace {

// The project's rig block as the library's inputs: every exposure with head observations (z_ref
// required, velocity optional), the points (role check: a check tie, never adjusted), the head
// observations with their lines for the snooping's labels.
struct StitchInputs {
  std::vector<stitch::RigStitchExposure> exposures;
  std::vector<stitch::RigStitchTie> ties;
  std::vector<stitch::RigStitchObservation> observations;
};

// An exposure of the project as the library's: POS, velocity (optional) and z_ref (required,
// below the rig centre; FILE:LINE otherwise).
stitch::RigStitchExposure StitchExposure(const triangulation::Project& project,
                                         const triangulation::Exposure& e) {
  if (!e.z_ref_m)
    ThrowInputError({project.exposures_file, e.line},
                    "image " + e.image +
                        " has no z_ref (rig stitch rectifies onto the level "
                        "plane Z = z_ref of each exposure)");
  if (!(e.center_m.z() > *e.z_ref_m))
    ThrowInputError({project.exposures_file, e.line},
                    "image " + e.image + ": z_ref (" + FormatNumber(*e.z_ref_m) +
                        " m) must lie below the rig centre Z (" + FormatNumber(e.center_m.z()) +
                        " m)");
  stitch::RigStitchExposure x;
  x.image = e.image;
  x.pose.rig_opk_rad = e.opk_rad;
  x.pose.rig_center_m = e.center_m;
  x.pose.velocity_mps = e.velocity_mps.value_or(Eigen::Vector3d::Zero());
  x.z_ref_m = *e.z_ref_m;
  return x;
}

StitchInputs StitchInputsFromProject(const triangulation::Project& project,
                                     const calib::Rig& rig,
                                     const std::string& camera_file) {
  StitchInputs in;
  std::map<std::string, int> tie_index, exposure_index;
  for (const auto& p : project.points) {
    tie_index[p.id] = static_cast<int>(in.ties.size());
    in.ties.push_back({p.id, p.role == triangulation::PointRole::kCheck});
  }
  for (const auto& o : project.observations) {
    const SourceRef where{project.observations_file, o.line};
    if (o.head.empty())
      ThrowInputError(where, "rig stitch needs head observations (observations.csv `head` column)");
    const int head = rig.HeadIndex(o.head);
    if (head < 0) ThrowInputError(where, "head '" + o.head + "' is not a head of " + camera_file);
    auto [it, added] = exposure_index.try_emplace(o.image, static_cast<int>(in.exposures.size()));
    if (added) in.exposures.push_back(StitchExposure(project, *project.FindExposure(o.image)));
    const std::string label =
        fs::path(project.observations_file).filename().string() + ":" + std::to_string(o.line);
    // A point observed but not listed in points.csv is a tie, as in the block adjustment.
    const auto [tie, new_tie] = tie_index.try_emplace(o.point, static_cast<int>(in.ties.size()));
    if (new_tie) in.ties.push_back({o.point, false});
    in.observations.push_back({it->second, head, tie->second, o.pixel, o.sigma_px, label});
  }
  if (in.observations.empty())
    throw InputError(project.observations_file + ": no head observations to stitch");
  return in;
}

// --match-ties: every exposure of the project, its ties matched on the head images under --images
// (stitch/rig/rig_tie_matching.h); observations.csv must have no rows. The zones' counts in
// `zones`, the RMS of the ties' LSM sigmas (virtual px) in `lsm_sigma_rms_px`.
StitchInputs MatchedStitchInputs(const triangulation::Project& project,
                                 const calib::Rig& rig,
                                 const std::string& images,
                                 std::vector<stitch::RigZoneMatchReport>* zones,
                                 double* lsm_sigma_rms_px) {
  if (!project.observations.empty())
    ThrowInputError({project.observations_file, project.observations.front().line},
                    "--match-ties measures the ties on the head images: observations.csv must have "
                    "no rows (got " +
                        std::to_string(project.observations.size()) + ")");
  StitchInputs in;
  for (const auto& e : project.exposures) in.exposures.push_back(StitchExposure(project, e));
  if (in.exposures.empty()) throw InputError(project.exposures_file + ": no exposures");
  for (const auto& e : in.exposures)  // every head image present before anything is computed
    for (const auto& head : rig.heads) HeadImagePath(images, e.image, head.id);
  stitch::RigTieMatches matches;
  Progress progress("rig tie matching", static_cast<long>(in.exposures.size()));
  for (int i = 0; i < static_cast<int>(in.exposures.size()); ++i) {
    std::vector<stitch::GrayImage> heads;
    for (const auto& head : rig.heads) {
      const std::string path = HeadImagePath(images, in.exposures[i].image, head.id);
      heads.push_back(stitch::ReadGrayImage(path));
      if (heads.back().cols() != head.camera.width_px ||
          heads.back().rows() != head.camera.height_px)
        throw InputError(path + ": " + std::to_string(heads.back().cols()) + " x " +
                         std::to_string(heads.back().rows()) + " px, head " + head.id + " is " +
                         std::to_string(head.camera.width_px) + " x " +
                         std::to_string(head.camera.height_px) + " px");
    }
    stitch::MatchRigExposureTies(rig, in.exposures[i], i, heads, {}, &matches);
    progress.Advance();
  }
  double sum2 = 0.0;
  for (double sigma : matches.lsm_sigma_px) sum2 += sigma * sigma;
  *lsm_sigma_rms_px =
      matches.lsm_sigma_px.empty() ? 0.0 : std::sqrt(sum2 / matches.lsm_sigma_px.size());
  in.ties = std::move(matches.ties);
  in.observations = std::move(matches.observations);
  *zones = std::move(matches.zones);
  return in;
}

// The library's options from the request, every value checked and named.
stitch::RigStitchOptions OptionsOf(const RigStitchRequest& r) {
  stitch::RigStitchOptions options;
  const auto mode = stitch::ParseRigStitchMode(r.mode);
  if (!mode)
    throw ConfigError("--mode must be line, per-exposure or angles (got '" + r.mode + "')");
  options.mode = *mode;
  options.snooping = !r.no_snooping;
  if (!(r.alpha > 0 && r.alpha < 1)) throw ConfigError("--alpha must be within (0, 1)");
  options.alpha = r.alpha;
  if (r.increment_sigma_arcsec) {
    if (!(*r.increment_sigma_arcsec > 0)) throw ConfigError("--increment-sigma-arcsec must be > 0");
    options.increment_sigma_rad = *r.increment_sigma_arcsec * M_PI / (180.0 * 3600.0);
  }
  if (r.dt_sigma_ms) {
    if (!(*r.dt_sigma_ms > 0)) throw ConfigError("--dt-sigma-ms must be > 0");
    options.dt_sigma_s = *r.dt_sigma_ms * 1e-3;
  }
  if (!(r.standard_radius_px > 0)) throw ConfigError("--standard-radius-px must be > 0");
  options.standard_radius_px = r.standard_radius_px;
  if (!(r.max_sigma0 > 0)) throw ConfigError("--max-sigma0 must be > 0");
  options.max_sigma0 = r.max_sigma0;
  if (!(r.suspect_effect_limit > 0)) throw ConfigError("--suspect-effect-limit must be > 0");
  options.suspect_effect_limit = r.suspect_effect_limit;
  if (!(r.default_sigma_px > 0)) throw ConfigError("--sigma-px must be > 0");
  return options;
}

// The tie matching's figures for the result, and its lines for the summary.
nlohmann::json TieMatchingJson(const StitchInputs& in,
                               const std::vector<stitch::RigZoneMatchReport>& zones_in,
                               double lsm_sigma_rms_px,
                               double sigma0,
                               std::string* printed) {
  nlohmann::json zones = nlohmann::json::array();
  for (const auto& z : zones_in) {
    zones.push_back({{"image", z.image},
                     {"zone", z.zone},
                     {"pixels", z.pixels},
                     {"cell_px", z.cell_px},
                     {"cells", z.cells},
                     {"lsm_tried", z.lsm_tried},
                     {"lsm_failed", z.lsm_failed},
                     {"ties", z.ties}});
    *printed +=
        StringPrintf("matched %s zone %s: %d ties (%d cells of %.0f px, LSM %d tried, %d failed)\n",
                     z.image.c_str(),
                     z.zone.c_str(),
                     z.ties,
                     z.cells,
                     z.cell_px,
                     z.lsm_tried,
                     z.lsm_failed);
  }
  // The LSM sigmas take the template's residuals as independent; sigma0 says by how much they
  // are too small here, and the increments' sigmas are scaled by it (a-posteriori).
  *printed += StringPrintf(
      "matched ties: LSM sigma RMS %.4f virtual px; sigma0 %.2f: the LSM sigmas are %.2f x "
      "too %s, the increments' sigmas are scaled by sigma0\n",
      lsm_sigma_rms_px,
      sigma0,
      sigma0 >= 1 ? sigma0 : 1 / sigma0,
      sigma0 >= 1 ? "small" : "large");
  return {{"ties", in.ties.size()},
          {"observations", in.observations.size()},
          {"prefilter_sigma_px", stitch::RigTieMatchOptions{}.prefilter_sigma_px},
          {"lsm_sigma_rms_px", lsm_sigma_rms_px},
          {"zones", zones}};
}

}  // namespace

RigStitchRun RunRigStitch(const RigStitchRequest& r) {
  RigStitchRun run;
  run.rig = calib::ReadRig(r.camera);
  const calib::Rig& rig = run.rig;
  if (rig.heads.size() < 2)
    throw InputError(r.camera + ": a rig of one head has nothing to stitch");
  if (rig.virtual_camera.orientation != calib::VirtualOrientation::kLevel)
    throw InputError(r.camera +
                     ": virtual.orientation must be level for rig stitch (the "
                     "horizontal virtual image of the POS attitude)");
  run.options = OptionsOf(r);
  const triangulation::Project project = triangulation::ReadProject(r.project, r.default_sigma_px);
  std::vector<stitch::RigZoneMatchReport> matched_zones;
  double lsm_sigma_rms_px = 0.0;
  const StitchInputs in =
      r.match_ties ? MatchedStitchInputs(project, rig, r.images, &matched_zones, &lsm_sigma_rms_px)
                   : StitchInputsFromProject(project, rig, r.camera);
  double height_sum = 0.0;
  for (const auto& e : in.exposures) height_sum += e.pose.rig_center_m.z() - e.z_ref_m;
  const double height_m = height_sum / in.exposures.size();
  stitch::RigStitchSources sources{r.camera, r.project, std::nullopt};
  if (r.relief_m) {
    if (!(*r.relief_m >= 0 && *r.relief_m < height_m))
      throw ConfigError("--relief-m must be within [0, " + FormatNumber(height_m, 6) +
                        ") m, the mean height above z_ref");
    run.options.relief_m = *r.relief_m;
    sources.relief_m = *r.relief_m;
  }
  // The standard tie positions of the rig's design at the block's mean height.
  const std::vector<stitch::StandardPosition> positions =
      stitch::DesignRig(rig, height_m, 200).standard_positions;
  if (r.need_head_images)  // every head image present before anything is computed or written
    for (const auto& e : in.exposures)
      for (const auto& head : rig.heads) HeadImagePath(r.images, e.image, head.id);
  run.result = stitch::SelfCalibrateRigStitching(
      rig, in.exposures, in.ties, in.observations, positions, run.options);
  run.json = stitch::RigStitchToJson(rig, run.options, run.result, sources);
  run.json["camera_models"] = HeadCameraModels(rig);
  if (r.match_ties)
    run.json["tie_matching"] =
        TieMatchingJson(in, matched_zones, lsm_sigma_rms_px, run.result.sigma0, &run.printed);
  run.printed += stitch::FormatRigStitchSummary(run.options, run.result, sources);
  run.exposures = in.exposures;
  return run;
}

}  // namespace aerocal::tools
