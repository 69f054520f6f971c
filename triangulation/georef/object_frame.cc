#include "triangulation/georef/object_frame.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "triangulation/georef/crs.h"

#include <Eigen/SVD>
#include <GeographicLib/Constants.hpp>
#include <GeographicLib/Geocentric.hpp>
#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <cmath>
#include <cstdio>
#include <limits>

namespace aerocal::triangulation {

struct ObjectFrame::Impl {
  FrameSpec spec;
  std::unique_ptr<GeographicLib::LocalCartesian> local;
  int zone = 0;
  bool north = true;
  // crs: the main CRS (pivot datum, vertical), and the points' and exposures' CRSs (shared).
  std::shared_ptr<CrsConverter> main, points, exposures;
  double undulation_m = 0;

  const CrsConverter& Of(File file) const { return file == File::kPoints ? *points : *exposures; }
  void SetOrigin(double lat, double lon, double h) {
    const GeographicLib::Geocentric earth(main->semi_major_m(), main->flattening());
    local = std::make_unique<GeographicLib::LocalCartesian>(lat, lon, h, earth);
    spec.lat_deg = lat;
    spec.lon_deg = lon;
    spec.h_m = h;
    spec.has_origin = true;
    // The geoid undulation at the origin: the orthometric height of the ellipsoid point h0 is
    // h0 - N.
    if (points->orthometric()) undulation_m = h - points->FromPivot({lon, lat, h}).z();
  }
};

namespace {

// "project.yaml:7: frame: " or "frame: " when the frame has no source.
std::string FramePrefix(const FrameSpec& spec) {
  return (spec.source.empty() ? "" : spec.source + ": ") + "frame: ";
}

// A platform velocity given as east, north, up (m/s) at a geodetic position, in the axes of the
// adjustment frame: the displacement v * dt, taken in the exposure's own tangent plane and
// converted as the centres are, over dt = +-0.5 s (central difference). That carries the
// meridian convergence and the UTM point scale (grid metres per metre) for utm:, the rotation
// between the exposure's and the origin's tangent planes for local:. The error of the difference
// is of the order |v dt|^2 / Earth radius, < 1e-9 relative for aircraft speeds.
Eigen::Vector3d VelocityToAdjustment(const ObjectFrame& frame,
                                     const Eigen::Vector3d& geodetic,
                                     const Eigen::Vector3d& enu_mps) {
  const GeographicLib::LocalCartesian tangent(geodetic.y(), geodetic.x(), geodetic.z());
  const auto moved = [&](double dt) {
    const Eigen::Vector3d d = enu_mps * dt;
    double lat = 0, lon = 0, h = 0;
    tangent.Reverse(d.x(), d.y(), d.z(), lat, lon, h);
    return frame.ToAdjustment({lon, lat, h});
  };
  return moved(0.5) - moved(-0.5);
}

}  // namespace

ObjectFrame::ObjectFrame(const FrameSpec& spec) : impl_(std::make_unique<Impl>()) {
  impl_->spec = spec;
  switch (spec.kind) {
    case FrameSpec::Kind::kLocal:
    case FrameSpec::Kind::kGeodeticToLocal:
      if (!(std::abs(spec.lat_deg) <= 90.0) || !(spec.lon_deg >= -180.0 && spec.lon_deg <= 360.0) ||
          !(std::abs(spec.h_m) <= 1e5))
        throw InputError(FramePrefix(spec) + "local origin out of range (got lat " +
                         std::to_string(spec.lat_deg) + ", lon " + std::to_string(spec.lon_deg) +
                         ", h " + std::to_string(spec.h_m) +
                         "; expected |lat| <= 90 deg, lon -180 .. 360 deg, |h| <= 1e5 m)");
      impl_->local =
          std::make_unique<GeographicLib::LocalCartesian>(spec.lat_deg, spec.lon_deg, spec.h_m);
      break;
    case FrameSpec::Kind::kUtm:
      try {
        GeographicLib::UTMUPS::DecodeZone(spec.utm_zone, impl_->zone, impl_->north);
      } catch (const std::exception& e) {
        throw InputError(FramePrefix(spec) + "utm zone '" + spec.utm_zone +
                         "' is not a UTM zone like 33N (" + e.what() + ")");
      }
      if (impl_->zone == GeographicLib::UTMUPS::UPS)
        throw InputError(FramePrefix(spec) + "utm zone '" + spec.utm_zone +
                         "' is a polar (UPS) zone");
      break;
    case FrameSpec::Kind::kProjected:
      break;
    case FrameSpec::Kind::kCrs: {
      const std::string where = FramePrefix(spec);
      impl_->main = std::make_shared<CrsConverter>(
          CrsOptions{spec.crs, spec.vertical, spec.geoid_grid, where + "crs"});
      const auto other = [&](const std::string& crs, const char* key) {
        if (crs.empty()) return impl_->main;
        return std::make_shared<CrsConverter>(CrsOptions{crs, "", "", where + key},
                                              impl_->main->PivotDefinition());
      };
      impl_->points = other(spec.points_crs, "points_crs");
      impl_->exposures = other(spec.exposures_crs, "exposures_crs");
      if (spec.has_origin) impl_->SetOrigin(spec.lat_deg, spec.lon_deg, spec.h_m);
      break;
    }
  }
}

ObjectFrame::~ObjectFrame() = default;
ObjectFrame::ObjectFrame(ObjectFrame&&) noexcept = default;
ObjectFrame& ObjectFrame::operator=(ObjectFrame&&) noexcept = default;

bool ObjectFrame::geodetic_input() const {
  return impl_->spec.kind != FrameSpec::Kind::kProjected &&
         impl_->spec.kind != FrameSpec::Kind::kCrs;
}

bool ObjectFrame::crs_input() const { return impl_->spec.kind == FrameSpec::Kind::kCrs; }

void ObjectFrame::FixOrigin(const Project& project) const {
  if (!crs_input() || impl_->local) return;
  // The mean of the surveyed points (else of the exposure centres) in geographic 3D coordinates.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const auto& p : project.points)
    if (p.xyz_m && p.role != PointRole::kTie) {
      const Eigen::Vector3d g = impl_->points->ToPivot(*p.xyz_m);
      if (!g.allFinite())
        ThrowInputError({project.points_file, p.line},
                        "cannot be converted from " + impl_->points->Name() +
                            " (coordinates in the CRS's normalised axis order, easting / "
                            "longitude first?)");
      sum += g;
      ++n;
    }
  if (n == 0)
    for (const auto& e : project.exposures) {
      const Eigen::Vector3d g = impl_->exposures->ToPivot(e.center_m);
      if (!g.allFinite())
        ThrowInputError({project.exposures_file, e.line},
                        "cannot be converted from " + impl_->exposures->Name());
      sum += g;
      ++n;
    }
  if (n == 0)
    throw InputError(FramePrefix(impl_->spec) + "crs: needs surveyed points or exposures");
  const Eigen::Vector3d c = sum / n;
  impl_->SetOrigin(c.y(), c.x(), c.z());
}

Eigen::Vector3d ObjectFrame::Origin() const {
  return {impl_->spec.lon_deg, impl_->spec.lat_deg, impl_->spec.h_m};
}

double ObjectFrame::GeoidUndulationAtOrigin() const { return impl_->undulation_m; }

Eigen::Matrix3d ObjectFrame::MetricJacobian(const Eigen::Vector3d& in, File file) const {
  if (!crs_input()) return Eigen::Matrix3d::Identity();
  const CrsConverter& crs = impl_->Of(file);
  Eigen::Matrix3d j;
  if (crs.axes() == CrsConverter::Axes::kGeographic) {
    // East, north, up at the point: displacements in its own tangent plane (GeographicLib).
    const Eigen::Vector3d g = crs.ToPivot(in);
    const GeographicLib::Geocentric earth(crs.semi_major_m(), crs.flattening());
    const GeographicLib::LocalCartesian tangent(g.y(), g.x(), g.z(), earth);
    for (int i = 0; i < 3; ++i) {
      const auto moved = [&](double d) {
        Eigen::Vector3d enu = Eigen::Vector3d::Zero();
        enu(i) = d;
        double lat = 0, lon = 0, h = 0;
        tangent.Reverse(enu.x(), enu.y(), enu.z(), lat, lon, h);
        Eigen::Vector3d out;
        impl_->local->Forward(lat, lon, h, out.x(), out.y(), out.z());
        return out;
      };
      j.col(i) = 0.5 * (moved(1.0) - moved(-1.0));
    }
  } else {
    // Grid or geocentric metres: central differences of 1 m (error ~ 1 m / Earth radius).
    for (int i = 0; i < 3; ++i) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(i) = 1.0;
      j.col(i) = 0.5 * (ToAdjustment(in + d, file) - ToAdjustment(in - d, file));
    }
  }
  return j;
}

