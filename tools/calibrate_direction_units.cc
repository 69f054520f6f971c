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
#include "triangulation/calibration/calibration_json.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/direction_units_run.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::tools {
namespace {

constexpr double kDeg = M_PI / 180.0;

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
}

// The quantity renamed "UNIT.name" (its statement with it).
triangulation::BudgetQuantity OfUnit(const std::string& unit, triangulation::BudgetQuantity q) {
  q.name = unit + "." + q.name;
  q.statement = triangulation::CertificateStatement(q.name, q.value, q.expanded, q.k, q.unit);
  return q;
}

// The heads' budgets: every head's interior quantities as "HEAD.c", ... (each from its own run:
// its estimate, its marginal covariance of the joint solve, the joint sigma0 and redundancy, its
// pixel pitch, its radii), m_0 once (one solve), the mounts of the heads after the first.
struct HeadsBudget {
  std::vector<triangulation::BudgetQuantity> quantities;
  std::vector<std::vector<double>> radii_mm;  // per unit (the run's order)
  triangulation::CalibrationRun first;  // the first head's run: the correlation table, stability
};

// The mount of unit k > 0 relative to the first unit, "HEAD.mount_omega" ... in deg.
std::vector<triangulation::BudgetQuantity> MountBudget(const triangulation::DirectionUnitsRun& run,
                                                       size_t k) {
  std::vector<triangulation::BudgetQuantity> out;
  const char* axes[3] = {"omega", "phi", "kappa"};
  const triangulation::DirectionUnitsCalibration& c = run.calibration;
  for (int i = 0; k > 0 && c.covariance_ok && i < 3; ++i)
    out.push_back(triangulation::AdjustedQuantityBudget(
        run.ids[k] + ".mount_" + axes[i],
        "deg",
        "mount of head " + run.ids[k] + " relative to head " + run.ids[0] + " (" + axes[i] + ")",
        c.mount_opk_rad[k][i] / kDeg,
        c.mount_sigma_rad[k][i] / kDeg,
        run.all.solve.redundancy,
        "the joint covariance of the two heads' rotations, propagated to the mount"));
  return out;
}

