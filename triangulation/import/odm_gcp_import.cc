#include "triangulation/import/odm_gcp_import.h"

#include "calib/core/error.h"
#include "calib/core/log.h"
#include "triangulation/adjustment/nadir_start.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/import/text_rows.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>

namespace aerocal::triangulation {

namespace {

// Geographic lists (PROJ "+proj=longlat"/"latlong", EPSG:4326 / 4979, "WGS84" alone) hold
// degrees, which the similarity start and the projected frame cannot take.
bool IsGeographicProjection(const std::string& projection) {
  std::string lower = projection;
  std::transform(
      lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  return lower.find("longlat") != std::string::npos || lower.find("latlong") != std::string::npos ||
         lower.find("lonlat") != std::string::npos || lower.find("latlon") != std::string::npos ||
         lower.find("4326") != std::string::npos || lower.find("4979") != std::string::npos ||
         lower == "wgs84" || lower == "wgs 84";
}

// The project's object frame: the list's projection as given, or --crs (checked here: an
// unknown CRS or a missing grid is exit 2).
FrameSpec OdmFrame(const OdmImportOptions& o, const std::string& projection) {
  FrameSpec frame;
  frame.kind = FrameSpec::Kind::kProjected;
  frame.description = projection;
  if (!o.crs.empty()) {
    frame.kind = FrameSpec::Kind::kCrs;
    frame.crs = o.crs;
    frame.description = "crs " + o.crs;
    frame.source = "--crs";
    (void)ObjectFrame(frame);
  }
  return frame;
}

// One row `geo_x geo_y geo_z im_x im_y image_name [gcp_name]`: the observation (pixel scaled to
// the full format, inside it) and the target's coordinates in `xyz`.
ImageObservation OdmObservation(const OdmImportOptions& o,
                                const internal::TextRow& row,
                                Eigen::Vector3d* xyz) {
  using internal::BoundedField;
  using internal::NumberField;
  *xyz = Eigen::Vector3d(BoundedField(row, 0, o.gcp_list, "geo_x", -1e8, 1e8),
                         BoundedField(row, 1, o.gcp_list, "geo_y", -1e8, 1e8),
                         BoundedField(row, 2, o.gcp_list, "geo_z", -1e8, 1e8));
  ImageObservation obs;
  obs.line = row.line;
  obs.pixel = Eigen::Vector2d(NumberField(row, 3, o.gcp_list, "im_x"),
                              NumberField(row, 4, o.gcp_list, "im_y")) *
              o.pixel_scale;
  obs.image = std::filesystem::path(internal::StringField(row, 5, o.gcp_list, "image_name"))
                  .stem()
                  .string();
  // Without a name, the coordinates identify the target.
  obs.point = row.fields.size() > 6 ? row.fields[6]
                                    : row.fields[0] + "_" + row.fields[1] + "_" + row.fields[2];
  obs.sigma_px = o.sigma_px;
  if (obs.pixel.x() < -0.5 || obs.pixel.y() < -0.5 || obs.pixel.x() > o.camera.width_px - 0.5 ||
      obs.pixel.y() > o.camera.height_px - 0.5)
    ThrowInputError({o.gcp_list, row.line},
                    "pixel outside the " + std::to_string(o.camera.width_px) + " x " +
                        std::to_string(o.camera.height_px) + " format");
  return obs;
}

// The target a row names: created at its first row (control when --control names it or names
// nothing, else check); a later row must give the same coordinates.
void AddTarget(const OdmImportOptions& o,
               const ImageObservation& obs,
               const Eigen::Vector3d& xyz,
               std::map<std::string, GroundPoint>* points) {
  auto [it, inserted] = points->try_emplace(obs.point);
  GroundPoint& p = it->second;
  if (inserted) {
    p.id = obs.point;
    p.line = obs.line;
    p.xyz_m = xyz;
    p.sigma_m = Eigen::Vector3d::Constant(o.target_sigma_m);
    p.role = o.control_ids.empty() || o.control_ids.count(p.id) ? PointRole::kControl
                                                                : PointRole::kCheck;
  } else if ((*p.xyz_m - xyz).norm() > 1e-6) {
    ThrowInputError({o.gcp_list, obs.line},
                    "target " + p.id + " has other coordinates on line " + std::to_string(p.line));
  }
}

// An image seeing fewer than two distinct targets gets no starting orientation: left out, with
// a warning per image.
std::vector<ImageObservation> WithoutImagesOfOneTarget(
    const std::string& gcp_list, const std::vector<ImageObservation>& observations) {
  std::map<std::string, std::set<std::string>> targets_of_image;
  for (const auto& obs : observations) targets_of_image[obs.image].insert(obs.point);
  std::vector<ImageObservation> kept;
  for (const auto& obs : observations)
    if (targets_of_image[obs.image].size() >= 2) kept.push_back(obs);
  for (const auto& [image, targets] : targets_of_image)
    if (targets.size() < 2)
      LogWarning(gcp_list + ": image " + image + " sees " + std::to_string(targets.size()) +
                 " target(s) only: no starting orientation; left out");
  return kept;
}

}  // namespace

Project ImportOdmGcpList(const OdmImportOptions& o) {
  if (!(o.sigma_px > 0) || !(o.target_sigma_m > 0) || !(o.pixel_scale > 0))
    throw ConfigError("ODM import: sigma_px, target_sigma_m and pixel_scale must be > 0");
  const auto rows = internal::ReadTextRows(o.gcp_list, false);
  if (rows.empty()) ThrowInputError({o.gcp_list, 1}, "empty GCP list (expected a projection line)");
  std::string projection;
  for (const auto& f : rows.front().fields) projection += (projection.empty() ? "" : " ") + f;
  if (IsGeographicProjection(projection) && o.crs.empty())
    ThrowInputError({o.gcp_list, rows.front().line},
                    "geographic GCP coordinates (" + projection +
                        "): give their CRS (--crs EPSG:4326, longitude first) or a projected list");
  Project project;
  project.path = o.gcp_list;
  project.cameras["cam1"] = o.camera;
  project.frame = OdmFrame(o, projection);
  std::map<std::string, GroundPoint> points;
  for (size_t i = 1; i < rows.size(); ++i) {
    Eigen::Vector3d xyz;
    const ImageObservation obs = OdmObservation(o, rows[i], &xyz);
    AddTarget(o, obs, xyz, &points);
    project.observations.push_back(obs);
  }
  if (project.observations.empty())
    ThrowInputError({o.gcp_list, 0},
                    "no targets listed (only the projection line): nothing to import");
  for (const auto& id : o.control_ids)
    if (!points.count(id))
      throw ConfigError("--control: '" + id + "' is no target of " + o.gcp_list +
                        " (every control name must match a target)");
  project.observations = WithoutImagesOfOneTarget(o.gcp_list, project.observations);
  for (auto& [id, p] : points) project.points.push_back(p);
  return project;
}

Project WithNadirStart(const Project& project, const std::string& camera) {
  if (project.frame.kind != FrameSpec::Kind::kCrs) {
    Project out = project;
    out.exposures = NadirStartFromControl(project, camera);
    return out;
  }
  const ObjectFrame frame(project.frame);
  Project local = ToAdjustmentFrame(project, frame);
  local.exposures = NadirStartFromControl(local, camera);
  // Only the new exposures are converted back: the points stay exactly as listed.
  const Project converted = FromAdjustmentFrame(local, frame);
  Project out = project;
  out.exposures = converted.exposures;
  out.frame = converted.frame;  // with the origin fixed at the block centre
  return out;
}

}  // namespace aerocal::triangulation
