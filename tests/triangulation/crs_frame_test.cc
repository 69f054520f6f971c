// `frame: {crs: ...}` through PROJ (triangulation/georef/crs.h, object_frame.h): axis order,
// compound CRSs with a geoid, missing grids, and the acceptance test of issue 34: the real ODM
// UAV block given in its UTM zone, in WGS84 geodetic, in ECEF and in a national projection with
// orthometric heights gives the same check-point RMSE and camera.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "tests/support/odm_uav_block.h"
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/georef/crs.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/import/colmap_export.h"
#include "triangulation/import/write_project.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <sstream>
#include <tuple>

namespace aerocal::triangulation {
namespace {

// A target of the ODM block (EPSG:32722, WGS 84 / UTM 22S, ellipsoidal height).
const Eigen::Vector3d kUtm22s(658586.0, 7167009.0, 890.0);

CrsConverter Crs(const std::string& definition, const std::string& pivot = "") {
  return CrsConverter(CrsOptions{definition, "", "", "test"}, pivot);
}

TEST(Crs, AxisOrderIsEastingOrLongitudeFirst) {
  const CrsConverter utm = Crs("EPSG:32722");
  EXPECT_EQ(utm.axes(), CrsConverter::Axes::kProjected);
  EXPECT_FALSE(utm.orthometric());
  const Eigen::Vector3d g = utm.ToPivot(kUtm22s);
  // Zone 22S: central meridian 51 W; the block is near 49.42 W, 25.61 S.
  EXPECT_NEAR(g.x(), -49.42, 0.01);
  EXPECT_NEAR(g.y(), -25.61, 0.01);
  EXPECT_NEAR(g.z(), kUtm22s.z(), 1e-9);  // a 2D CRS: the height passes as ellipsoidal
  const Eigen::Vector3d back = utm.FromPivot(g);
  EXPECT_LT((back - kUtm22s).norm(), 1e-6);
  // EPSG:4326 declares latitude first; files hold longitude first.
  const CrsConverter geographic = Crs("EPSG:4326", utm.PivotDefinition());
  EXPECT_EQ(geographic.axes(), CrsConverter::Axes::kGeographic);
  EXPECT_LT((geographic.ToPivot(g) - g).norm(), 1e-12);
  const CrsConverter ecef = Crs("EPSG:4978", utm.PivotDefinition());
  EXPECT_EQ(ecef.axes(), CrsConverter::Axes::kGeocentric);
  const Eigen::Vector3d xyz = ecef.FromPivot(g);
  EXPECT_NEAR(xyz.norm(), 6.375e6, 2e4);
  EXPECT_LT((ecef.ToPivot(xyz) - g).cwiseProduct(Eigen::Vector3d(1e5, 1e5, 1)).norm(), 1e-4);
}

TEST(Crs, ProjStringsAndWktAreCrsDefinitions) {
  const CrsConverter utm = Crs("EPSG:32722");
  // The ODM list's projection line (no +type=crs) and the WKT of the pivot.
  const CrsConverter proj_string = Crs("+proj=utm +zone=22 +south +datum=WGS84 +units=m +no_defs");
  EXPECT_LT((proj_string.ToPivot(kUtm22s) - utm.ToPivot(kUtm22s)).norm(), 1e-9);
  const CrsConverter wkt = Crs(utm.PivotDefinition());
  EXPECT_EQ(wkt.axes(), CrsConverter::Axes::kGeographic);
  const Eigen::Vector3d g = utm.ToPivot(kUtm22s);
  EXPECT_LT((wkt.ToPivot(g) - g).norm(), 1e-12);
}

TEST(Crs, CompoundWithInstalledGeoidAndSeparateVertical) {
  // EGM96 (egm96_15.gtx ships with Debian's proj-data, PROJ names it us_nga_egm96_15.tif):
  // N is about +4 m at the block.
  const CrsConverter compound = Crs("EPSG:32722+5773");
  ASSERT_TRUE(compound.orthometric());
  const Eigen::Vector3d g = compound.ToPivot({kUtm22s.x(), kUtm22s.y(), 0.0});
  std::printf("EGM96 undulation at the ODM block: %.3f m (%s)\n",
              g.z(),
              compound.OperationDescription().c_str());
  EXPECT_NEAR(g.z(), 4.0, 1.0);
  EXPECT_NE(compound.OperationDescription().find("egm96"), std::string::npos);
  const CrsConverter separate(CrsOptions{"EPSG:32722", "EPSG:5773", "", "test"});
  EXPECT_NEAR(separate.ToPivot({kUtm22s.x(), kUtm22s.y(), 0.0}).z(), g.z(), 1e-6);
}

TEST(Crs, MissingGridIsAnInputErrorNamingIt) {
  // EGM2008 height needs us_nga_egm08_25.tif, which proj-data does not ship: never a silent
  // ellipsoidal height.
  try {
    (void)Crs("EPSG:32722+3855");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("egm08"), std::string::npos) << e.what();
  }
  try {
    (void)CrsConverter(CrsOptions{"EPSG:32722", "", "/nonexistent/geoid.gtx", "test"});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/geoid.gtx"), std::string::npos);
  }
  EXPECT_THROW((void)Crs("EPSG:99999999"), InputError);
}

// The block `local` (in the tangent plane of `utm_frame`) written in another frame's CRSs, the
// conversions by PROJ and GeographicLib through the same tangent plane (same origin).
Project InFrame(const Project& local, const ObjectFrame& utm_frame, FrameSpec spec) {
  spec.kind = FrameSpec::Kind::kCrs;
  spec.has_origin = true;
  const Eigen::Vector3d origin = utm_frame.Origin();
  spec.lon_deg = origin.x();
  spec.lat_deg = origin.y();
  spec.h_m = origin.z();
  const ObjectFrame frame(spec);
  return FromAdjustmentFrame(local, frame);
}

TEST(CrsFrame, OdmUavBlockInFourCrsGivesTheSameResult) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_br_uav_gcp_block is absent";
  Project utm = testing::ImportOdmUavBlock(dir);  // EPSG:32722 (PROVENANCE.md)
  utm.frame = FrameSpec{};
  utm.frame.kind = FrameSpec::Kind::kCrs;
  utm.frame.crs = "EPSG:32722";
  const ObjectFrame utm_frame(utm.frame);
  utm_frame.FixOrigin(utm);

