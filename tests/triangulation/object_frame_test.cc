// Geodetic input converted with GeographicLib (local tangent plane, UTM) and written back.
#include "triangulation/georef/object_frame.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block_io.h"
#include "triangulation/import/write_project.h"
#include "triangulation/simulation/flight_simulator.h"

#include <GeographicLib/UTMUPS.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <regex>

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

// The default simulated flight as a projected block, and the same block in geodetic coordinates
// (the simulated frame taken as the tangent plane of LocalFrame()).
struct ProjectedAndGeodetic {
  Project projected, geodetic;
};
ProjectedAndGeodetic SimulatedBlocks() {
  ProjectedAndGeodetic out;
  out.projected = testing::ProjectFromFlight(SimulateFlight(FlightSimulationOptions{}));
  const ObjectFrame frame(LocalFrame());
  out.geodetic = out.projected;
  out.geodetic.frame = LocalFrame();
  for (auto& p : out.geodetic.points)
    if (p.xyz_m) p.xyz_m = frame.ToInput(*p.xyz_m);
  for (auto& e : out.geodetic.exposures) e.center_m = frame.ToInput(e.center_m);
  return out;
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

// A velocity of geodetic input is east, north, up (m/s) at the exposure (object_frame.h).
Eigen::Vector3d VelocityInFrame(const FrameSpec& spec,
                                const Eigen::Vector3d& lon_lat_h,
                                const Eigen::Vector3d& enu_mps) {
  Project project;
  Exposure e;
  e.center_m = lon_lat_h;
  e.velocity_mps = enu_mps;
  project.exposures.push_back(e);
  return *ToAdjustmentFrame(project, ObjectFrame(spec)).exposures.front().velocity_mps;
}

TEST(ObjectFrame, VelocitiesTurnWithTheFrame) {
  const Eigen::Vector3d v(30.0, 55.0, -2.0);
  // At the origin of the local frame east, north, up are its axes.
  const FrameSpec local = LocalFrame();
  const Eigen::Vector3d at_origin(local.lon_deg, local.lat_deg, local.h_m);
  EXPECT_LT((VelocityInFrame(local, at_origin, v) - v).norm(), 1e-6);
  // 0.2 deg of longitude east of the origin the local north turns by d_lon sin(lat) about up
  // (meridian convergence on the tangent plane, to first order): 0.2 deg * 0.7355 = 0.147 deg.
  const double lat = local.lat_deg * M_PI / 180.0, dlon = 0.2 * M_PI / 180.0;
  const double turn = dlon * std::sin(lat);
  const Eigen::Vector3d east_of(local.lon_deg + 0.2, local.lat_deg, local.h_m);
  const Eigen::Vector3d turned = VelocityInFrame(local, east_of, v);
  const Eigen::Vector3d expected(v.x() * std::cos(turn) - v.y() * std::sin(turn),
                                 v.x() * std::sin(turn) + v.y() * std::cos(turn),
                                 v.z());
  EXPECT_LT((turned.head<2>() - expected.head<2>()).norm(), 1e-3 * v.norm());
  // The exposure's east axis dips below the origin's plane by d_lon cos(lat) = 2.36 mrad.
  EXPECT_NEAR(turned.z(), v.z() - v.x() * dlon * std::cos(lat), 1e-3);
  // UTM: grid = k R/(R+h) Rz(gamma) (east, north) with the point scale k and the meridian
  // convergence gamma of GeographicLib (grid north is gamma clockwise from true north), R/(R+h)
  // because the grid is the ellipsoid's (centres are converted so: h = 500 m gives 7.8e-5, R
  // taken as the mean radius, 4e-7 relative off M or N); up unchanged.
  FrameSpec utm;
  utm.kind = FrameSpec::Kind::kUtm;
  utm.utm_zone = "32N";
  const double lon = 11.2, latd = 47.4;  // 2.2 deg east of the zone's central meridian
  int zone = 0;
  bool north = true;
  double x = 0, y = 0, gamma_deg = 0, k = 0;
  GeographicLib::UTMUPS::Forward(latd, lon, zone, north, x, y, gamma_deg, k, 32);
  const double g = gamma_deg * M_PI / 180.0;
  const Eigen::Vector3d grid = VelocityInFrame(utm, {lon, latd, 500.0}, v);
  const double scale = k * 6371e3 / (6371e3 + 500.0);
  EXPECT_NEAR(grid.x(), scale * (v.x() * std::cos(g) - v.y() * std::sin(g)), 1e-4);
  EXPECT_NEAR(grid.y(), scale * (v.x() * std::sin(g) + v.y() * std::cos(g)), 1e-4);
  EXPECT_NEAR(grid.z(), v.z(), 1e-6);
  EXPECT_GT(std::abs(g), 0.02);  // the test would not see a missing rotation otherwise
}

TEST(ObjectFrame, BadZoneIsAnInputError) {
  FrameSpec spec;
  spec.kind = FrameSpec::Kind::kUtm;
  spec.utm_zone = "99Q";
  EXPECT_THROW(ObjectFrame{spec}, InputError);
}

TEST(ObjectFrame, GeodeticAndProjectedInputGiveTheSameCheckRmse) {
  const auto [projected, geodetic] = SimulatedBlocks();
  const ObjectFrame frame(LocalFrame());
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

TEST(ObjectFrame, GeodeticFrameWithoutOriginAdjustsAboutTheBlockCentre) {
  // The simulated block as project folders: once projected, once geodetic with `frame:
  // {geodetic: WGS84}` (no origin given). Both through `aerocal adjust`: same check RMSE.
  const auto [projected, geodetic] = SimulatedBlocks();
  testing::TempDir dir("aerocal_geodetic");
  WriteProjectFolder(projected, dir.File("projected"));
  WriteProjectFolder(geodetic, dir.File("geodetic"));
  const std::string yaml = ReadTextFile(dir.File("geodetic/project.yaml"));
  WriteFileAtomically(
      dir.File("geodetic/project.yaml"),
      std::regex_replace(yaml, std::regex("frame: .*"), "frame: {geodetic: WGS84}"));

  const Project read = ReadProject(dir.File("geodetic/project.yaml"));
  ASSERT_EQ(read.frame.kind, FrameSpec::Kind::kGeodeticToLocal);
  EXPECT_NEAR(read.frame.lat_deg, 47.3769, 0.1);  // the block lies within a few km of LocalFrame()
  EXPECT_NEAR(read.frame.lon_deg, 8.5417, 0.1);

  std::vector<nlohmann::json> results;
  for (const char* name : {"projected", "geodetic"}) {
    const auto run = testing::RunAerocal(
        "adjust --project " + dir.File(std::string(name) + "/project.yaml") +
        " --self-calibration all --out " + dir.File(std::string(name) + ".json"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    results.push_back(aerocal::testing::ReadJson(dir.File(std::string(name) + ".json")));
  }
  for (const auto& r : results)
    std::printf("sigma0 %.4f, iterations %d, rejected %zu, converged %d, frame %s\n",
                r["sigma0"].get<double>(),
                r["iterations"].get<int>(),
                r["rejected"].size(),
                r["converged"].get<bool>(),
                r["frame"].get<std::string>().c_str());
  const auto& a = results[0]["check"];
  const auto& b = results[1]["check"];
  ASSERT_EQ(a["n"], b["n"]);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(a["rmse_m"][k].get<double>(), b["rmse_m"][k].get<double>(), 1e-3) << "axis " << k;
  EXPECT_NE(results[1]["frame"].get<std::string>().find("local tangent plane"), std::string::npos);
}

}  // namespace
}  // namespace aerocal::triangulation
