// Adjusted exposures and points of `aerocal adjust`'s result.json written in any CRS
// (`aerocal export --write-crs`), and a GeoJSON of the check-point errors that QGIS opens.
// The result's numbers are in the project's files' CRSs (object_frame.h, crs: frames); they are
// converted through the project's tangent plane (the same origin as the adjustment) by PROJ,
// attitudes turned with the axes (the rotation nearest each CRS's Jacobian).
#pragma once

#include "triangulation/block/block.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::triangulation {

/// Writes FOLDER/exposures.csv (image, X, Y, Z, omega, phi, kappa in `write_crs`),
/// FOLDER/points.csv (point, X, Y, Z, role: every adjusted point) and
/// FOLDER/check_errors.geojson (RFC 7946: longitude/latitude WGS84 of each check point's adjusted
/// position, properties point, dX_m, dY_m, dZ_m (adjusted - surveyed, east/north/up metres of the
/// tangent plane), d_plan_m, d_m, rays). FOLDER/crs.txt states the CRS of every number. The
/// project needs a crs: frame; InputError otherwise, or when a value cannot be converted.
void ExportResultInCrs(const Project& project,
                       const nlohmann::json& result,
                       const std::string& write_crs,
                       const std::string& folder);

}  // namespace aerocal::triangulation
