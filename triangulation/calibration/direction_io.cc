#include "triangulation/calibration/direction_io.h"

#include "calib/camera/rotation.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/string_printf.h"

#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <tuple>

namespace aerocal::triangulation {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kArcSecond = kDeg / 3600.0;
// Largest angular sigma accepted: a degree is no calibrated direction.
constexpr double kMaxSigmaArcsec = 3600.0;
// Two values of one target's / setting's angles on different rows must agree to this, deg.
constexpr double kSameAngleDeg = 1e-9;

// A target's direction (both columns, or none) on a row.
std::optional<Eigen::Vector2d> RowAngles(const CsvTable& table, const CsvTable::Row& row) {
  const auto a = table.OptionalBounded(row, "azimuth_deg", -180.0, 180.0);
  const auto e = table.OptionalBounded(row, "elevation_deg", -89.0, 89.0);
  if (a.has_value() != e.has_value())
    ThrowInputError(table.Where(row), "azimuth_deg and elevation_deg go together (one is empty)");
  if (!a) return std::nullopt;
  return Eigen::Vector2d(*a, *e);
}

bool SameAngles(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a - b).cwiseAbs().maxCoeff() <= kSameAngleDeg;
}

// A row's goniometer setting: its name and (turn, tilt) in degrees.
std::pair<std::string, Eigen::Vector2d> RowSetting(const CsvTable& table,
                                                   const CsvTable::Row& row) {
  const Eigen::Vector2d angles(table.OptionalBounded(row, "turn_deg", -180.0, 180.0).value_or(0.0),
                               table.OptionalBounded(row, "tilt_deg", -180.0, 180.0).value_or(0.0));
  std::string name = table.String(row, "setting");
  const bool has_angles = table.HasColumn("turn_deg") || table.HasColumn("tilt_deg");
  if (name.empty() && has_angles)
    name = StringPrintf("turn %.6g tilt %.6g", angles.x(), angles.y());
  return {name, angles};
}

// The camera a row is measured in (its pixel frame bounds col, row); sets the row's unit.
using CameraOfRow =
    std::function<const calib::Camera&(const CsvTable&, const CsvTable::Row&, std::string* unit)>;

void CheckDirectionColumns(const CsvTable& table, const std::string& path) {
  table.RequireColumns({"target", "col", "row"});
  table.RejectUnknownColumns({"target",
                              "col",
                              "row",
                              "sigma_px",
                              "azimuth_deg",
                              "elevation_deg",
                              "sigma_arcsec",
                              "setting",
                              "turn_deg",
                              "tilt_deg",
                              "group",
                              "unit"});
  if (table.HasColumn("azimuth_deg") != table.HasColumn("elevation_deg"))
    ThrowInputError({path, 0}, "azimuth_deg and elevation_deg go together (one column is missing)");
  if (table.rows().empty())
    ThrowInputError({path, 0}, "no rows (a directions file needs observations)");
}

// One row's observation: target, pixel in `camera`'s frame, sigmas and the instrument setting.
DirectionObservation ReadDirectionObservation(const CsvTable& table,
                                              const CsvTable::Row& row,
                                              const calib::Camera& camera,
                                              double default_sigma_px,
                                              Eigen::Vector2d* turn_tilt_deg) {
  const SourceRef where = table.Where(row);
  DirectionObservation o;
  o.where = where.ToString();
  o.target = table.String(row, "target");
  if (o.target.empty()) ThrowInputError(where, "target must not be empty");
  o.pixel = Eigen::Vector2d(table.Bounded(row, "col", -0.5, camera.width_px - 0.5),
                            table.Bounded(row, "row", -0.5, camera.height_px - 0.5));
  o.sigma_px = table.OptionalBounded(row, "sigma_px", 0.0, 100.0).value_or(default_sigma_px);
  if (!(o.sigma_px > 0)) ThrowInputError(where, "sigma_px must be > 0 (got 0)");
  o.sigma_rad =
      table.OptionalBounded(row, "sigma_arcsec", 0.0, kMaxSigmaArcsec).value_or(0.0) * kArcSecond;
  const auto [setting, turn_tilt] = RowSetting(table, row);
  o.setting = setting;
  o.instrument_rotation =
      calib::RotationFromOpk(Eigen::Vector3d(turn_tilt.y() * kDeg, turn_tilt.x() * kDeg, 0.0));
  *turn_tilt_deg = turn_tilt;
  return o;
}

// A named setting has the same turn and tilt on every row.
void CheckSettingAngles(const std::string& setting,
                        const Eigen::Vector2d& turn_tilt,
                        int line,
                        const SourceRef& where,
                        std::map<std::string, std::pair<Eigen::Vector2d, int>>* settings) {
  if (setting.empty()) return;
  const auto [at, added] = settings->emplace(setting, std::make_pair(turn_tilt, line));
  if (!added && !SameAngles(at->second.first, turn_tilt))
    ThrowInputError(
        where,
        StringPrintf("setting %s has turn %.9g, tilt %.9g deg here and %.9g, %.9g at line %d",
                     setting.c_str(),
                     turn_tilt.x(),
                     turn_tilt.y(),
                     at->second.first.x(),
                     at->second.first.y(),
                     at->second.second));
}

