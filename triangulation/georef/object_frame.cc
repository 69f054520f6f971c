#include "triangulation/georef/object_frame.h"

#include "calib/core/error.h"

#include <GeographicLib/LocalCartesian.hpp>
#include <GeographicLib/UTMUPS.hpp>

#include <cmath>
#include <cstdio>

namespace aerocal::triangulation {

struct ObjectFrame::Impl {
  FrameSpec spec;
  std::unique_ptr<GeographicLib::LocalCartesian> local;
  int zone = 0;
  bool north = true;
};

ObjectFrame::ObjectFrame(const FrameSpec& spec) : impl_(std::make_unique<Impl>()) {
  impl_->spec = spec;
  switch (spec.kind) {
    case FrameSpec::Kind::kLocal:
    case FrameSpec::Kind::kGeodeticToLocal:
      if (!(std::abs(spec.lat_deg) <= 90.0) || !(spec.lon_deg >= -180.0 && spec.lon_deg <= 360.0))
        throw InputError("frame: local origin lat/lon out of range (got " +
                         std::to_string(spec.lat_deg) + ", " + std::to_string(spec.lon_deg) + ")");
      impl_->local =
          std::make_unique<GeographicLib::LocalCartesian>(spec.lat_deg, spec.lon_deg, spec.h_m);
      break;
    case FrameSpec::Kind::kUtm:
      try {
        GeographicLib::UTMUPS::DecodeZone(spec.utm_zone, impl_->zone, impl_->north);
      } catch (const std::exception& e) {
        throw InputError("frame: utm zone '" + spec.utm_zone + "' is not a UTM zone like 33N (" +
                         e.what() + ")");
      }
      if (impl_->zone == GeographicLib::UTMUPS::UPS)
        throw InputError("frame: utm zone '" + spec.utm_zone + "' is a polar (UPS) zone");
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
    GeographicLib::UTMUPS::Reverse(impl_->zone, impl_->north, a.x(), a.y(), lat, lon);
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
  for (auto& p : out.points)
    if (p.xyz_m) p.xyz_m = frame.ToAdjustment(*p.xyz_m);
  for (auto& e : out.exposures) e.center_m = frame.ToAdjustment(e.center_m);
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
