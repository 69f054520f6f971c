// Forward intersection of image rays and the adjustment options.
#include "triangulation/adjustment/forward_intersection.h"

#include "calib/core/error.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

namespace aerocal::triangulation {
namespace {

TEST(ForwardIntersection, ExactRaysOfTheTrueCameraMeetAtTheGroundPoint) {
  const SimulatedFlight flight = SimulateFlight(FlightSimulationOptions{});
  int checked = 0;
  for (const auto& p : flight.points_truth) {
    std::vector<ImageRay> rays;
    for (const auto& e : flight.exposures_truth) {
      Eigen::Vector2d pixel;
      if (!flight.truth.ProjectToPixel(e.opk_rad, e.center_m, *p.xyz_m, &pixel)) continue;
      if (pixel.x() < 0 || pixel.y() < 0 || pixel.x() > flight.truth.width_px - 1 ||
          pixel.y() > flight.truth.height_px - 1)
        continue;
      rays.push_back(RayFromPixel(flight.truth, e.opk_rad, e.center_m, pixel));
    }
    if (rays.size() < 2) continue;
    const auto x = IntersectRays(rays);
    ASSERT_TRUE(x.has_value()) << p.id;
    // Noise-free rays: the projection round trip is exact to 1e-6 px (~3e-7 m on the ground).
    EXPECT_LT((*x - *p.xyz_m).norm(), 1e-4) << p.id;
    if (++checked == 50) break;
  }
  EXPECT_EQ(checked, 50);
}

TEST(ForwardIntersection, RejectsParallelRaysAndFallsBackToAHeight) {
  const ImageRay a{{0, 0, 1000}, {0, 0, -1}}, b{{1e-3, 0, 1000}, {0, 0, -1}};
  EXPECT_FALSE(IntersectRays({a, b}).has_value());
  EXPECT_FALSE(IntersectRays({a}).has_value());
  const Eigen::Vector3d x = IntersectWithHeight({a, b}, 100.0);
  EXPECT_NEAR(x.z(), 100.0, 1e-12);
  EXPECT_NEAR(x.x(), 0.5e-3, 1e-12);
}

TEST(AdjustOptions, SelfCalibrationListsAreCheckedAgainstTheParameterTable) {
  EXPECT_TRUE(ParseSelfCalibration("none").empty());
  EXPECT_EQ(ParseSelfCalibration("all").size(), 10u);
  EXPECT_EQ(ParseSelfCalibration("c, x0,y0").size(), 3u);
  EXPECT_THROW(ParseSelfCalibration("c,k1"), ConfigError);
  EXPECT_THROW(ParseSelfCalibration("c,c"), ConfigError);
  AdjustOptions o;
  o.correlation_threshold = 1.5;
  EXPECT_THROW(o.Validate(), ConfigError);
  o = AdjustOptions{};
  o.max_rejections = -1;
  EXPECT_THROW(o.Validate(), ConfigError);
  o.max_rejections = 0;  // the automatic cap
  EXPECT_NO_THROW(o.Validate());
}

}  // namespace
}  // namespace aerocal::triangulation
