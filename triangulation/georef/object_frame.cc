#include "triangulation/georef/object_frame.h"

#include "calib/core/error.h"

#include <GeographicLib/Constants.hpp>
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
Eigen::Vector3d VelocityToAdjustment(const ObjectFrame& frame, const Eigen::Vector3d& geodetic,
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
        throw InputError(FramePrefix(spec) + "utm zone '" + spec.utm_zone + "' is a polar (UPS) zone");
      break;
    case FrameSpec::Kind::kProjected:
      break;
  }
}

ObjectFrame::~ObjectFrame() = default;
ObjectFrame::ObjectFrame(ObjectFrame&&) noexcept = default;
ObjectFrame& ObjectFrame::operator=(ObjectFrame&&) noexcept = default;

bool ObjectFrame::geodetic_input() const { return impl_->spec.kind != FrameSpec::Kind::kProjected; }

Eigen::Vector3d ObjectFrame::ToAdjustment(const Eigen::Vector3d& in) const {
  Eigen::Vector3d out = in;
  if (impl_->local) {
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

Eigen::Vector3d ObjectFrame::ToInput(const Eigen::Vector3d& a) const {
  Eigen::Vector3d out = a;
  if (impl_->local) {
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
  char text[512];
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

Project ToAdjustmentFrame(const Project& project, const ObjectFrame& frame) {
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
      ThrowInputError(where, "not a longitude/latitude/height (got " + std::to_string(xyz.x()) +
                                 ", " + std::to_string(xyz.y()) + ", " + std::to_string(xyz.z()) +
                                 "): " + frame_text);
    try {
      const Eigen::Vector3d a = frame.ToAdjustment(xyz);
      if (!a.allFinite()) ThrowInputError(where, "cannot be converted: " + frame_text);
      return a;
    } catch (const GeographicLib::GeographicErr& e) {
      ThrowInputError(where, std::string("cannot be converted to the frame (") +
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

void ToInputFrame(const ObjectFrame& frame, AdjustmentResult* result) {
  result->frame = frame.Description();
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