Eigen::Vector3d ObjectFrame::ToAdjustment(const Eigen::Vector3d& in, File file) const {
  Eigen::Vector3d out = in;
  if (crs_input()) {
    AEROCAL_CHECK(impl_->local) << "crs frame without origin (FixOrigin not called)";
    const Eigen::Vector3d g = impl_->Of(file).ToPivot(in);
    if (!g.allFinite()) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
    impl_->local->Forward(g.y(), g.x(), g.z(), out.x(), out.y(), out.z());
  } else if (impl_->local) {
    impl_->local->Forward(in.y(), in.x(), in.z(), out.x(), out.y(), out.z());
  } else if (impl_->zone > 0) {
    int zone = 0;
    bool north = true;
    GeographicLib::UTMUPS::Forward(in.y(), in.x(), zone, north, out.x(), out.y(), impl_->zone);
    if (north != impl_->north)  // a point across the equator: keep one false northing
      out.y() +=
          impl_->north ? -GeographicLib::UTMUPS::UTMShift() : GeographicLib::UTMUPS::UTMShift();
    out.z() = in.z();
  }
  return out;
}

Eigen::Vector3d ObjectFrame::ToInput(const Eigen::Vector3d& a, File file) const {
  Eigen::Vector3d out = a;
  if (crs_input()) {
    AEROCAL_CHECK(impl_->local) << "crs frame without origin (FixOrigin not called)";
    double lat = 0, lon = 0, h = 0;
    impl_->local->Reverse(a.x(), a.y(), a.z(), lat, lon, h);
    out = impl_->Of(file).FromPivot({lon, lat, h});
  } else if (impl_->local) {
    double lat = 0, lon = 0, h = 0;
    impl_->local->Reverse(a.x(), a.y(), a.z(), lat, lon, h);
    out = {lon, lat, h};
  } else if (impl_->zone > 0) {
    double lat = 0, lon = 0;
    try {
      GeographicLib::UTMUPS::Reverse(impl_->zone, impl_->north, a.x(), a.y(), lat, lon);
    } catch (const GeographicLib::GeographicErr&) {
      // An adjusted point far outside the zone (a diverged solution): no geodetic value.
      lat = lon = std::numeric_limits<double>::quiet_NaN();
    }
    out = {lon, lat, a.z()};
  }
  return out;
}

