// Writes a block as a COLMAP text model (the inverse of colmap_import.h, same conventions), so
// the same data can be adjusted by `colmap bundle_adjuster` for comparison. Cameras become
// OPENCV through calib::ConvertCamera: exact without distortion (fx = c / ((1 + B1) p), fy = c / p,
// cx = x0 / p + W / 2, cy = -y0 / p + H / 2, k1 = k2 = p1 = p2 = 0); with distortion k1, k2, p1,
// p2 (and fx, fy, cx, cy) are fitted over the format and the residual is returned per camera
// (COLMAP's OPENCV has no K3 term and no shear B2).
// Points need coordinates: pass the starting coordinates (e.g. forward intersections).
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// Observations of points absent from `points_m` are left out. Files written atomically.
/// Returns one note per camera: exact, or the conversion residual RMS / max in pixels.
std::vector<std::string> WriteColmapModel(const Project& project,
                                          const std::map<std::string, Eigen::Vector3d>& points_m,
                                          const std::string& folder);

}  // namespace aerocal::triangulation