  struct Case {
    const char* name;
    FrameSpec spec;
  };
  std::vector<Case> cases(6);
  cases[0] = {"UTM 22S (EPSG:32722)", utm.frame};
  cases[1].name = "WGS84 geodetic (EPSG:4979)";
  cases[1].spec.crs = "EPSG:4979";
  cases[2].name = "ECEF (EPSG:4978)";
  cases[2].spec.crs = "EPSG:4978";
  // A national projection with orthometric heights: SIRGAS 2000 / Brazil Mercator with EGM96
  // heights (the pivot is SIRGAS 2000's geographic 3D CRS, PROJ's "SIRGAS 2000 to WGS 84 (1)").
  cases[3].name = "SIRGAS 2000 / Brazil Mercator + EGM96 height (EPSG:5641+5773)";
  cases[3].spec.crs = "EPSG:5641+5773";
  // The Brazil Polyconic is not conformal: its grid scale differs along east and north, so a
  // ground sigma isotropic in plan is not along the grid axes and the diagonal sigmas of the file
  // carry it only approximately (object_frame.h): same coordinates, sigmas off by 5e-6 here,
  // the camera by 2e-6 relative.
  cases[4].name = "SIRGAS 2000 / Brazil Polyconic + EGM96 height (EPSG:5880+5773)";
  cases[4].spec.crs = "EPSG:5880+5773";
  // Control in the national grid with orthometric heights, the images' centres in WGS84 3D.
  cases[5].name = "points EPSG:5641+5773, exposures EPSG:4979 (per file)";
  cases[5].spec.crs = "EPSG:5641+5773";
  cases[5].spec.exposures_crs = "EPSG:4979";