std::string ObjectFrame::Description() const {
  const FrameSpec& s = impl_->spec;
  char text[1024];
  if (crs_input()) {
    const auto file_text = [&](const char* what, const CrsConverter& c) {
      const char* axes =
          c.axes() == CrsConverter::Axes::kGeographic  ? "X = longitude, Y = latitude (deg)"
          : c.axes() == CrsConverter::Axes::kProjected ? "X = easting, Y = northing (m)"
                                                       : "X, Y, Z geocentric (m)";
      return std::string(what) + " in " + c.Name() + " (" + c.Definition() + "; " + axes +
             (c.axes() == CrsConverter::Axes::kGeocentric ? std::string()
              : c.orthometric()                           ? ", Z = orthometric height (m)"
                                                          : ", Z = ellipsoidal height (m)") +
             "; PROJ: " + c.OperationDescription() + ")";
    };
    std::string out =
        "local tangent plane (east, north, up; GeographicLib LocalCartesian on the "
        "ellipsoid of " +
        impl_->main->Name() + ")";
    std::snprintf(text,
                  sizeof(text),
                  " about lat %.9f, lon %.9f, h %.3f m (ellipsoidal)",
                  s.lat_deg,
                  s.lon_deg,
                  s.h_m);
    out += text;
    if (impl_->points->orthometric()) {
      std::snprintf(
          text, sizeof(text), "; geoid undulation at the origin N = %.3f m", impl_->undulation_m);
      out += text;
    }
    out += "; " + file_text("points", *impl_->points);
    out += "; " + file_text("exposure centres", *impl_->exposures) +
           ", attitudes relative to that CRS's axes at the exposure";
    out +=
        "; results written back in each file's CRS; differences, RMSE and sigmas in metres of "
        "the tangent plane";
    return out;
  }
  if (impl_->local) {
    std::snprintf(
        text,
        sizeof(text),
        "local tangent plane (east, north, up; WGS84, GeographicLib LocalCartesian) about "
        "lat %.9f, lon %.9f, h %.3f m; input geodetic (X = lon, Y = lat deg, Z = "
        "ellipsoidal height m), results written back geodetic, differences in metres",
        s.lat_deg,
        s.lon_deg,
        s.h_m);
  } else if (impl_->zone > 0) {
    std::snprintf(text,
                  sizeof(text),
                  "UTM zone %d%s (WGS84, GeographicLib UTMUPS; ellipsoidal heights, map-projection "
                  "scale and Earth curvature not modelled); input geodetic (X = lon, Y = lat deg, "
                  "Z = ellipsoidal height m), results written back geodetic, differences in metres",
                  impl_->zone,
                  impl_->north ? "N" : "S");
  } else {
    std::snprintf(text, sizeof(text), "projected frame as given (%s)", s.description.c_str());
  }
  return text;
}