// The row's target direction: a new target is added to `out`, a known one must agree.
void AddTargetDirection(
    const std::string& target,
    const std::optional<Eigen::Vector2d>& angles,
    int line,
    const SourceRef& where,
    std::map<std::string, std::pair<std::optional<Eigen::Vector2d>, int>>* target_angles,
    DirectionData* out) {
  const auto [at, added] = target_angles->emplace(target, std::make_pair(angles, line));
  if (added) {
    const Eigen::Vector2d start_rad =
        angles ? Eigen::Vector2d(*angles * kDeg) : Eigen::Vector2d(0.0, 0.0);
    out->targets.push_back({target, start_rad, angles.has_value()});
  } else if (at->second.first.has_value() != angles.has_value() ||
             (angles && !SameAngles(*angles, *at->second.first))) {
    ThrowInputError(
        where,
        "target " + target + ": its azimuth_deg, elevation_deg differ from line " +
            std::to_string(at->second.second) +
            " (a known target gives the same direction on every row; an estimated one none)");
  }
}

DirectionData ReadRows(const CsvTable& table,
                       const std::string& path,
                       const CameraOfRow& camera_of_row,
                       double default_sigma_px) {
  CheckDirectionColumns(table, path);
  DirectionData out;
  std::map<std::string, std::pair<std::optional<Eigen::Vector2d>, int>>
      target_angles;                                                // -> (angles, line)
  std::map<std::string, std::pair<Eigen::Vector2d, int>> settings;  // -> (turn, tilt; line)
  // target, setting, group, unit
  std::set<std::tuple<std::string, std::string, std::string, std::string>> seen;
  for (const auto& row : table.rows()) {
    const SourceRef where = table.Where(row);
    std::string unit;
    const calib::Camera& camera = camera_of_row(table, row, &unit);
    Eigen::Vector2d turn_tilt;
    const DirectionObservation o =
        ReadDirectionObservation(table, row, camera, default_sigma_px, &turn_tilt);
    CheckSettingAngles(o.setting, turn_tilt, row.line, where, &settings);
    AddTargetDirection(o.target, RowAngles(table, row), row.line, where, &target_angles, &out);
    const std::string group = table.String(row, "group");
    if (!seen.emplace(o.target, o.setting, group, unit).second)
      ThrowInputError(where,
                      "target " + o.target + (o.setting.empty() ? "" : " at setting " + o.setting) +
                          (group.empty() ? "" : " in group " + group) +
                          (unit.empty() ? "" : " by unit " + unit) +
                          " is observed twice (a repeated series goes into its own group)");
    if (table.HasColumn("group")) out.groups.push_back(group);
    if (!unit.empty()) out.units.push_back(unit);
    out.observations.push_back(o);
  }
  out.settings = static_cast<int>(settings.size());
  return out;
}

}  // namespace

DirectionData ReadDirections(const std::string& path,
                             const calib::Camera& camera,
                             double default_sigma_px) {
  const CsvTable table = CsvTable::Read(path);
  const auto one_camera =
      [&](const CsvTable& t, const CsvTable::Row& row, std::string*) -> const calib::Camera& {
    const std::string unit = t.String(row, "unit");
    if (!unit.empty())
      ThrowInputError(t.Where(row),
                      "unit " + unit +
                          ": the camera file is one camera; a unit names a head of a rig file or a "
                          "sub-image of a multi-CCD camera file (--camera)");
    return camera;
  };
  return ReadRows(table, path, one_camera, default_sigma_px);
}

DirectionData ReadUnitDirections(const std::string& path,
                                 const std::map<std::string, calib::Camera>& units,
                                 const std::string& camera_file,
                                 double default_sigma_px) {
  const CsvTable table = CsvTable::Read(path);
  std::string ids;
  for (const auto& [id, camera] : units) ids += (ids.empty() ? "" : ", ") + id;
  if (!table.HasColumn("unit"))
    ThrowInputError({path, 1},
                    "no 'unit' column: " + camera_file + " has several units (" + ids +
                        "); every row names the one that measured it");
  const auto unit_camera =
      [&](const CsvTable& t, const CsvTable::Row& row, std::string* unit) -> const calib::Camera& {
    *unit = t.String(row, "unit");
    if (unit->empty())
      ThrowInputError(t.Where(row),
                      "unit must not be empty (every row names its unit: " + ids + ")");
    const auto it = units.find(*unit);
    if (it == units.end())
      ThrowInputError(t.Where(row),
                      "unit " + *unit + " is not a unit of " + camera_file + " (" + ids + ")");
    return it->second;
  };
  return ReadRows(table, path, unit_camera, default_sigma_px);
}

}  // namespace aerocal::triangulation