  AdjustOptions options;
  options.robust_start = true;
  options.free_interior = ParseSelfCalibration("all");
  std::vector<AdjustmentResult> results;
  // The same physical data in every CRS: survey sigmas of 2 cm on every axis of the ground
  // (a grid metre of UTM is k ground metres: 0.02 ground metres are 0.02 k grid metres there).
  Project local = ToAdjustmentFrame(utm, utm_frame);
  for (auto& p : local.points) p.sigma_m = Eigen::Vector3d::Constant(0.02);
  for (const auto& c : cases) {
    const Project input = InFrame(local, utm_frame, c.spec);
    const ObjectFrame frame(input.frame);
    const Project converted = ToAdjustmentFrame(input, frame);
    // The conversion there and back (PROJ, GeographicLib) keeps the block to 0.1 mm.
    double round_trip_m = 0;
    for (size_t i = 0; i < local.points.size(); ++i)
      if (local.points[i].xyz_m)
        round_trip_m =
            std::max(round_trip_m, (*converted.points[i].xyz_m - *local.points[i].xyz_m).norm());
    double sigma_change = 0;
    for (const auto& p : converted.points)
      sigma_change = std::max(sigma_change,
                              (p.sigma_m / 0.02 - Eigen::Vector3d::Ones()).cwiseAbs().maxCoeff());
    std::printf("%s: largest round-trip difference of a point %.3g m, of a sigma %.3g relative\n",
                c.name,
                round_trip_m,
                sigma_change);
    EXPECT_LT(round_trip_m, 1e-4) << c.name;
    AdjustmentResult r = Adjust(converted, options);
    ToInputFrame(frame, &r);
    ASSERT_TRUE(r.converged()) << c.name;
    std::printf(
        "%-64s check RMSE %.4f %.4f %.4f m (n %d), c %.6f mm, first check point %.6f "
        "%.6f %.3f\n  frame: %s\n",
        c.name,
        r.check.rmse_m(0),
        r.check.rmse_m(1),
        r.check.rmse_m(2),
        static_cast<int>(r.check.n),
        r.cameras[0].estimated[0],
        r.check_points[0].adjusted_m.x(),
        r.check_points[0].adjusted_m.y(),
        r.check_points[0].adjusted_m.z(),
        r.frame.c_str());
    // Each result in its input CRS: the surveyed coordinates are the file's.
    const GroundPoint* survey = input.FindPoint(r.check_points[0].point);
    ASSERT_NE(survey, nullptr);
    EXPECT_LT((r.check_points[0].surveyed_m - *survey->xyz_m).norm(), 1e-6) << c.name;
    results.push_back(std::move(r));
  }
  const AdjustmentResult& a = results[0];
  double max_rmse = 0, max_camera = 0;
  for (size_t k = 1; k < results.size(); ++k) {
    const AdjustmentResult& b = results[k];
    ASSERT_EQ(a.check.n, b.check.n) << cases[k].name;  // counts
    ASSERT_EQ(a.rejected.size(), b.rejected.size()) << cases[k].name;
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(a.check.rmse_m(i), b.check.rmse_m(i), 1e-3) << cases[k].name;
      max_rmse = std::max(max_rmse, std::abs(a.check.rmse_m(i) - b.check.rmse_m(i)));
    }
    const auto& ca = a.cameras[0].estimated;
    const auto& cb = b.cameras[0].estimated;
    ASSERT_EQ(ca.size(), cb.size());
    ASSERT_EQ(a.cameras[0].sigma.size(), ca.size());
    for (int i = 0; i < static_cast<int>(ca.size()); ++i) {
      // 1e-6 relative, or of the parameter's precision where the value is near 0.
      const double scale = std::max(std::abs(ca[i]), a.cameras[0].sigma[i]);
      const double d = std::abs(ca[i] - cb[i]) / std::max(scale, 1e-300);
      EXPECT_LT(d, k == 4 ? 1e-5 : 1e-6)
          << cases[k].name << " parameter " << i << ": " << ca[i] << " vs " << cb[i];
      if (k != 4) max_camera = std::max(max_camera, d);
    }
  }
  std::printf(
      "largest differences to the UTM run: check RMSE %.3g m (all six), camera %.3g "
      "relative (all but the Polyconic)\n",
      max_rmse,
      max_camera);
}

