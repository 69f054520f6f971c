#include "tools/rig_design_document.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "tools/rig_stitch_run.h"

namespace aerocal::tools {
namespace {

nlohmann::json PointJson(const Eigen::Vector2d& p) { return {p.x(), p.y()}; }

}  // namespace

double FlyingHeight(const calib::Rig& rig, double given_m, const std::string& file) {
  const double height_m = given_m != 0.0                ? given_m
                          : rig.virtual_camera.height_m ? *rig.virtual_camera.height_m
                                                        : 0.0;
  if (!(height_m > 0))
    throw ConfigError("--height-m: give the relative flying height (> 0 m; the rig file " + file +
                      " has no virtual.height_m)");
  if (!(height_m >= 1 && height_m <= 1e5))
    throw ConfigError("--height-m must be within 1 .. 100000 m (got " + FormatNumber(height_m) +
                      ")");
  return height_m;
}

nlohmann::json RigDesignDocument(const calib::Rig& rig,
                                 const std::string& camera_file,
                                 double height_m,
                                 const stitch::RigDesign& d,
                                 const std::string& svg) {
  const calib::Camera& v = rig.virtual_camera.camera;
  nlohmann::json doc;
  doc["kind"] = "rig_design";
  doc["camera_models"] = HeadCameraModels(rig);
  doc["camera"] = camera_file;
  doc["height_m"] = height_m;
  doc["virtual_gsd_m"] = d.virtual_gsd_m;
  for (const stitch::HeadDesign& head : d.heads) {
    nlohmann::json h = {
        {"id", head.id}, {"tilt_deg", head.tilt_deg}, {"nadir_gsd_m", head.nadir_gsd_m}};
    for (const stitch::GsdSample& s : head.samples) {
      nlohmann::json row = {
          {"where", s.where},
          {"pixel", PointJson(s.pixel)},
          {"off_axis_deg", s.off_axis_deg},
          {"gsd_ratio", {{"along_tilt", s.ratio.x()}, {"across_tilt", s.ratio.y()}}}};
      row["closed_form"] = s.on_tilt_line ? nlohmann::json{{"along_tilt", s.closed_form.x()},
                                                           {"across_tilt", s.closed_form.y()}}
                                          : nlohmann::json();
      h["gsd"].push_back(row);
    }
    for (const auto& p : head.footprint_m) h["footprint_m"].push_back(PointJson(p));
    doc["heads"].push_back(h);
  }
  const auto rect = [](const stitch::PixelRectangle& r) {
    return nlohmann::json{{"min_px", PointJson(r.min_px)},
                          {"max_px", PointJson(r.max_px)},
                          {"width_px", r.Width()},
                          {"height_px", r.Height()}};
  };
  doc["virtual_format"] = {
      {"file_px", {v.width_px, v.height_px}},
      {"needed", rect(d.covered_box_px)},
      {"fits",
       d.covered_box_px.min_px.x() >= -0.5 && d.covered_box_px.min_px.y() >= -0.5 &&
           d.covered_box_px.max_px.x() <= v.width_px - 0.5 &&
           d.covered_box_px.max_px.y() <= v.height_px - 0.5}};
  doc["covered_area_m2"] = d.covered_area_m2;
  doc["effective_format"] = rect(d.effective_px);
  doc["effective_format"]["width_m"] = d.effective_px.Width() * d.virtual_gsd_m;
  doc["effective_format"]["height_m"] = d.effective_px.Height() * d.virtual_gsd_m;
  doc["effective_format"]["area_m2"] = d.effective_area_m2;
  doc["grid"] = {
      {"cell_px", d.coverage.cell_px}, {"cols", d.coverage.cols}, {"rows", d.coverage.rows}};
  for (const auto& [zone, area] : d.zone_area_m2) doc["zones"][zone] = {{"area_m2", area}};
  for (const auto& s : d.standard_positions)
    doc["standard_positions"].push_back(
        {{"name", s.name}, {"zone", s.zone}, {"virtual_px", PointJson(s.virtual_px)}});
  doc["plot_svg"] = svg.empty() ? nlohmann::json() : nlohmann::json(svg);
  return doc;
}

}  // namespace aerocal::tools