// The budget of every head (HeadsBudget). The distortion radii are the given ones (--radii-mm,
// the budget file) for every head, else each head's own format's (DefaultCertifiedRadiiMm): a head
// of a smaller format is not certified beyond its corners.
HeadsBudget UnitsBudget(const calib::Rig& rig,
                        const triangulation::DirectionUnitsRun& run,
                        const DirectionSetup& setup) {
  HeadsBudget out;
  for (size_t k = 0; k < run.ids.size(); ++k) {
    const calib::Camera& camera = rig.heads[rig.HeadIndex(run.ids[k])].camera;
    triangulation::CalibrationRun unit;
    unit.camera = run.ids[k];
    unit.start_c_mm = camera.c_mm();
    unit.project.cameras[unit.camera] = camera;
    unit.all = run.adjustments[k];
    triangulation::BudgetOptions of_unit = setup.budget;
    if (!setup.radii_given) of_unit.radii_mm = DefaultCertifiedRadiiMm(camera);
    out.radii_mm.push_back(of_unit.radii_mm);
    for (const auto& q : triangulation::UncertaintyBudget(unit, unit.project, of_unit)) {
      if (q.name.rfind("m_", 0) != 0)
        out.quantities.push_back(OfUnit(run.ids[k], q));
      else if (k == 0)
        out.quantities.push_back(q);
    }
    for (auto& q : MountBudget(run, k)) out.quantities.push_back(std::move(q));
    if (k == 0) out.first = unit;
  }
  return out;
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

// Per unit: its rotation to the instrument, its mount relative to the first unit, the start, its
// format and pixel pitch, the radii of its certified distortion values and its interior's
// correlations (the certificate draws and budgets every head from these, not only the first).
nlohmann::json UnitsJson(const triangulation::DirectionUnitsRun& run,
                         const calib::Rig& written,
                         const std::vector<std::vector<double>>& radii_mm) {
  nlohmann::json units = nlohmann::json::array();
  const triangulation::DirectionUnitsCalibration& c = run.calibration;
  for (size_t k = 0; k < run.ids.size(); ++k) {
    const triangulation::DirectionCalibration& u = c.units[k];
    const calib::Camera& head = written.heads[written.HeadIndex(run.ids[k])].camera;
    const triangulation::CalibrationAdjustment& a = run.adjustments[k];
    units.push_back(
        {{"id", run.ids[k]},
         {"observations", run.observations[k]},
         {"instrument_from_unit_opk_deg", DegreesJson(u.opk_rad)},
         {"instrument_from_unit_sigma_arcsec", ArcsecOrNullJson(u.opk_sigma_rad, c.covariance_ok)},
         {"mount_opk_deg", DegreesJson(c.mount_opk_rad[k])},
         {"mount_sigma_arcsec",
          k == 0 ? nlohmann::json() : ArcsecOrNullJson(c.mount_sigma_rad[k], c.covariance_ok)},
         {"rig_mount_deg", DegreesJson(written.heads[written.HeadIndex(run.ids[k])].mount_rad)},
         {"start_opk_deg", DegreesJson(run.start_opk_rad[k])},
         {"start_rotation", run.start_rotation[k]},
         {"pixel_size_mm", head.pixel_size_mm},
         {"format_px", {head.width_px, head.height_px}},
         {"radii_mm", radii_mm[k]}});
    if (!a.result.cameras.empty())
      units.back()["interior_covariance"] =
          triangulation::InteriorCovarianceToJson(a.interior_covariance, a.result.cameras[0]);
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
          {"instrument_from_camera_opk_deg", DegreesJson(c.units.front().opk_rad)},
          {"instrument_from_camera_sigma_arcsec",
           ArcsecOrNullJson(c.units.front().opk_sigma_rad, c.covariance_ok)},
          {"estimated_targets", EstimatedTargetsJson(c.target_angles_rad, c.target_sigma_rad)},
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
  const DirectionSetup setup = ReadDirectionSetup(args, reference);
  const triangulation::DirectionRunOptions& options = setup.options;
  std::map<std::string, calib::Camera> units;
  for (const auto& h : rig.heads) units[h.id] = h.camera;
  const triangulation::DirectionData data =
      triangulation::ReadUnitDirections(args.directions, units, args.camera, args.sigma_px);
  for (const auto& g : data.groups)
    if (!g.empty())
      ThrowInputError({args.directions, 1},
                      "group: the groups' stability test of a rig's heads is not built (each "
                      "group would have to determine every head alone; --camera " +
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
  nlohmann::json json = DirectionResultJson(r, setup);
  const HeadsBudget budget = UnitsBudget(rig, run, setup);
  for (const auto& q : budget.quantities)
    outcome.printed += StringPrintf("  %s\n", q.statement.c_str());
  // The first head's run gives the interior correlations, groups (none), stability and radii;
  // the budget lists every head's quantities, `units` every head's radii and correlations.
  nlohmann::json cal = triangulation::CalibrationToJson(
      budget.first, budget.quantities, budget.radii_mm.front(), reference.c_mm());
  cal["method"] = MethodJson(run, data, args.directions);
  cal["units"] = UnitsJson(run, written, budget.radii_mm);
  cal["data"] = DirectionDataJson(data, 0);
  cal["data"]["units"] = run.ids.size();
  // The first unit's id, pixel size and format: the certificate's distortion figure is its.
  const calib::Camera& first_head = rig.heads[rig.HeadIndex(run.ids.front())].camera;
  cal["camera"] = {{"file", args.camera},
                   {"kind", "rig"},
                   {"reference_head", rig.reference_head},
                   {"first_unit", run.ids.front()},
                   {"id", run.ids.front()},
                   {"pixel_size_mm", first_head.pixel_size_mm},
                   {"format_px", {first_head.width_px, first_head.height_px}}};
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
  FinishDirectionOutcome(r, std::move(json), true, &outcome);
  return outcome;
}

}  // namespace aerocal::tools
