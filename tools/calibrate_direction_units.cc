#include "tools/calibrate_direction_units.h"

#include "calib/camera/rig_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/result_file.h"
#include "calib/core/string_printf.h"
#include "calib/core/yaml_util.h"
#include "tools/calibrate_models.h"
#include "tools/camera_formats.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/direction_units_run.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::tools {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kArcSecond = kDeg / 3600.0;

nlohmann::json Degrees(const Eigen::Vector3d& rad) {
  return {rad.x() / kDeg, rad.y() / kDeg, rad.z() / kDeg};
}
// Sigmas in arc seconds; null when the covariance is not known.
nlohmann::json ArcsecOrNull(const Eigen::Vector3d& rad, bool known) {
  if (!known) return nullptr;
  return {rad.x() / kArcSecond, rad.y() / kArcSecond, rad.z() / kArcSecond};
}

// Options of a single camera that a rig run does not take: refused by name.
void RefuseSingleCameraOptions(const DirectionsArgs& args) {
  if (!args.model.empty())
    throw ConfigError(
        "--model: a rig's heads are calibrated in their own models (not with a rig "
        "file, --camera " +
        args.camera + ")");
  if (args.camera_format != "aerocal")
    throw ConfigError("--camera-format: a rig file is written in aerocal's rig layout (got " +
                      args.camera_format + ")");
  if (!args.budget.empty() || !args.radii_mm.empty())
    throw ConfigError(std::string(args.budget.empty() ? "--radii-mm" : "--budget") +
                      ": the uncertainty budget of a multi-unit run is not built (a rig file, "
                      "--camera " +
                      args.camera + ")");
}

// The units in the adjustment's order: the reference head first, then the rig's order.
std::vector<triangulation::DirectionUnitStart> UnitStarts(const calib::Rig& rig) {
  std::vector<triangulation::DirectionUnitStart> out;
  const int ref = rig.ReferenceIndex();
  out.push_back({rig.heads[ref].id, rig.heads[ref].camera, rig.heads[ref].mount_rad});
  for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k)
    if (k != ref) out.push_back({rig.heads[k].id, rig.heads[k].camera, rig.heads[k].mount_rad});
  return out;
}

// The rig with every calibrated head's interior and mount: rig_from_unit_k = M_first R_1^T R_k,
// M_first the first unit's mount of the file (the reference of the estimated mounts).
calib::Rig UpdatedRig(const calib::Rig& rig, const triangulation::DirectionUnitsRun& run) {
  calib::Rig out = rig;
  const Eigen::Matrix3d rig_from_first =
      calib::RotationFromOpk(rig.heads[rig.HeadIndex(run.ids.front())].mount_rad);
  for (size_t k = 0; k < run.ids.size(); ++k) {
    calib::RigHead& head = out.heads[out.HeadIndex(run.ids[k])];
    head.camera = triangulation::UpdatedCamera(head.camera, run.all.cameras[k]);
    head.mount_rad = calib::OpkFromRotation(
        rig_from_first * calib::RotationFromOpk(run.calibration.mount_opk_rad[k]));
  }
  return out;
}

// Per unit: its rotation to the instrument, its mount relative to the first unit, the start.
nlohmann::json UnitsJson(const triangulation::DirectionUnitsRun& run, const calib::Rig& written) {
  nlohmann::json units = nlohmann::json::array();
  const triangulation::DirectionUnitsCalibration& c = run.calibration;
  for (size_t k = 0; k < run.ids.size(); ++k) {
    const triangulation::DirectionCalibration& u = c.units[k];
    units.push_back(
        {{"id", run.ids[k]},
         {"observations", run.observations[k]},
         {"instrument_from_unit_opk_deg", Degrees(u.opk_rad)},
         {"instrument_from_unit_sigma_arcsec", ArcsecOrNull(u.opk_sigma_rad, c.covariance_ok)},
         {"mount_opk_deg", Degrees(c.mount_opk_rad[k])},
         {"mount_sigma_arcsec",
          k == 0 ? nlohmann::json() : ArcsecOrNull(c.mount_sigma_rad[k], c.covariance_ok)},
         {"rig_mount_deg", Degrees(written.heads[written.HeadIndex(run.ids[k])].mount_rad)},
         {"start_opk_deg", Degrees(run.start_opk_rad[k])},
         {"start_rotation", run.start_rotation[k]}});
  }
  return units;
}