// `import odm --crs`: the block's GCP list converted to WGS84 longitude/latitude (EPSG:4326, as a
// surveyor's RTK list comes) imports and adjusts like the UTM list with --crs EPSG:32722.
TEST(CrsFrame, ImportOdmTakesAWgs84GcpList) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_br_uav_gcp_block is absent";
  testing::TempDir tmp("aerocal_crs_odm");
  const Project block = testing::ImportOdmUavBlock(dir);
  calib::WriteCamera(tmp.File("camera.yaml"), block.cameras.begin()->second);
  const CrsConverter utm = Crs("EPSG:32722");
  const std::string list = ReadTextFile(dir + "/odm_gcp_br/gcp_list_floatxy_raw.txt");
  std::istringstream in(list);
  std::string line;
  std::getline(in, line);  // the projection
  std::string wgs84 = "EPSG:4326\n";
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    Eigen::Vector3d xyz;
    std::string rest;
    if (!(fields >> xyz.x() >> xyz.y() >> xyz.z())) continue;
    std::getline(fields, rest);
    const Eigen::Vector3d g = utm.ToPivot(xyz);
    char buffer[128];
    std::snprintf(buffer, sizeof(buffer), "%.11f %.11f %.4f", g.x(), g.y(), g.z());
    wgs84 += buffer + rest + "\n";
  }
  WriteFileAtomically(tmp.File("gcp_wgs84.txt"), wgs84);
  // Without --crs the geographic list is refused, naming the option.
  const auto refused =
      testing::RunAerocal("import odm --gcp-list " + tmp.File("gcp_wgs84.txt") + " --camera " +
                          tmp.File("camera.yaml") + " --out " + tmp.File("refused"));
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--crs"), std::string::npos) << refused.output;

  std::vector<nlohmann::json> results;
  for (const auto& [name, gcp, crs] :
       std::vector<std::tuple<std::string, std::string, std::string>>{
           {"utm", dir + "/odm_gcp_br/gcp_list_floatxy_raw.txt", "EPSG:32722"},
           {"wgs84", tmp.File("gcp_wgs84.txt"), "EPSG:4326"}}) {
    const auto imported = testing::RunAerocal(
        "import odm --gcp-list " + gcp + " --camera " + tmp.File("camera.yaml") + " --control " +
        dir + "/odm_gcp_br/gcp_list_raw.txt --crs " + crs + " --out " + tmp.File(name));
    ASSERT_EQ(imported.exit_code, 0) << imported.output;
    const auto run = testing::RunAerocal("adjust --project " + tmp.File(name + "/project.yaml") +
                                         " --robust-start --out " + tmp.File(name + ".json"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    results.push_back(aerocal::testing::ReadJson(tmp.File(name + ".json")));
    std::printf("%s: check RMSE %s\n  frame: %s\n",
                name.c_str(),
                results.back()["check"]["rmse_m"].dump().c_str(),
                results.back()["frame"].get<std::string>().c_str());
  }
  ASSERT_EQ(results[0]["check"]["n"], results[1]["check"]["n"]);
  for (int k = 0; k < 3; ++k)
    EXPECT_NEAR(results[0]["check"]["rmse_m"][k].get<double>(),
                results[1]["check"]["rmse_m"][k].get<double>(),
                1e-3);
  EXPECT_NE(results[1]["frame"].get<std::string>().find("X = longitude"), std::string::npos);

  // `aerocal export --write-crs EPSG:4326` of the UTM result gives the WGS84 result's exposures
  // (centres to 1e-8 deg ~ 1 mm, attitudes relative to east/north/up to 1e-4 deg) and a GeoJSON
  // of the check-point errors.
  const auto exported = testing::RunAerocal("export --project " + tmp.File("utm/project.yaml") +
                                            " --result " + tmp.File("utm.json") +
                                            " --write-crs EPSG:4326 --out " + tmp.File("export"));
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  const CsvTable table = CsvTable::Read(tmp.File("export/exposures.csv"));
  ASSERT_EQ(table.rows().size(), results[1]["exposures"].size());
  for (const auto& row : table.rows()) {
    const std::string image = table.String(row, "image");
    for (const auto& e : results[1]["exposures"])
      if (e["image"] == image) {
        EXPECT_NEAR(table.Number(row, "X"), e["X"].get<double>(), 1e-8) << image;
        EXPECT_NEAR(table.Number(row, "Y"), e["Y"].get<double>(), 1e-8) << image;
        EXPECT_NEAR(table.Number(row, "Z"), e["Z"].get<double>(), 1e-3) << image;
        for (const char* angle : {"omega", "phi", "kappa"})
          EXPECT_NEAR(table.Number(row, angle), e[angle].get<double>(), 1e-4) << image << angle;
      }
  }
  const nlohmann::json geojson =
      aerocal::testing::ReadJson(tmp.File("export/check_errors.geojson"));
  EXPECT_EQ(geojson["type"], "FeatureCollection");
  EXPECT_EQ(geojson["features"].size(), results[0]["check"]["points"].size());
  EXPECT_NEAR(geojson["features"][0]["geometry"]["coordinates"][0].get<double>(), -49.42, 0.01);
}

// A GTX geoid grid (PROJ's vgridshift format: big-endian header lat0, lon0, dlat, dlon (deg),
// rows, columns, then float32 undulations row by row from the south) over the ODM block with
// N = 10 + 1 m per 0.5 deg north + 0.5 m per 0.5 deg east (bilinear interpolation is exact).
void WriteGtx(const std::string& path) {
  std::string bytes;
  const auto put = [&](const void* data, size_t n) {
    const char* c = static_cast<const char*>(data);
    for (size_t i = n; i-- > 0;) bytes += c[i];  // little-endian host -> big-endian file
  };
  for (double v : {-27.0, -51.0, 0.5, 0.5}) put(&v, 8);
  for (int32_t v : {8, 8}) put(&v, 4);
  for (int row = 0; row < 8; ++row)
    for (int col = 0; col < 8; ++col) {
      const float n = 10.0f + 1.0f * row + 0.5f * col;
      put(&n, 4);
    }
  WriteFileAtomically(path, bytes);
}

// Orthometric heights through the geoid PROJ finds (EGM96, installed) or a grid file the user
// names give the same adjustment as ellipsoidal heights; a grid that is not installed is exit 2
// naming it, never a silent ellipsoidal height.
TEST(CrsFrame, OrthometricHeightsGiveTheEllipsoidalResult) {
  const std::string dir = testing::SharedDataDir("odm_br_uav_gcp_block");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_br_uav_gcp_block is absent";
  testing::TempDir tmp("aerocal_crs_geoid");
  Project utm = testing::ImportOdmUavBlock(dir);
  utm.frame = FrameSpec{};
  utm.frame.kind = FrameSpec::Kind::kCrs;
  utm.frame.crs = "EPSG:32722";
  const ObjectFrame utm_frame(utm.frame);
  utm_frame.FixOrigin(utm);
  const Project local = ToAdjustmentFrame(utm, utm_frame);
  WriteGtx(tmp.File("geoid.gtx"));

  FrameSpec ellipsoidal, egm96, user_grid;
  ellipsoidal.crs = "EPSG:32722";
  egm96.crs = "EPSG:32722+5773";
  user_grid.crs = "EPSG:32722";
  user_grid.geoid_grid = tmp.File("geoid.gtx");
  std::vector<nlohmann::json> results;
  std::vector<double> first_height;
  for (const auto& [name, spec] : std::vector<std::pair<std::string, FrameSpec>>{
           {"ellipsoidal", ellipsoidal}, {"egm96", egm96}, {"user_grid", user_grid}}) {
    const Project block = InFrame(local, utm_frame, spec);
    first_height.push_back(block.points.front().xyz_m->z());
    WriteProjectFolder(block, tmp.File(name));
    const auto run = testing::RunAerocal("adjust --project " + tmp.File(name + "/project.yaml") +
                                         " --robust-start --out " + tmp.File(name + ".json"));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    results.push_back(aerocal::testing::ReadJson(tmp.File(name + ".json")));
    std::printf("%s: height of %s %.4f m, check RMSE %s, c %.6f\n  frame: %s\n",
                name.c_str(),
                block.points.front().id.c_str(),
                first_height.back(),
                results.back()["check"]["rmse_m"].dump().c_str(),
                results.back()["cameras"][0]["estimated"]["c"].get<double>(),
                results.back()["frame"].get<std::string>().c_str());
  }
  // The heights in the files differ by the undulation (EGM96 ~4 m; the user grid 10 + ...).
  EXPECT_NEAR(first_height[0] - first_height[1], 4.0, 1.0);
  EXPECT_NEAR(first_height[0] - first_height[2], 10.0 + 2.8 + 1.6, 0.5);
  for (size_t k = 1; k < results.size(); ++k) {
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(results[0]["check"]["rmse_m"][i].get<double>(),
                  results[k]["check"]["rmse_m"][i].get<double>(),
                  1e-6);
    const double c0 = results[0]["cameras"][0]["estimated"]["c"].get<double>();
    EXPECT_NEAR(results[k]["cameras"][0]["estimated"]["c"].get<double>(), c0, 1e-6 * c0);
  }
  EXPECT_NE(results[1]["frame"].get<std::string>().find("geoid undulation at the origin N = 4.0"),
            std::string::npos);
  EXPECT_NE(results[2]["frame"].get<std::string>().find("geoid.gtx"), std::string::npos);

  // EGM2008 heights: us_nga_egm08_25.tif is not in Debian's proj-data.
  const std::string yaml = ReadTextFile(tmp.File("egm96/project.yaml"));
  const size_t at = yaml.find("EPSG:32722+5773");
  ASSERT_NE(at, std::string::npos);
  WriteFileAtomically(tmp.File("egm96/project.yaml"),
                      yaml.substr(0, at) + "EPSG:32722+3855" + yaml.substr(at + 15));
  const auto missing = testing::RunAerocal("adjust --project " + tmp.File("egm96/project.yaml") +
                                           " --out " + tmp.File("missing.json"));
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("us_nga_egm08_25.tif"), std::string::npos) << missing.output;
  // A user grid that is not there.
  std::remove(tmp.File("geoid.gtx").c_str());
  const auto gone = testing::RunAerocal("adjust --project " + tmp.File("user_grid/project.yaml") +
                                        " --out " + tmp.File("gone.json"));
  EXPECT_EQ(gone.exit_code, 2) << gone.output;
  EXPECT_NE(gone.output.find("geoid.gtx"), std::string::npos) << gone.output;
}

