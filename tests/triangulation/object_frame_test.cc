// Geodetic input converted with GeographicLib (local tangent plane, UTM) and written back.
#include "triangulation/georef/object_frame.h"

#include "calib/core/error.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::triangulation {
namespace {

FrameSpec LocalFrame() {
  FrameSpec spec;
  spec.kind = FrameSpec::Kind::kLocal;
  spec.lat_deg = 47.3769;
  spec.lon_deg = 8.5417;
  spec.h_m = 400.0;
  return spec;
}

TEST(ObjectFrame, GeodeticRoundTripsThroughLocalTangentPlaneAndUtm) {
  FrameSpec utm;
  utm.kind = FrameSpec::Kind::kUtm;
  utm.utm_zone = "32N";
  for (const FrameSpec& spec : {LocalFrame(), utm}) {
    const ObjectFrame frame(spec);
    ASSERT_TRUE(frame.geodetic_input());
    const Eigen::Vector3d geodetic(8.61, 47.41, 812.5);  // lon, lat, h
    const Eigen::Vector3d back = frame.ToInput(frame.ToAdjustment(geodetic));
    EXPECT_NEAR(back.x(), geodetic.x(), 1e-10);  // deg: ~1e-5 m
    EXPECT_NEAR(back.y(), geodetic.y(), 1e-10);
    EXPECT_NEAR(back.z(), geodetic.z(), 1e-6);
  }
  // The origin of the tangent plane is (0, 0, 0); up is the ellipsoid normal.
  const ObjectFrame local(LocalFrame());
  EXPECT_LT(local.ToAdjustment({8.5417, 47.3769, 400.0}).norm(), 1e-6);
  EXPECT_NEAR(local.ToAdjustment({8.5417, 47.3769, 500.0}).z(), 100.0, 1e-6);
  // 32N: Zurich is near easting 465 km, northing 5247 km.
  const Eigen::Vector3d en = ObjectFrame(utm).ToAdjustment({8.5417, 47.3769, 400.0});
  EXPECT_NEAR(en.x(), 465e3, 2e3);
  EXPECT_NEAR(en.y(), 5247e3, 2e3);
}

TEST(ObjectFrame, BadZoneIsAnInputError) {
  FrameSpec spec;
  spec.kind = FrameSpec::Kind::kUtm;
  spec.utm_zone = "99Q";
  EXPECT_THROW(ObjectFrame{spec}, InputError);
}

TEST(ObjectFrame, GeodeticAndProjectedInputGiveTheSameCheckRmse) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  Project projected;
  projected.cameras["cam1"] = flight.nominal;
  projected.exposures = flight.exposures_file;
  projected.observations = flight.observations;
  projected.points = flight.points_file;
  // The same block as geodetic coordinates: the simulated frame is taken as the tangent plane.
  const ObjectFrame frame(LocalFrame());
  Project geodetic = projected;
  geodetic.frame = LocalFrame();
  for (auto& p : geodetic.points)
    if (p.xyz_m) p.xyz_m = frame.ToInput(*p.xyz_m);
  for (auto& e : geodetic.exposures) e.center_m = frame.ToInput(e.center_m);
  ASSERT_GT(std::abs(geodetic.points.front().xyz_m->y() - 47.3), 0.0);

  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("all");
  const AdjustmentResult a = Adjust(projected, options);
  AdjustmentResult b = Adjust(ToAdjustmentFrame(geodetic, frame), options);
  ToInputFrame(frame, &b);
  ASSERT_TRUE(a.converged() && b.converged());
  ASSERT_EQ(a.check.n, b.check.n);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.check.rmse_m(k), b.check.rmse_m(k), 1e-3);
  EXPECT_NEAR(a.check.spatial_rmse_m, b.check.spatial_rmse_m, 1e-3);
  // Results are written back geodetic and the frame is stated.
  const auto& p = b.check_points.front();
  EXPECT_NEAR(p.adjusted_m.y(), 47.4, 0.3);  // latitude, deg
  EXPECT_NE(b.frame.find("local tangent plane"), std::string::npos);
  EXPECT_NEAR(b.exposures.front().center_m.x(), 8.5, 0.3);  // longitude, deg
}

}  // namespace
}  // namespace aerocal::triangulation
