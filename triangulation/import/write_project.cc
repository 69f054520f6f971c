#include "triangulation/import/write_project.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "triangulation/block/block_io.h"

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
  yaml += "frame: {projected: " + Quoted(project.frame.description) + "}\n";
  WriteFileAtomically(folder + "/project.yaml", yaml);
}

}  // namespace aerocal::triangulation
