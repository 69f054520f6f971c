// Importer of OpenDroneMap / OpenSfM `gcp_list.txt` (FORMATS.md "Imports"): the first line is
// the projection (a PROJ string or EPSG code), then `geo_x geo_y geo_z im_x im_y image_name
// [gcp_name] [extra...]`, blank-separated. ODM's pixel frame is aerocal's (origin at the centre
// of the top-left pixel, x = column, y = row), so pixels carry over unchanged; `pixel_scale`
// converts measurements made on resized images back to the full format (e.g. 1 / 0.6).
// Without `crs` the coordinates stay in the file's projected frame, which the project states
// (`frame: {projected: ...}`), and a geographic (EPSG:4326 / longlat) list is rejected. With `crs`
// (the CRS of the list's coordinates, e.g. its own first line or "EPSG:4326"; any CRS PROJ reads,
// compound with a vertical CRS for orthometric heights) the project gets `frame: {crs: ...}` and
// is adjusted in the local tangent plane (triangulation/georef/object_frame.h).
#pragma once

#include "triangulation/block/block.h"

#include <set>
#include <string>

namespace aerocal::triangulation {

struct OdmImportOptions {
  std::string gcp_list;
  calib::Camera camera;               // the camera of every image (format must match the list)
  std::set<std::string> control_ids;  // targets used as control; the others become check points
                                      // (empty: every target is control)
  double sigma_px = 1.0;              // a-priori sigma of the image measurements, > 0
  double target_sigma_m = 0.02;       // survey sigma of the targets, > 0
  double pixel_scale = 1.0;           // full-format px per listed px, > 0
  std::string crs;                    // CRS of the coordinates; empty: projected as given
};

/// Points (control/check), observations (image = file stem) and frame; no exposures (see
/// NadirStartFromControl for starting values). InputError("FILE:LINE: ...") on bad lines.
Project ImportOdmGcpList(const OdmImportOptions& options);

/// The imported block with starting exposures (NadirStartFromControl, camera `camera`), computed
/// in the adjustment frame for a crs: frame and written back in its CRS (the frame then states
/// its origin, the block centre).
Project WithNadirStart(const Project& project, const std::string& camera);

}  // namespace aerocal::triangulation