namespace {

// The rotation nearest J (polar decomposition).
Eigen::Matrix3d NearestRotation(const Eigen::Matrix3d& j) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(j, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0) r = -r;  // a left-handed file CRS; does not occur with PROJ's order
  return r;
}

// Standard deviations along the file's axes -> along the adjustment axes: the diagonal of
// J diag(s^2) J^T.
Eigen::Vector3d PropagatedSigma(const Eigen::Matrix3d& j, const Eigen::Vector3d& sigma) {
  const Eigen::Matrix3d cov = j * sigma.cwiseAbs2().asDiagonal() * j.transpose();
  return cov.diagonal().cwiseSqrt();
}

Project CrsToAdjustmentFrame(const Project& project, const ObjectFrame& frame) {
  using File = ObjectFrame::File;
  frame.FixOrigin(project);
  Project out = project;
  const auto convert = [&](const Eigen::Vector3d& xyz, File file, const SourceRef& where) {
    const Eigen::Vector3d a = frame.ToAdjustment(xyz, file);
    if (!a.allFinite())
      ThrowInputError(where,
                      "cannot be converted from the file's CRS (" + frame.Description() +
                          "): outside the CRS's area, or not in its axis order (easting / "
                          "longitude first)?");
    return a;
  };
  for (auto& p : out.points) {
    if (!p.xyz_m) continue;
    const Eigen::Matrix3d j = frame.MetricJacobian(*p.xyz_m, File::kPoints);
    p.sigma_m = PropagatedSigma(j, p.sigma_m);
    p.xyz_m = convert(*p.xyz_m, File::kPoints, {project.points_file, p.line});
  }
  for (auto& e : out.exposures) {
    const Eigen::Matrix3d j = frame.MetricJacobian(e.center_m, File::kExposures);
    if (e.velocity_mps) e.velocity_mps = j * *e.velocity_mps;
    if (e.center_sigma_m) e.center_sigma_m = PropagatedSigma(j, *e.center_sigma_m);
    e.opk_rad = calib::OpkFromRotation(NearestRotation(j) * calib::RotationFromOpk(e.opk_rad));
    if (e.z_ref_m)
      e.z_ref_m = convert({e.center_m.x(), e.center_m.y(), *e.z_ref_m},
                          File::kExposures,
                          {project.exposures_file, e.line})
                      .z();
    e.center_m = convert(e.center_m, File::kExposures, {project.exposures_file, e.line});
  }
  out.frame.description = frame.Description();
  return out;
}

}  // namespace

Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame) {
  if (frame.crs_input()) return CrsToAdjustmentFrame(project, frame);
  Project out = project;
  if (!frame.geodetic_input()) return out;
  const FrameSpec& spec = frame.impl_->spec;
  // Geodetic input: X = longitude, Y = latitude (deg), Z = height (m). Metre coordinates under a
  // geodetic frame are an input error at their line, never a NaN or a GeographicLib exception.
  const auto convert = [&](const Eigen::Vector3d& xyz, const SourceRef& where) {
    const std::string frame_text =
        "the frame (" + (spec.source.empty() ? std::string("frame:") : spec.source) +
        ") takes geodetic X = longitude, Y = latitude (deg), Z = height (m); metre coordinates "
        "need frame: {projected: ...}";
    if (!(std::abs(xyz.y()) <= 90.0 && std::abs(xyz.x()) <= 540.0 && std::abs(xyz.z()) <= 1e5))
      ThrowInputError(where,
                      "not a longitude/latitude/height (got " + std::to_string(xyz.x()) + ", " +
                          std::to_string(xyz.y()) + ", " + std::to_string(xyz.z()) +
                          "): " + frame_text);
    try {
      const Eigen::Vector3d a = frame.ToAdjustment(xyz);
      if (!a.allFinite()) ThrowInputError(where, "cannot be converted: " + frame_text);
      return a;
    } catch (const GeographicLib::GeographicErr& e) {
      ThrowInputError(where,
                      std::string("cannot be converted to the frame (") +
                          (spec.source.empty() ? "frame:" : spec.source) + "): " + e.what());
    }
  };
  for (auto& p : out.points)
    if (p.xyz_m) p.xyz_m = convert(*p.xyz_m, {project.points_file, p.line});
  for (auto& e : out.exposures) {
    if (e.velocity_mps) e.velocity_mps = VelocityToAdjustment(frame, e.center_m, *e.velocity_mps);
    e.center_m = convert(e.center_m, {project.exposures_file, e.line});
  }
  out.frame.description = frame.Description();
  return out;
}

