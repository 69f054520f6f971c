#include "triangulation/import/write_project.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/log.h"
#include "triangulation/block/block_io.h"

#include <cmath>
#include <set>

namespace aerocal::triangulation {
namespace {

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (char ch : text) {
    if (ch == '"' || ch == '\\') out += '\\';
    out += ch;
  }
  return out + "\"";
}

}  // namespace

std::string FrameYaml(const FrameSpec& f) {
  if (f.kind != FrameSpec::Kind::kCrs) return "frame: {projected: " + Quoted(f.description) + "}";
  std::string yaml = "frame: {crs: " + Quoted(f.crs);
  if (!f.vertical.empty()) yaml += ", vertical: " + Quoted(f.vertical);
  if (!f.geoid_grid.empty()) yaml += ", geoid_grid: " + Quoted(f.geoid_grid);
  if (!f.points_crs.empty()) yaml += ", points_crs: " + Quoted(f.points_crs);
  if (!f.exposures_crs.empty()) yaml += ", exposures_crs: " + Quoted(f.exposures_crs);
  if (f.has_origin)
    yaml += ", origin: {lat: " + FormatNumber(f.lat_deg, 15) +
            ", lon: " + FormatNumber(f.lon_deg, 15) + ", h: " + FormatNumber(f.h_m, 10) + "}";
  return yaml + "}";
}

Project UsableImportedBlock(const Project& project, const std::string& source) {
  Project out = project;
  std::set<std::string> observed;
  for (const auto& o : project.observations) observed.insert(o.image);
  out.exposures.clear();
  for (const auto& e : project.exposures) {
    if (observed.count(e.image))
      out.exposures.push_back(e);
    else
      LogWarning(source + ": image " + e.image + " has no usable observation: left out");
  }
  if (out.observations.empty())
    throw InputError(source + ": no image observations: nothing to adjust (no block written)");
  if (out.exposures.size() < 2)
    throw InputError(source + ": " + std::to_string(out.exposures.size()) +
                     " observed exposure(s): a block needs two or more (no block written)");
  for (const auto& [id, camera] : out.cameras)
    if (!(camera.width_px > 0 && camera.height_px > 0 && camera.pixel_size_mm > 0 &&
          camera.c_mm() > 0 && std::isfinite(camera.c_mm())))
      throw InputError(source + ": camera " + id + " has no usable format or principal distance");
  return out;
}

void WriteProjectFolder(const Project& project, const std::string& folder) {
  std::string yaml = "# Imported from " + project.path + "\ncameras:\n";
  for (const auto& [id, camera] : project.cameras) {
    const std::string file = "camera_" + id + ".yaml";
    calib::WriteCamera(folder + "/" + file, camera);
    yaml += "  " + Quoted(id) + ": " + file + "\n";
  }
  WriteExposures(folder + "/exposures.csv", project.exposures);
  WriteObservations(folder + "/observations.csv", project.observations);
  WritePoints(folder + "/points.csv", project.points);
  yaml += "exposures: exposures.csv\nobservations: observations.csv\npoints: points.csv\n";
  yaml += FrameYaml(project.frame) + "\n";
  WriteFileAtomically(folder + "/project.yaml", yaml);
}

}  // namespace aerocal::triangulation
