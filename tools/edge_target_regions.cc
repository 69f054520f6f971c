#include "tools/edge_target_regions.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/result_file.h"
#include "stitch/io/stitch_result_json.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal::tools {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

// The exposures array of an adjust result, or of the flight result's adjustment that wrote the
// camera (the adjusted orientation the camera file belongs to).
const nlohmann::json& ExposuresOf(const nlohmann::json& doc,
                                  const std::string& path,
                                  std::string* adjustment) {
  if (doc.contains("exposures") && doc["exposures"].is_array()) return doc["exposures"];
  if (!doc.contains("adjustments") || !doc["adjustments"].is_array())
    throw InputError(path + ": not an adjust or flight result (no exposures, no adjustments)");
  std::string wanted;
  if (doc.contains("camera_written_from") && doc["camera_written_from"].is_object() &&
      doc["camera_written_from"].value("adjustment", nlohmann::json()).is_string())
    wanted = doc["camera_written_from"]["adjustment"].get<std::string>();
  const nlohmann::json* chosen = nullptr;
  for (const auto& a : doc["adjustments"]) {
    if (!a.is_object() || !a.contains("exposures") || !a["exposures"].is_array()) continue;
    const std::string name =
        a.contains("name") && a["name"].is_string() ? a["name"].get<std::string>() : "";
    if (wanted.empty() || name == wanted) chosen = &a, *adjustment = name;
    if (!wanted.empty() && name == wanted) break;
  }
  if (chosen == nullptr) throw InputError(path + ": no adjustment with exposures");
  return (*chosen)["exposures"];
}

double JsonNumber(const nlohmann::json& e, const char* key, const std::string& where) {
  if (!e.contains(key) || !e[key].is_number() || !std::isfinite(e[key].get<double>()))
    throw InputError(where + ": exposure without a finite " + key);
  return e[key].get<double>();
}

// The projected edge's position across `region` (file px) at the region's middle line, in the
// slanted-edge measurement's convention (stitch::SlantedEdgeResult::edge_offset_px).
double ProjectedOffset(const stitch::EdgeTargetRegion& t,
                       const stitch::PixelRegion& region,
                       const Eigen::Vector2i& origin_px) {
  const Eigen::Vector2d a = t.start_px - origin_px.cast<double>();
  const Eigen::Vector2d d = t.end_px - t.start_px;
  if (t.axis == stitch::MtfAxis::kX) {
    const double row = region.row + 0.5 * (region.height - 1);
    return a.x() + (row - a.y()) * d.x() / d.y() - region.col;
  }
  const double col = region.col + 0.5 * (region.width - 1);
  return a.y() + (col - a.x()) * d.y() / d.x() - region.row;
}

// The edge `v` of the virtual image in raw sub-image `sub`: its ends mapped by the sub-image's
// projectivity, the region built in the sub-image's format.
stitch::EdgeTargetRegion InSubimage(const stitch::EdgeTargetRegion& v,
                                    const calib::SubimageMapping& sub,
                                    const stitch::EdgeTarget& target,
                                    const stitch::EdgeTargetRegionOptions& options) {
  stitch::EdgeTargetRegion t = stitch::RegionOfImageEdge(target.id,
                                                         sub.SubFromVirtual(v.start_px),
                                                         sub.SubFromVirtual(v.end_px),
                                                         (target.end_m - target.start_m).norm(),
                                                         sub.width_px,
                                                         sub.height_px,
                                                         options);
  if (!t.usable) t.reason = "not in sub-image " + sub.id + ": " + t.reason;
  return t;
}

}  // namespace

calib::Camera CameraWithMappings(const calib::Camera& camera,
                                 const std::string& path,
                                 const std::string& frame) {
  const nlohmann::json doc = ReadResult(path, {"stitch", "flight"}, "`aerocal stitch` or `flight`");
  if (doc.at("kind") == "stitch") return stitch::ApplyStitchDocument(camera, doc, path, frame);
  if (!doc.contains("stitching") || !doc["stitching"].is_object())
    throw InputError(path + ": a flight result without its stitching (no sub-image mappings)");
  return stitch::ApplyStitchDocument(camera, doc["stitching"], path + ": stitching", frame);
}

