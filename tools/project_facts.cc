#include "tools/project_facts.h"

#include "calib/core/file_digest.h"
#include "triangulation/block/block_io.h"

namespace aerocal::tools {

void AddProjectFacts(const triangulation::Project& input, nlohmann::json* json) {
  (*json)["aerocal_version"] = AEROCAL_VERSION;
  (*json)["inputs"] = InputFilesToJson(triangulation::ProjectFiles(input));
  const calib::Camera& camera = input.cameras.begin()->second;
  (*json)["camera_format"] = {{"width_px", camera.width_px},
                              {"height_px", camera.height_px},
                              {"pixel_size_mm", camera.pixel_size_mm}};
  (*json)["camera_names"] = nlohmann::json::object();
  for (const auto& [id, c] : input.cameras) (*json)["camera_names"][id] = c.name;
}

}  // namespace aerocal::tools
