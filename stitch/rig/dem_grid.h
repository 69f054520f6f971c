// A DEM grid as the rectification surface of `aerocal rig convert` (CONVENTIONS.md "Multi-head
// rigs": "or a DEM / per-point heights where given"). File: the ESRI ASCII grid (`.asc`): header
// lines `ncols N`, `nrows M`, `xllcorner X` | `xllcenter X`, `yllcorner Y` | `yllcenter Y`,
// `cellsize S` (m), optional `NODATA_value V`, then M rows of N heights (m), the first row the
// northernmost (largest Y). Coordinates are those of the object frame of the exposure.
// Heights are sample values at cell centres, interpolated bilinearly between them.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::stitch {

struct DemGrid {
  int cols = 0, rows = 0;      // >= 2 each
  double x0_m = 0, y0_m = 0;   // centre of the south-west cell (object frame)
  double cell_m = 0;           // > 0
  std::vector<double> height;  // row-major from the SOUTH row up; NaN = no data

  /// Bilinear height at (x, y); nullopt outside the centres' hull or next to a no-data sample.
  std::optional<double> HeightAt(double x_m, double y_m) const;
  /// Mean of the valid heights.
  double MeanHeight() const;
};

/// Reads an ESRI ASCII grid; InputError("FILE:LINE: what") on a bad header, a missing or
/// non-numeric height, fewer than 2 x 2 samples or no valid sample.
DemGrid ReadDemAscii(const std::string& path);

/// Point where the ray origin + s direction (s > 0) meets the DEM, by fixed-point iteration on
/// the height (converges for rays steeper than the terrain slopes, as near-nadir rays over
/// terrain are) to 1e-6 m; nullopt when the ray leaves the grid or does not converge.
std::optional<Eigen::Vector3d> IntersectDem(const DemGrid& dem,
                                            const Eigen::Vector3d& origin,
                                            const Eigen::Vector3d& direction);

}  // namespace aerocal::stitch