Project FromAdjustmentFrame(const Project& project, const ObjectFrame& frame) {
  using File = ObjectFrame::File;
  AEROCAL_CHECK(frame.crs_input() && frame.impl_->local) << "FromAdjustmentFrame needs a crs: "
                                                            "frame with its origin fixed";
  Project out = project;
  out.frame = frame.impl_->spec;
  const auto convert = [&](const Eigen::Vector3d& a, File file, const SourceRef& where) {
    const Eigen::Vector3d x = frame.ToInput(a, file);
    if (!x.allFinite()) ThrowInputError(where, "cannot be converted to the file's CRS");
    return x;
  };
  for (auto& p : out.points) {
    if (!p.xyz_m) continue;
    p.xyz_m = convert(*p.xyz_m, File::kPoints, {project.points_file, p.line});
    p.sigma_m = PropagatedSigma(frame.MetricJacobian(*p.xyz_m, File::kPoints).inverse(), p.sigma_m);
  }
  for (auto& e : out.exposures) {
    if (e.z_ref_m)
      e.z_ref_m = frame.ToInput({e.center_m.x(), e.center_m.y(), *e.z_ref_m}, File::kExposures).z();
    e.center_m = convert(e.center_m, File::kExposures, {project.exposures_file, e.line});
    const Eigen::Matrix3d j = frame.MetricJacobian(e.center_m, File::kExposures);
    const Eigen::Matrix3d j_inv = j.inverse();
    if (e.velocity_mps) e.velocity_mps = j_inv * *e.velocity_mps;
    if (e.center_sigma_m) e.center_sigma_m = PropagatedSigma(j_inv, *e.center_sigma_m);
    e.opk_rad =
        calib::OpkFromRotation(NearestRotation(j).transpose() * calib::RotationFromOpk(e.opk_rad));
  }
  return out;
}

void ToInputFrame(const ObjectFrame& frame, AdjustmentResult* result) {
  result->frame = frame.Description();
  if (frame.crs_input()) {
    using File = ObjectFrame::File;
    for (auto& [id, xyz] : result->points_m) xyz = frame.ToInput(xyz);
    for (auto* table : {&result->control_points, &result->check_points})
      for (auto& p : *table) {
        p.surveyed_m = frame.ToInput(p.surveyed_m);
        p.adjusted_m = frame.ToInput(p.adjusted_m);
      }
    for (auto& e : result->exposures) {
      e.center_m = frame.ToInput(e.center_m, File::kExposures);
      if (!e.center_m.allFinite()) continue;
      const Eigen::Matrix3d q = NearestRotation(frame.MetricJacobian(e.center_m, File::kExposures));
      e.opk_rad = calib::OpkFromRotation(q.transpose() * calib::RotationFromOpk(e.opk_rad));
    }
    return;
  }
  if (!frame.geodetic_input()) return;
  for (auto& [id, xyz] : result->points_m) xyz = frame.ToInput(xyz);
  for (auto* table : {&result->control_points, &result->check_points})
    for (auto& p : *table) {
      p.surveyed_m = frame.ToInput(p.surveyed_m);
      p.adjusted_m = frame.ToInput(p.adjusted_m);
    }
  for (auto& e : result->exposures) e.center_m = frame.ToInput(e.center_m);
}

}  // namespace aerocal::triangulation