// `import colmap --crs`: a model georeferenced in ECEF (as COLMAP's model_aligner writes it)
// imports with frame: {crs: EPSG:4978} and adjusts in the tangent plane; a geographic CRS is
// refused (a COLMAP model is Cartesian).
TEST(CrsFrame, ImportColmapTakesAGeocentricModel) {
  FlightSimulationOptions o;
  o.interior_correction = {};
  o.ground_points = 60;
  o.tie_points = 300;
  const SimulatedFlight f = SimulateFlight(o);
  Project local = testing::ProjectFromFlight(f);  // nominal = truth (no correction)
  local.exposures = f.exposures_truth;
  local.points = f.points_truth;
  FrameSpec ecef;
  ecef.kind = FrameSpec::Kind::kCrs;
  ecef.crs = "EPSG:4978";
  ecef.has_origin = true;
  ecef.lat_deg = 47.3769;
  ecef.lon_deg = 8.5417;
  ecef.h_m = 400.0;
  const Project model = FromAdjustmentFrame(local, ObjectFrame(ecef));
  std::map<std::string, Eigen::Vector3d> points;
  for (const auto& g : model.points) points[g.id] = *g.xyz_m;
  testing::TempDir tmp("aerocal_crs_colmap");
  WriteColmapModel(model, points, tmp.File("model"));
  const auto refused =
      testing::RunAerocal("import colmap --colmap-model " + tmp.File("model") +
                          " --pixel-size-mm 0.009 --crs EPSG:4326 --out " + tmp.File("refused"));
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  const auto imported = testing::RunAerocal("import colmap --colmap-model " + tmp.File("model") +
                                            " --pixel-size-mm 0.009 --sigma-px 0.2 --crs EPSG:4978 "
                                            "--out " +
                                            tmp.File("block"));
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto adjusted = testing::RunAerocal("adjust --project " + tmp.File("block/project.yaml") +
                                            " --out " + tmp.File("r.json"));
  ASSERT_EQ(adjusted.exit_code, 0) << adjusted.output;
  const auto doc = aerocal::testing::ReadJson(tmp.File("r.json"));
  EXPECT_NEAR(doc["sigma0_px"].get<double>(), 0.2, 0.02);
  EXPECT_NE(doc["frame"].get<std::string>().find("X, Y, Z geocentric"), std::string::npos);
  // The adjusted centres are written back geocentric (|X| ~ Earth radius).
  EXPECT_NEAR(Eigen::Vector3d(doc["exposures"][0]["X"].get<double>(),
                              doc["exposures"][0]["Y"].get<double>(),
                              doc["exposures"][0]["Z"].get<double>())
                  .norm(),
              6.37e6,
              2e4);
}

}  // namespace
}  // namespace aerocal::triangulation
