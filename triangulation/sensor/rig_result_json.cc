// The rig part of an adjustment's result (RigResultToJson, rig_head_camera.h): one writer per
// section. The heads' mounts, lever arms and time offsets are mounted blocks in the one JSON form
// {mode, value, sigma} (MountedToJson, calib/problem/mounted_block.h), as the platform's; the
// reference head is the rig's datum, so its blocks are fixed.
#include "calib/camera/camera_model.h"
#include "triangulation/adjustment/determinability.h"
#include "triangulation/adjustment/mounted_json.h"
#include "triangulation/sensor/rig_head_camera.h"

#include <cmath>

namespace aerocal::triangulation {
namespace {

using nlohmann::json;

constexpr double kDegPerRad = 180.0 / M_PI;

json Scalar(const std::optional<double>& s, double scale) { return s ? json(*s * scale) : json(); }

// Interior by the head model's parameter names, with its sigmas (null where unknown).
json HeadToJson(const RigHeadEstimate& h, const RigAdjustOptions& o) {
  json interior, interior_sigma;
  const std::vector<calib::ParamInfo> table = calib::CameraModelParams(h.model);
  for (int i = 0; i < static_cast<int>(table.size()); ++i) {
    const std::string name(table[i].name);
    interior[name] = h.interior[i];
    interior_sigma[name] = Scalar(h.interior_sigma[i], 1.0);
  }
  const auto mode = [&](calib::BlockMode m) { return h.reference ? calib::BlockMode::kFixed : m; };
  return {
      {"id", h.id},
      {"reference", h.reference},
      {"interior", interior},
      {"interior_sigma", interior_sigma},
      {"mount_deg", MountedToJson(mode(o.mounts), h.mount_rad, h.mount_sigma_rad, kDegPerRad)},
      {"lever_arm_m", MountedToJson(mode(o.lever_arms), h.lever_arm_m, h.lever_arm_sigma_m, 1.0)},
      {"time_offset_ms",
       MountedToJson(mode(o.time_offsets), h.time_offset_s, h.time_offset_sigma_s, 1e3)}};
}

// The --rig-* options as given; a prior sigma only where the mode is weighted.
json OptionsToJson(const RigAdjustOptions& o) {
  const bool weighted_increments = o.increments == calib::BlockMode::kWeighted;
  const bool weighted_offsets = o.time_offsets == calib::BlockMode::kWeighted;
  return {{"mounts", calib::BlockModeName(o.mounts)},
          {"lever_arms", calib::BlockModeName(o.lever_arms)},
          {"increments", calib::BlockModeName(o.increments)},
          {"increment_sigma_arcsec",
           weighted_increments ? json(o.increment_sigma_rad * kDegPerRad * 3600.0) : json()},
          {"time_offsets", calib::BlockModeName(o.time_offsets)},
          {"time_offset_sigma_ms", weighted_offsets ? json(o.time_offset_sigma_s * 1e3) : json()}};
}

// Per exposure and non-reference head: the increment (deg) and time offset (ms) with sigmas;
// a held increment or time offset has no sigma (null).
json ExposuresToJson(const RigAdjustmentResult& r) {
  const bool held_increments = r.options.increments == calib::BlockMode::kFixed;
  const bool held_offsets = r.options.time_offsets == calib::BlockMode::kFixed;
  json exposures = json::array();
  for (const RigExposureEstimate& e : r.exposures) {
    const Eigen::Vector3d deg = e.increment_rad * kDegPerRad;
    json sigma = {{"domega", nullptr},
                  {"dphi", nullptr},
                  {"dkappa", nullptr},
                  {"dT_ms", held_offsets ? json() : Scalar(e.time_offset_sigma_s, 1e3)}};
    if (e.increment_sigma_rad && !held_increments) {
      sigma["domega"] = e.increment_sigma_rad->x() * kDegPerRad;
      sigma["dphi"] = e.increment_sigma_rad->y() * kDegPerRad;
      sigma["dkappa"] = e.increment_sigma_rad->z() * kDegPerRad;
    }
    exposures.push_back({{"image", e.image},
                         {"head", e.head},
                         {"domega", deg.x()},
                         {"dphi", deg.y()},
                         {"dkappa", deg.z()},
                         {"dT_ms", e.time_offset_s * 1e3},
                         {"sigma", sigma}});
  }
  return exposures;
}

}  // namespace

nlohmann::json RigResultToJson(const RigAdjustmentResult& r) {
  const Determinability& d = r.determinability;
  json heads = json::array();
  for (const RigHeadEstimate& h : r.heads) heads.push_back(HeadToJson(h, r.options));
  const json rig = {
      {"camera", r.camera},
      {"reference_head", r.reference_head},
      {"options", OptionsToJson(r.options)},
      {"heads", heads},
      {"determinability", DeterminabilityToJson(d, d.covariance_ok && d.undetermined.empty())}};
  return {{"rig", rig}, {"rig_exposures", ExposuresToJson(r)}};
}

}  // namespace aerocal::triangulation
