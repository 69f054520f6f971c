#include "triangulation/calibration/direction_run.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"
#include "calib/residuals/direction.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

// Unknowns of a run on `observations`: the free interior, the rotation and every unknown target
// seen.
int Unknowns(const std::vector<DirectionTarget>& targets,
             const std::vector<DirectionObservation>& observations,
             int free_interior) {
  std::set<std::string> seen;
  for (const auto& o : observations) seen.insert(o.target);
  int n = free_interior + 3;
  for (const auto& t : targets)
    if (!t.known && seen.count(t.id)) n += 2;
  return n;
}

}  // namespace

void CheckDirectionsInFront(const Eigen::Vector3d& start_opk_rad,
                            const std::vector<DirectionTarget>& targets,
                            const std::vector<DirectionObservation>& observations) {
  std::map<std::string, Eigen::Vector2d> angles;
  for (const auto& t : targets) angles[t.id] = t.angles_rad;
  const Eigen::Matrix3d r = calib::RotationFromOpk(start_opk_rad);
  for (size_t i = 0; i < observations.size(); ++i) {
    const DirectionObservation& o = observations[i];
    const auto a = angles.find(o.target);
    if (a == angles.end()) continue;  // CalibrateFromDirections names it
    Eigen::Vector3d t;
    calib::DirectionFromAngles(a->second.data(), t.data());
    const Eigen::Vector3d uvw = r.transpose() * o.instrument_rotation.transpose() * t;
    if (!(uvw.z() < -0.05))  // within ~87 deg of the axis: a camera sees nothing beyond
      throw InputError((o.where.empty() ? "observation " + std::to_string(i + 1) : o.where) +
                       ": target " + o.target +
                       StringPrintf(" is %.1f deg off the camera's axis at the start orientation "
                                    "(omega %.3f, phi %.3f, kappa %.3f deg): no camera sees it",
                                    std::acos(std::clamp(-uvw.z(), -1.0, 1.0)) * 180 / M_PI,
                                    start_opk_rad.x() * 180 / M_PI,
                                    start_opk_rad.y() * 180 / M_PI,
                                    start_opk_rad.z() * 180 / M_PI));
  }
}

CalibrationAdjustment AdjustmentOfDirections(const std::string& camera_id,
                                             const calib::Camera& start,
                                             const DirectionCalibration& d,
                                             const std::vector<DirectionObservation>& observations,
                                             const std::vector<std::string>& free_interior,
                                             double max_sigma0) {
  CalibrationAdjustment out;
  AdjustmentResult& r = out.result;
  r.solve = d.report;
  r.free_interior = free_interior;
  r.sigma0 = d.report.sigma0;
  double sum2 = 0;
  for (double s : d.apriori_sigma_px) sum2 += s * s;
  const double apriori_px =
      d.apriori_sigma_px.empty() ? 0.0 : std::sqrt(sum2 / d.apriori_sigma_px.size());
  r.sigma0_px = r.sigma0 * apriori_px;
  r.sigma0_um = r.sigma0_px * start.pixel_size_mm * 1e3;
  CameraEstimate c;
  c.id = camera_id;
  c.model = start.model;
  c.initial = start.interior;
  c.estimated = d.camera.interior;
  c.free = calib::ParamVector<bool>::ForModel(start.model);
  for (const auto& name : free_interior) c.free[start.ParamIndex(name)] = true;
  c.sigma = calib::InteriorParams(d.interior_sigma);
  r.cameras.push_back(c);
  for (size_t i = 0; i < observations.size(); ++i) {
    ObservationResidual v;
    v.image = observations[i].setting.empty() ? "collimator" : observations[i].setting;
    v.point = observations[i].target;
    v.measured_px = observations[i].pixel;
    v.residual_px = d.residual_px[i];
    v.sigma_px = d.apriori_sigma_px[i];
    r.residuals.push_back(v);
  }
  r.determinability.covariance_ok = d.covariance_ok;
  r.determinability.undetermined = d.undetermined;
  for (const auto& h : d.high_correlations)
    if (h.a.rfind("interior.", 0) == 0 || h.b.rfind("interior.", 0) == 0)
      r.determinability.high_correlations.push_back(h);
  r.frame = "instrument frame (directions; no position, no scale)";
  r.datum = "the known directions (collimators) and instrument settings (goniometer)";
  r.warnings = GroupRmsWarnings(r.solve);
  if (!r.solve.converged)
    r.Invalidate("the adjustment did not converge (" + r.solve.termination + ")");
  if (r.sigma0 > max_sigma0)
    r.Invalidate("sigma0 " + FormatNumber(r.sigma0, 3) + " is above the limit " +
                 FormatNumber(max_sigma0, 3) + " (max_sigma0)");
  if (!d.undetermined.empty())
    r.Invalidate("singular: " + std::to_string(d.undetermined.size()) +
                 " parameter(s) not determinable (" + d.undetermined.front() + ", ...)");
  else if (!d.covariance_ok)
    r.Invalidate("no covariance of the interior");
  out.interior_covariance = d.interior_covariance;
  return out;
}

DirectionRun RunDirectionCalibration(const std::string& camera_id,
                                     const calib::Camera& start,
                                     std::vector<DirectionTarget> targets,
                                     const std::vector<DirectionObservation>& observations,
                                     const std::vector<std::string>& group_of_observation,
                                     const DirectionRunOptions& options) {
  DirectionRun out;
  out.start_opk_rad = StartRotationFromDirections(start, targets, observations);
  StartUnknownTargets(start, out.start_opk_rad, observations, &targets);
  CheckDirectionsInFront(out.start_opk_rad, targets, observations);
  const std::vector<std::string>& free = options.calibration.free_interior;
  const auto adjust = [&](const std::vector<DirectionObservation>& obs,
                          DirectionCalibration* keep) {
    DirectionCalibration d =
        CalibrateFromDirections(start, out.start_opk_rad, targets, obs, options.calibration);
    CalibrationAdjustment a =
        AdjustmentOfDirections(camera_id, start, d, obs, free, options.max_sigma0);
    if (keep) *keep = std::move(d);
    return a;
  };
  CalibrationRun& run = out.run;
  run.camera = camera_id;
  run.start_c_mm = start.c_mm();
  run.project.cameras[camera_id] = start;
  run.all = adjust(observations, &out.all);

  std::map<std::string, std::vector<DirectionObservation>> groups;
  for (size_t i = 0; i < group_of_observation.size() && i < observations.size(); ++i)
    if (!group_of_observation[i].empty())
      groups[group_of_observation[i]].push_back(observations[i]);
  for (const auto& [name, obs] : groups) {
    const int unknowns = Unknowns(targets, obs, static_cast<int>(free.size()));
    if (2 * static_cast<int>(obs.size()) <= unknowns)
      throw InputError(
          StringPrintf("group %s: %zu observations (%zu scalar) cannot determine its %d unknowns",
                       name.c_str(),
                       obs.size(),
                       2 * obs.size(),
                       unknowns));
    GroupCalibration g;
    g.group = name;
    std::set<std::string> labels;
    for (const auto& o : obs) labels.insert(o.setting.empty() ? o.target : o.setting);
    g.images.assign(labels.begin(), labels.end());
    g.adjustment = adjust(obs, nullptr);
    run.groups.push_back(std::move(g));
  }
  run.stability = GroupStability(run.groups, options.stability_alpha);
  return out;
}

}  // namespace aerocal::triangulation
