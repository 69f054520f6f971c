#include "triangulation/calibration/direction_units_run.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal::triangulation {
namespace {

// Distinct known targets among the observations: two or more fix a rotation (Wahba's problem).
int KnownTargetsSeen(const std::vector<DirectionTarget>& targets,
                     const std::vector<DirectionObservation>& observations) {
  std::set<std::string> known, seen;
  for (const auto& t : targets)
    if (t.known) known.insert(t.id);
  for (const auto& o : observations)
    if (known.count(o.target)) seen.insert(o.target);
  return static_cast<int>(seen.size());
}

// The units with observations, in the order of `units`, each with its design mount.
std::vector<DirectionUnit> SplitByUnit(const std::vector<DirectionUnitStart>& units,
                                       const std::vector<DirectionObservation>& observations,
                                       const std::vector<std::string>& unit_of_observation,
                                       std::vector<Eigen::Vector3d>* design_mounts) {
  AEROCAL_CHECK(unit_of_observation.size() == observations.size()) << "one unit per observation";
  std::vector<DirectionUnit> out;
  for (const auto& u : units) {
    DirectionUnit unit{u.id, u.camera, Eigen::Vector3d::Zero(), {}};
    for (size_t i = 0; i < observations.size(); ++i)
      if (unit_of_observation[i] == u.id) unit.observations.push_back(observations[i]);
    if (unit.observations.empty()) continue;
    out.push_back(std::move(unit));
    design_mounts->push_back(u.design_mount_rad);
  }
  return out;
}

// A unit's own interior and rotation need as many scalar observations as unknowns (its share of
// the targets' unknowns is not counted: they are shared).
void CheckEnoughDirections(const DirectionUnit& unit, int free_interior) {
  const int n = static_cast<int>(unit.observations.size());
  const int unknowns = free_interior + 3;
  if (2 * n < unknowns)
    throw InputError(unit.observations.front().where + ": unit " + unit.id + ": " +
                     std::to_string(n) + " directions (" + std::to_string(2 * n) +
                     " scalar) cannot determine its " + std::to_string(unknowns) + " unknowns (" +
                     std::to_string(free_interior) + " free interior parameters and the rotation)");
}

// The start rotation of every unit (see the header comment); `how` says which.
void StartRotations(const std::vector<DirectionTarget>& targets,
                    const std::vector<Eigen::Vector3d>& design_mounts,
                    std::vector<DirectionUnit>* units,
                    std::vector<std::string>* how) {
  const auto wahba = [&](DirectionUnit& u) {
    if (KnownTargetsSeen(targets, u.observations) < 2) return false;
    u.start_opk_rad = StartRotationFromDirections(u.start, targets, u.observations);
    how->push_back("Wahba's problem (SVD) on the known directions");
    return true;
  };
  DirectionUnit& first = units->front();
  if (!wahba(first)) how->push_back("zero");
  const Eigen::Matrix3d instrument_from_rig =
      calib::RotationFromOpk(first.start_opk_rad) *
      calib::RotationFromOpk(design_mounts.front()).transpose();
  for (size_t k = 1; k < units->size(); ++k) {
    DirectionUnit& u = (*units)[k];
    if (wahba(u)) continue;
    u.start_opk_rad =
        calib::OpkFromRotation(instrument_from_rig * calib::RotationFromOpk(design_mounts[k]));
    how->push_back("the first unit's start and the camera file's mounts");
  }
}

// The units' adjustments as one result: the first unit's statistics and validity (one solve),
// every unit's camera and residuals; sigma0_px over every observation's a-priori sigma.
AdjustmentResult MergedResult(const std::vector<DirectionUnit>& units,
                              const std::vector<CalibrationAdjustment>& adjustments) {
  AdjustmentResult all = adjustments.front().result;
  all.cameras.clear();
  all.residuals.clear();
  double sum2 = 0;
  for (size_t k = 0; k < units.size(); ++k) {
    const AdjustmentResult& r = adjustments[k].result;
    all.cameras.push_back(r.cameras.front());
    for (ObservationResidual v : r.residuals) {
      v.image = units[k].id + (v.image == "collimator" ? "" : " " + v.image);
      sum2 += v.sigma_px * v.sigma_px;
      all.residuals.push_back(v);
    }
  }
  const double apriori_px = all.residuals.empty() ? 0.0 : std::sqrt(sum2 / all.residuals.size());
  all.sigma0_px = all.sigma0 * apriori_px;
  all.sigma0_um = all.sigma0_px * units.front().start.pixel_size_mm * 1e3;
  return all;
}

}  // namespace

DirectionUnitsRun RunDirectionUnitsCalibration(
    const std::vector<DirectionUnitStart>& starts,
    std::vector<DirectionTarget> targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& unit_of_observation,
    const DirectionRunOptions& options) {
  DirectionUnitsRun out;
  std::vector<Eigen::Vector3d> design_mounts;
  std::vector<DirectionUnit> units =
      SplitByUnit(starts, observations, unit_of_observation, &design_mounts);
  AEROCAL_CHECK(!units.empty()) << "no unit has observations";
  const std::vector<std::string>& free = options.calibration.free_interior;
  for (const auto& u : units) CheckEnoughDirections(u, static_cast<int>(free.size()));
  StartRotations(targets, design_mounts, &units, &out.start_rotation);
  // Unknown targets start from the first unit that sees them: the later units first, so that an
  // earlier unit's start overwrites theirs.
  for (auto u = units.rbegin(); u != units.rend(); ++u)
    StartUnknownTargets(u->start, u->start_opk_rad, u->observations, &targets);
  for (const auto& u : units) CheckDirectionsInFront(u.start_opk_rad, targets, u.observations);
  out.calibration = CalibrateUnitsFromDirections(units, targets, options.calibration);
  std::vector<CalibrationAdjustment>& adjustments = out.adjustments;
  for (size_t k = 0; k < units.size(); ++k) {
    out.ids.push_back(units[k].id);
    out.start_opk_rad.push_back(units[k].start_opk_rad);
    out.observations.push_back(static_cast<int>(units[k].observations.size()));
    adjustments.push_back(AdjustmentOfDirections(units[k].id,
                                                 units[k].start,
                                                 out.calibration.units[k],
                                                 units[k].observations,
                                                 free,
                                                 options.max_sigma0));
  }
  out.all = MergedResult(units, adjustments);
  return out;
}

}  // namespace aerocal::triangulation