std::vector<stitch::EdgeTarget> ReadEdgeTargets(const std::string& path) {
  const std::vector<std::string> columns = {
      "id", "start_x", "start_y", "start_z", "end_x", "end_y", "end_z"};
  const CsvTable t = CsvTable::Read(path);
  t.RequireColumns(columns);
  t.RejectUnknownColumns(columns);
  std::vector<stitch::EdgeTarget> targets;
  std::set<std::string> ids;
  for (const auto& row : t.rows()) {
    const std::string where = path + ":" + std::to_string(row.line);
    stitch::EdgeTarget e;
    e.id = t.String(row, "id");
    if (e.id.empty()) throw InputError(where + ": empty id");
    if (!ids.insert(e.id).second) throw InputError(where + ": repeated id '" + e.id + "'");
    const double big = 1e8;  // m: any projected or local frame
    e.start_m = {t.Bounded(row, "start_x", -big, big),
                 t.Bounded(row, "start_y", -big, big),
                 t.Bounded(row, "start_z", -big, big)};
    e.end_m = {t.Bounded(row, "end_x", -big, big),
               t.Bounded(row, "end_y", -big, big),
               t.Bounded(row, "end_z", -big, big)};
    if ((e.end_m - e.start_m).norm() <= 0.0)
      throw InputError(where + ": edge '" + e.id + "' has zero length");
    targets.push_back(e);
  }
  if (targets.empty()) throw InputError(path + ": no edge targets");
  return targets;
}

ExposureOrientation ReadExposureOrientation(const std::string& result_path,
                                            const std::string& image) {
  const nlohmann::json doc = ReadJsonFile(result_path);
  ExposureOrientation out;
  for (const auto& e : ExposuresOf(doc, result_path, &out.adjustment)) {
    if (!e.is_object() || e.value("image", nlohmann::json()) != image) continue;
    const std::string where = result_path + ": image '" + image + "'";
    out.center_m = {
        JsonNumber(e, "X", where), JsonNumber(e, "Y", where), JsonNumber(e, "Z", where)};
    out.opk_rad = kDegToRad * Eigen::Vector3d(JsonNumber(e, "omega", where),
                                              JsonNumber(e, "phi", where),
                                              JsonNumber(e, "kappa", where));
    return out;
  }
  throw InputError(result_path + ": no exposure of image '" + image + "'" +
                   (out.adjustment.empty() ? "" : " in adjustment " + out.adjustment));
}

FoundEdgeRegions FindEdgeRegions(const calib::Camera& camera,
                                 const ExposureOrientation& orientation,
                                 const std::vector<stitch::EdgeTarget>& targets,
                                 const std::vector<std::string>& only,
                                 const Eigen::Vector2i& origin_px,
                                 int file_cols,
                                 int file_rows,
                                 const stitch::EdgeTargetRegionOptions& options,
                                 const calib::SubimageMapping* subimage) {
  for (const std::string& id : only)
    if (std::none_of(targets.begin(), targets.end(), [&](const auto& t) { return t.id == id; }))
      throw ConfigError("--target: no edge target '" + id + "' in the target file");
  FoundEdgeRegions out;
  for (const stitch::EdgeTarget& target : targets) {
    if (!only.empty() && std::find(only.begin(), only.end(), target.id) == only.end()) continue;
    const stitch::EdgeTargetRegion v = stitch::RegionOfEdgeTarget(
        camera, orientation.opk_rad, orientation.center_m, target, options);
    if (!v.usable) {
      out.skipped.emplace_back(target.id, v.reason);
      continue;
    }
    const stitch::EdgeTargetRegion t =
        subimage == nullptr ? v : InSubimage(v, *subimage, target, options);
    if (!t.usable) {
      out.skipped.emplace_back(target.id, t.reason);
      continue;
    }
    stitch::PixelRegion r = t.region;
    r.col -= origin_px.x(), r.row -= origin_px.y();
    if (r.col < 0 || r.row < 0 || r.col + r.width > file_cols || r.row + r.height > file_rows) {
      out.skipped.emplace_back(target.id, "the region leaves the image file");
      continue;
    }
    out.found.push_back({t, v, r, ProjectedOffset(t, r, origin_px)});
  }
  return out;
}

}  // namespace aerocal::tools