// The method: the instrument, the file, the shared rotation, the estimated targets, the units.
nlohmann::json MethodJson(const triangulation::DirectionUnitsRun& run,
                          const triangulation::DirectionData& data,
                          const std::string& path) {
  const triangulation::DirectionUnitsCalibration& c = run.calibration;
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  nlohmann::json targets = nlohmann::json::object();
  for (const auto& [id, angles] : c.target_angles_rad) {
    const auto s = c.target_sigma_rad.find(id);
    targets[id] = {{"azimuth_deg", angles.x() / kDeg},
                   {"elevation_deg", angles.y() / kDeg},
                   {"sigma_arcsec",
                    s == c.target_sigma_rad.end() ? nlohmann::json()
                                                  : nlohmann::json({s->second.x() / kArcSecond,
                                                                    s->second.y() / kArcSecond})}};
  }
  return {{"kind", c.method},
          {"directions", path},
          {"targets", data.targets.size()},
          {"known_targets", known},
          {"settings", data.settings},
          {"units", run.ids},
          {"adjustment",
           "direction adjustment of several units in one problem "
           "(triangulation/calibration/direction_calibration.h, CalibrateUnitsFromDirections): a "
           "shared rotation of the instrument, per unit its interior and its mount relative to the "
           "first unit; no position, no scale; no data snooping"},
          {"instrument_from_camera_opk_deg", Degrees(c.units.front().opk_rad)},
          {"instrument_from_camera_sigma_arcsec",
           ArcsecOrNull(c.units.front().opk_sigma_rad, c.covariance_ok)},
          {"estimated_targets", targets},
          {"sub_images",
           "the heads of a rig file in one adjustment; the sub-images of a multi-CCD camera file "
           "are not (one interior for the whole file)"}};
}

}  // namespace

bool IsRigCameraFile(const std::string& path) {
  const YAML::Node root = LoadYamlFile(path);
  return root.IsMap() && root["rig"];
}

CalibrateOutcome CalibrateRigFromDirections(const DirectionsArgs& args) {
  CalibrateOutcome outcome;
  RefuseSingleCameraOptions(args);
  const calib::Rig rig = calib::ReadRig(args.camera);
  const calib::Camera& reference = rig.heads[rig.ReferenceIndex()].camera;
  triangulation::DirectionRunOptions options;
  options.calibration.free_interior = triangulation::ParseSelfCalibration(
      args.self_calibration.empty() ? DefaultSelfCalibration(reference.model)
                                    : args.self_calibration,
      reference.model);
  if (options.calibration.free_interior.empty())
    throw ConfigError("--self-calibration: calibrate needs at least one parameter (got none)");
  if (!args.out.empty()) CheckOutputFile(args.out, "--out");
  if (!args.write_camera.empty()) CheckOutputFile(args.write_camera, "--write-camera");
  std::map<std::string, calib::Camera> units;
  for (const auto& h : rig.heads) units[h.id] = h.camera;
  const triangulation::DirectionData data =
      triangulation::ReadUnitDirections(args.directions, units, args.camera, args.sigma_px);
  for (const auto& g : data.groups)
    if (!g.empty())
      ThrowInputError({args.directions, 1},
                      "group: the groups' stability test of a multi-unit run is not built "
                      "(--camera " +
                          args.camera + " is a rig)");

  const triangulation::DirectionUnitsRun run = triangulation::RunDirectionUnitsCalibration(
      UnitStarts(rig), data.targets, data.observations, data.units, options);
  const triangulation::AdjustmentResult& r = run.all;
  outcome.printed += StringPrintf("%s, %zu units (%s): %s",
                                  run.calibration.method.c_str(),
                                  run.ids.size(),
                                  args.directions.c_str(),
                                  triangulation::FormatSummary(r).c_str());
  const calib::Rig written = UpdatedRig(rig, run);
  nlohmann::json json = triangulation::AdjustmentToJson(r);
  json["command"] = "calibrate";
  json["valid"] = r.valid;
  json["invalid_reasons"] = r.invalid_reasons;
  json["self_calibration"] = options.calibration.free_interior;
  nlohmann::json cal;
  cal["method"] = MethodJson(run, data, args.directions);
  cal["units"] = UnitsJson(run, written);
  int known = 0;
  for (const auto& t : data.targets) known += t.known;
  cal["data"] = {{"images", std::max(1, data.settings)},
                 {"observations", data.observations.size()},
                 {"control_points", known},
                 {"check_points", 0},
                 {"groups", 0},
                 {"targets", data.targets.size()},
                 {"settings", data.settings},
                 {"units", run.ids.size()}};
  cal["camera"] = {{"file", args.camera}, {"kind", "rig"}, {"reference_head", rig.reference_head}};
  cal["rms_px"] = RmsPx(r);
  for (size_t k = 0; k < run.ids.size(); ++k) {
    const Eigen::Vector3d& m = run.calibration.mount_opk_rad[k];
    outcome.printed += StringPrintf("  unit %s: %d directions, mount %.6f %.6f %.6f deg\n",
                                    run.ids[k].c_str(),
                                    run.observations[k],
                                    m.x() / kDeg,
                                    m.y() / kDeg,
                                    m.z() / kDeg);
  }
  // Only a valid result is written as a camera file (a file that exists is one the next run may
  // use).
  if (!args.write_camera.empty() && r.valid) {
    calib::WriteRig(args.write_camera, written);
    cal["camera_written"] = {{"file", args.write_camera}, {"format", "aerocal rig"}};
    outcome.printed +=
        "rig (" + std::to_string(run.ids.size()) + " units updated) -> " + args.write_camera + "\n";
  } else if (!args.write_camera.empty()) {
    outcome.errors += "camera not written: the result is not valid\n";
  }
  json["calibration"] = cal;
  for (const auto& reason : r.invalid_reasons)
    outcome.errors += "calibrate: not valid: " + reason + "\n";
  outcome.doc = std::move(json);
  outcome.valid = r.valid;
  return outcome;
}

}  // namespace aerocal::tools
