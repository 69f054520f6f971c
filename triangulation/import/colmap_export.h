// Writes a block as a COLMAP text model (the inverse of colmap_import.h, same conventions), so
// the same data can be adjusted by `colmap bundle_adjuster` for comparison. Cameras become
// OPENCV (fx = fy = c / p, cx = x0 / p + W / 2, cy = -y0 / p + H / 2, k1 = k2 = p1 = p2 = 0); the
// 10-parameter distortion terms are not exported (the nominal cameras of a comparison have none).
// Points need coordinates: pass the starting coordinates (e.g. forward intersections).
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <map>
#include <string>

namespace aerocal::triangulation {

/// Observations of points absent from `points_m` are left out. Files written atomically.
void WriteColmapModel(const Project& project,
                      const std::map<std::string, Eigen::Vector3d>& points_m,
                      const std::string& folder);

}  // namespace aerocal::triangulation
