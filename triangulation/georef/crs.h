// A coordinate reference system through PROJ (the only place in aerocal that uses PROJ;
// CONVENTIONS.md "Object frame and georeferencing"). A CrsConverter converts the coordinates of
// one file's CRS into the geographic 3D CRS of the block's datum (the pivot: longitude, latitude
// in degrees, ellipsoidal height in metres) and back, in PROJ's normalised axis order (easting /
// longitude first, as GIS tools write files), whatever order the CRS definition declares.
//
// Heights: a CRS with a vertical component (compound "EPSG:32632+5783", or `vertical` given
// separately) is converted with the geoid model PROJ finds among the installed grids; a user grid
// (`geoid_grid`, a GTX / GeoTIFF file PROJ reads) adds its undulation to the heights (h = H + N).
// A needed grid that is not installed is an InputError naming it, never a silent ellipsoidal
// height. A CRS without a vertical component takes its heights as ellipsoidal heights of its
// datum. The network is off: PROJ never downloads grids.
#pragma once

#include <Eigen/Core>

#include <memory>
#include <string>

namespace aerocal::triangulation {

struct CrsOptions {
  std::string definition;  // anything PROJ reads: "EPSG:32632", "EPSG:2056+5728", WKT, PROJ string
  std::string vertical;    // optional vertical CRS ("EPSG:5783"), combined with `definition`
  std::string geoid_grid;  // optional grid file: heights are orthometric above it
  std::string where;       // "project.yaml:7: frame: crs" for error messages
};

class CrsConverter {
 public:
  enum class Axes { kGeographic, kProjected, kGeocentric };

  /// `pivot` is the PROJ definition (WKT or PROJJSON) of the geographic 3D CRS to convert to;
  /// empty: the one of this CRS's own datum (PivotDefinition()). InputError (naming `where` and
  /// the grid) when PROJ cannot read the CRS or a grid is missing.
  CrsConverter(const CrsOptions& options, const std::string& pivot = "");
  ~CrsConverter();
  CrsConverter(CrsConverter&&) noexcept;
  CrsConverter& operator=(CrsConverter&&) noexcept;

  /// Coordinates of the file (x, y, z in the normalised axis order) -> pivot (lon, lat deg, h m).
  /// NaN where PROJ cannot convert.
  Eigen::Vector3d ToPivot(const Eigen::Vector3d& in) const;
  Eigen::Vector3d FromPivot(const Eigen::Vector3d& lon_lat_h) const;

  /// The pivot CRS (WKT) and its ellipsoid.
  const std::string& PivotDefinition() const;
  double semi_major_m() const;
  double flattening() const;
  Axes axes() const;
  /// True when the heights are orthometric (a vertical CRS or a user geoid grid).
  bool orthometric() const;
  /// PROJ's name of the CRS, its definition as given, and the operation used (with its grids).
  std::string Name() const;
  std::string Definition() const;
  std::string OperationDescription() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace aerocal::triangulation
