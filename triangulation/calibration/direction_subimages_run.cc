#include "triangulation/calibration/direction_subimages_run.h"

#include "calib/core/error.h"
#include "calib/core/string_printf.h"

#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

// The sub-image calibration as a calibration adjustment: AdjustmentOfDirections of the virtual
// camera, its residuals labelled with their sub-image ("SUB" or "SUB SETTING"), (u, v) and the
// virtual pixel through the estimated mapping; not valid without a gauge.
CalibrationAdjustment SubimageAdjustment(const std::string& camera_id,
                                         const calib::Camera& start,
                                         const SubimageDirectionsCalibration& c,
                                         const std::vector<DirectionObservation>& observations,
                                         const std::vector<std::string>& subimage_of,
                                         const DirectionRunOptions& options) {
  CalibrationAdjustment a = AdjustmentOfDirections(camera_id,
                                                   start,
                                                   c.frame,
                                                   observations,
                                                   options.calibration.free_interior,
                                                   options.max_sigma0);
  for (size_t i = 0; i < a.result.residuals.size(); ++i) {
    ObservationResidual& v = a.result.residuals[i];
    const calib::SubimageMapping& m =
        c.frame.camera.subimages[c.frame.camera.SubimageIndex(subimage_of[i])];
    v.image = subimage_of[i] + (observations[i].setting.empty() ? "" : " " + v.image);
    v.subimage = subimage_of[i];
    v.subimage_px = observations[i].pixel;
    v.measured_px = m.VirtualFromSub(observations[i].pixel);
  }
  a.result.datum =
      "the known directions (collimators) and instrument settings (goniometer); the "
      "reference sub-image " +
      c.gauge.reference + "'s mapping entries held (gauge)";
  if (!c.gauge.ok) a.result.Invalidate("no gauge of the sub-images' mappings: " + c.gauge.message);
  return a;
}

// Unknowns of a run on `observations`: the free interior, R, each observed sub-image's mapping
// less the gauge's entries, every unknown target seen.
int SubimageUnknowns(const calib::Camera& start,
                     const std::vector<DirectionTarget>& targets,
                     const std::vector<DirectionObservation>& observations,
                     const std::vector<std::string>& subimage_of,
                     int free_interior,
                     int gauge) {
  std::set<std::string> seen, subimages;
  for (size_t i = 0; i < observations.size(); ++i) {
    seen.insert(observations[i].target);
    subimages.insert(subimage_of[i]);
  }
  int n = free_interior + 3 - gauge;
  for (const auto& s : subimages)
    n += calib::MappingParamCount(start.subimages[start.SubimageIndex(s)].model);
  for (const auto& t : targets)
    if (!t.known && seen.count(t.id)) n += 2;
  return n;
}

}  // namespace

SubimageDirectionsRun RunSubimageDirectionCalibration(
    const std::string& camera_id,
    const calib::Camera& start,
    std::vector<DirectionTarget> targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of,
    const std::vector<std::string>& group_of_observation,
    const DirectionRunOptions& options) {
  SubimageDirectionsRun out;
  const std::vector<DirectionObservation> virtual_observations =
      VirtualObservations(start, observations, subimage_of);
  out.start_opk_rad = StartRotationFromDirections(start, targets, virtual_observations);
  StartUnknownTargets(start, out.start_opk_rad, virtual_observations, &targets);
  CheckDirectionsInFront(out.start_opk_rad, targets, virtual_observations);
  const auto adjust = [&](const std::vector<DirectionObservation>& obs,
                          const std::vector<std::string>& sub,
                          SubimageDirectionsCalibration* keep) {
    *keep = CalibrateSubimagesFromDirections(
        start, out.start_opk_rad, targets, obs, sub, "", options.calibration);
    return SubimageAdjustment(camera_id, start, *keep, obs, sub, options);
  };
  CalibrationRun& run = out.run;
  run.camera = camera_id;
  run.start_c_mm = start.c_mm();
  run.project.cameras[camera_id] = start;
  run.all = adjust(observations, subimage_of, &out.all);

  std::map<std::string, std::pair<std::vector<DirectionObservation>, std::vector<std::string>>>
      groups;
  for (size_t i = 0; i < group_of_observation.size() && i < observations.size(); ++i)
    if (!group_of_observation[i].empty()) {
      groups[group_of_observation[i]].first.push_back(observations[i]);
      groups[group_of_observation[i]].second.push_back(subimage_of[i]);
    }
  const int free = static_cast<int>(options.calibration.free_interior.size());
  const int gauge = static_cast<int>(out.all.gauge.held.size());
  for (const auto& [name, obs] : groups) {
    const int unknowns = SubimageUnknowns(start, targets, obs.first, obs.second, free, gauge);
    if (2 * static_cast<int>(obs.first.size()) <= unknowns)
      throw InputError(
          StringPrintf("group %s: %zu observations (%zu scalar) cannot determine "
                       "its %d unknowns",
                       name.c_str(),
                       obs.first.size(),
                       2 * obs.first.size(),
                       unknowns));
    GroupCalibration g;
    g.group = name;
    std::set<std::string> labels;
    for (const auto& o : obs.first) labels.insert(o.setting.empty() ? o.target : o.setting);
    g.images.assign(labels.begin(), labels.end());
    out.groups.emplace_back();
    g.adjustment = adjust(obs.first, obs.second, &out.groups.back());
    run.groups.push_back(std::move(g));
  }
  run.stability = GroupStability(run.groups, options.stability_alpha);
  return out;
}

}  // namespace aerocal::triangulation
