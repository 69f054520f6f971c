// The real UAV block ../shared/data/odm_br_uav_gcp_block imported as a user would (ODM GCP list,
// the author's control subset, the other targets check points) with starting values from the
// surveyed targets: shared by the real-data test and the snooping benchmark.
#pragma once

#include "triangulation/adjustment/nadir_start.h"
#include "triangulation/import/odm_gcp_import.h"

#include <set>
#include <string>

namespace aerocal::testing {

/// `dir` is SharedDataDir("odm_br_uav_gcp_block"); `control_ids` (optional) receives the ids of
/// the author's control subset (gcp_list_raw.txt).
inline triangulation::Project ImportOdmUavBlock(const std::string& dir,
                                                std::set<std::string>* control_ids = nullptr) {
  // Canon PowerShot SX260 HS: 4000 x 3000 px, f = 4.5 mm ~ 2904 px (the author's note).
  triangulation::OdmImportOptions in;
  in.gcp_list = dir + "/odm_gcp_br/gcp_list_floatxy_raw.txt";
  in.camera.name = "Canon PowerShot SX260 HS";
  in.camera.width_px = 4000;
  in.camera.height_px = 3000;
  in.camera.pixel_size_mm = 4.5 / 2904.0;
  in.camera.interior[calib::BrownFraser10Model::kC] = 4.5;
  {
    triangulation::OdmImportOptions subset;
    subset.gcp_list = dir + "/odm_gcp_br/gcp_list_raw.txt";
    subset.camera = in.camera;
    for (const auto& p : triangulation::ImportOdmGcpList(subset).points)
      in.control_ids.insert(p.id);
  }
  if (control_ids) *control_ids = in.control_ids;
  triangulation::Project project = triangulation::ImportOdmGcpList(in);
  // Starting values from every surveyed target (a similarity per near-nadir image).
  project.exposures = triangulation::NadirStartFromControl(project, "cam1");
  return project;
}

}  // namespace aerocal::testing
