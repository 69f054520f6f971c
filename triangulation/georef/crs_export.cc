#include "triangulation/georef/crs_export.h"

#include "calib/camera/rotation.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/georef/crs.h"
#include "triangulation/georef/object_frame.h"

#include <Eigen/SVD>

#include <cmath>
#include <filesystem>
#include <sstream>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& j) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(j, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) r = -r;
  return r;
}

Eigen::Vector3d Vec(const nlohmann::json& v, const std::string& what) {
  if (!v.is_array() || v.size() != 3) throw InputError("result: " + what + " is not [X, Y, Z]");
  return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

// The project's frame with both files in `crs` (same main CRS, so the same pivot datum, and the
// same origin as `from`): ToInput of it writes tangent-plane coordinates in `crs`.
FrameSpec TargetSpec(const FrameSpec& spec, const ObjectFrame& from, const std::string& crs) {
  FrameSpec out = spec;
  out.points_crs = out.exposures_crs = crs;
  const Eigen::Vector3d origin = from.Origin();
  out.has_origin = true;
  out.lon_deg = origin.x();
  out.lat_deg = origin.y();
  out.h_m = origin.z();
  return out;
}

std::string Number(double v, int digits = 12) { return FormatNumber(v, digits); }

using File = ObjectFrame::File;

// Converts a result's coordinates (in the project's CRS) into the output frames' CRS.
struct CrsExport {
  const ObjectFrame& from;
  const std::string& write_crs;
  Eigen::Vector3d Convert(const Eigen::Vector3d& in,
                          File file,
                          const ObjectFrame& out,
                          const std::string& what) const {
    const Eigen::Vector3d x = out.ToInput(from.ToAdjustment(in, file));
    if (!x.allFinite())
      throw InputError("result: " + what + " cannot be converted to " + write_crs);
    return x;
  }
};

// Exposures: centres and attitudes (relative to the CRS's axes at the exposure).
void WriteExposuresInCrs(const CrsExport& x,
                         const ObjectFrame& to,
                         const nlohmann::json& result,
                         const std::string& folder) {
  WriteFileAtomically(folder + "/exposures.csv", [&](std::ostream& out) {
    out << "image,X,Y,Z,omega,phi,kappa\n";
    for (const auto& e : result.at("exposures")) {
      const std::string image = e.at("image").get<std::string>();
      const Eigen::Vector3d c_in(
          e.at("X").get<double>(), e.at("Y").get<double>(), e.at("Z").get<double>());
      const Eigen::Vector3d opk_in(e.at("omega").get<double>() * kDegToRad,
                                   e.at("phi").get<double>() * kDegToRad,
                                   e.at("kappa").get<double>() * kDegToRad);
      const Eigen::Vector3d c_out = x.Convert(c_in, File::kExposures, to, "exposure " + image);
      const Eigen::Matrix3d r_local =
          NearestRotation(x.from.MetricJacobian(c_in, File::kExposures)) *
          calib::RotationFromOpk(opk_in);
      const Eigen::Vector3d opk_out = calib::OpkFromRotation(
          NearestRotation(to.MetricJacobian(c_out, File::kExposures)).transpose() * r_local);
      out << image << "," << Number(c_out.x()) << "," << Number(c_out.y()) << ","
          << Number(c_out.z()) << "," << Number(opk_out.x() / kDegToRad, 10) << ","
          << Number(opk_out.y() / kDegToRad, 10) << "," << Number(opk_out.z() / kDegToRad, 10)
          << "\n";
    }
  });
}

// Points: every adjusted point with its role.
void WritePointsInCrs(const CrsExport& x,
                      const ObjectFrame& to,
                      const nlohmann::json& result,
                      const std::string& folder) {
  WriteFileAtomically(folder + "/points.csv", [&](std::ostream& out) {
    out << "point,X,Y,Z,role\n";
    for (const auto& [table, role] :
         {std::pair<const char*, const char*>{"control", "control"}, {"check", "check"}})
      for (const auto& p : result.at(table).at("points")) {
        const std::string id = p.at("point").get<std::string>();
        const Eigen::Vector3d c =
            x.Convert(Vec(p.at("adjusted"), id), File::kPoints, to, std::string(role) + " " + id);
        out << id << "," << Number(c.x()) << "," << Number(c.y()) << "," << Number(c.z()) << ","
            << role << "\n";
      }
  });
}

// Check-point errors for QGIS (RFC 7946 GeoJSON: WGS84 longitude, latitude).
void WriteCheckErrorsGeoJson(const CrsExport& x,
                             const ObjectFrame& wgs84,
                             const nlohmann::json& result,
                             const std::string& folder) {
  nlohmann::json features = nlohmann::json::array();
  for (const auto& p : result.at("check").at("points")) {
    const std::string id = p.at("point").get<std::string>();
    const Eigen::Vector3d g =
        x.Convert(Vec(p.at("adjusted"), id), File::kPoints, wgs84, "check " + id);
    const Eigen::Vector3d d = Vec(p.at("difference_m"), id);
    features.push_back({{"type", "Feature"},
                        {"geometry", {{"type", "Point"}, {"coordinates", {g.x(), g.y(), g.z()}}}},
                        {"properties",
                         {{"point", id},
                          {"dX_m", d.x()},
                          {"dY_m", d.y()},
                          {"dZ_m", d.z()},
                          {"d_plan_m", std::hypot(d.x(), d.y())},
                          {"d_m", d.norm()},
                          {"rays", p.value("rays", 0)}}}});
  }
  const nlohmann::json geojson = {
      {"type", "FeatureCollection"}, {"name", "check_errors"}, {"features", features}};
  WriteFileAtomically(folder + "/check_errors.geojson", geojson.dump(1) + "\n");
}

// crs.txt: what the files' numbers are.
void WriteCrsNote(const CrsConverter& target,
                  const std::string& write_crs,
                  const ObjectFrame& from,
                  const std::string& folder) {
  std::ostringstream crs;
  crs << "exposures.csv, points.csv: " << target.Name() << " (" << write_crs << "; "
      << (target.axes() == CrsConverter::Axes::kGeographic  ? "X = longitude, Y = latitude (deg)"
          : target.axes() == CrsConverter::Axes::kProjected ? "X = easting, Y = northing (m)"
                                                            : "X, Y, Z geocentric (m)")
      << (target.axes() == CrsConverter::Axes::kGeocentric ? ""
          : target.orthometric()                           ? ", Z = orthometric height (m)"
                                                           : ", Z = ellipsoidal height (m)")
      << "); omega, phi, kappa (deg) relative to that CRS's axes at the exposure\n"
      << "check_errors.geojson: WGS 84 longitude, latitude (deg), ellipsoidal height (m); "
         "dX_m, dY_m, dZ_m = adjusted - surveyed in metres east, north, up of the adjustment's "
         "tangent plane\n"
      << "converted from: " << from.Description() << "\n";
  WriteFileAtomically(folder + "/crs.txt", crs.str());
}

}  // namespace

void ExportResultInCrs(const Project& project,
                       const nlohmann::json& result,
                       const std::string& write_crs,
                       const std::string& folder) {
  if (project.frame.kind != FrameSpec::Kind::kCrs)
    throw InputError(project.path +
                     ": --write-crs needs a project with frame: {crs: ...} (the "
                     "CRS its numbers are in)");
  const ObjectFrame from(project.frame);
  from.FixOrigin(project);
  const ObjectFrame to(TargetSpec(project.frame, from, write_crs));
  const ObjectFrame wgs84(TargetSpec(project.frame, from, "EPSG:4979"));
  const CrsConverter target(CrsOptions{write_crs, "", "", "--write-crs"});
  const CrsExport x{from, write_crs};
  std::filesystem::create_directories(folder);
  WriteExposuresInCrs(x, to, result, folder);
  WritePointsInCrs(x, to, result, folder);
  WriteCheckErrorsGeoJson(x, wgs84, result, folder);
  WriteCrsNote(target, write_crs, from, folder);
}

}  // namespace aerocal::triangulation
