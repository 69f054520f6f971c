// aerocal calibrate --directions (issue 36 item 6) on simulated laboratory instruments written in
// the directions file (docs/formats.md): a 9 x 9 collimator array over the field of view (0.5 arc
// second direction sigma, 0.05 px image sigma) and a 9 x 9 goniometer sequence on one target of
// unknown direction. The oracle: c, x0, y0 and the distortion within 3 reported sigmas of the
// truth, the method stated in the result and in the certificate, the camera file written in the
// requested format; two series as groups give the stability table and the reproducibility
// component; bad rows name FILE:LINE (exit 2, nothing written). A rig of three heads before one
// collimator array (the `unit` column) recovers every head's interior, the shared rotation and the
// mounts within 3 sigma, writes the rig file again, and gives a budget and certificate per head. A
// 2 x 3-CCD camera's sub-images (the `unit` column naming them) are calibrated in one adjustment
// with a gauge from the rank of the normal matrix, a budget with every mapping entry's U, groups,
// the certificate, and the camera file written again.
#include "calib/camera/camera.h"
#include "calib/camera/camera_io.h"
#include "calib/camera/rig_io.h"
#include "calib/camera/rotation.h"
#include "calib/core/string_printf.h"
#include "tests/support/simulated_directions.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <string>

namespace aerocal {
namespace {

using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

constexpr double kDeg = M_PI / 180.0;
constexpr double kArcSecond = kDeg / 3600.0;
constexpr double kSigmaPx = 0.05;
constexpr double kSigmaArcsec = 0.5;
const Eigen::Vector3d kTrueOpk(0.2 * kDeg, -0.3 * kDeg, 3.0 * kDeg);

// The camera file: nominal c, everything else 0 (the start).
constexpr const char* kCameraYaml =
    "name: lab\npixel_size_mm: 0.006\nformat_px: [6000, 4000]\ninterior: {c: 50.0}\n";

calib::Camera Truth() {
  calib::Camera camera = calib::Camera::OfModel(calib::CameraModelId::kBrownFraser10);
  camera.pixel_size_mm = 0.006;
  camera.width_px = 6000;
  camera.height_px = 4000;
  const double truth[10] = {50.012, 0.011, -0.007, -3e-5, 2e-8, -5e-12, 3e-6, -2e-6, 0.0, 0.0};
  std::copy(truth, truth + 10, camera.interior.begin());
  return camera;
}

Eigen::Vector3d Direction(double azimuth, double elevation) {
  return testing::InstrumentDirection(azimuth, elevation);
}

// The measured pixel of direction t (instrument frame) through setting G, with image noise.
Eigen::Vector2d Observe(const Eigen::Matrix3d& g, const Eigen::Vector3d& t, std::mt19937_64* rng) {
  const Eigen::Vector2d px = testing::ObserveDirection(Truth(), kTrueOpk, g, t, kSigmaPx, rng);
  EXPECT_TRUE(px.allFinite());
  return px;
}

Eigen::Matrix3d AngularError(std::mt19937_64* rng) {
  return testing::RandomSmallRotation(kSigmaArcsec * kArcSecond, rng);
}

// Node (i, j) of the 9 x 9 grid: azimuth -17..17 deg, elevation -11 .. 11 deg.
Eigen::Vector2d GridDeg(int i, int j) { return {-17.0 + 34.0 * i / 8.0, -11.0 + 22.0 * j / 8.0}; }

// A collimator array's rows (one per collimator), `group` in the last column when not empty.
std::string CollimatorRows(std::mt19937_64* rng, const std::string& group) {
  std::string rows;
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      const Eigen::Vector2d a = GridDeg(i, j);
      const Eigen::Vector3d t = AngularError(rng) * Direction(a.x() * kDeg, a.y() * kDeg);
      const Eigen::Vector2d px = Observe(Eigen::Matrix3d::Identity(), t, rng);
      rows += StringPrintf("C%d%d,%.5f,%.5f,%.3f,%.6f,%.6f,%.2f%s\n",
                           i,
                           j,
                           px.x(),
                           px.y(),
                           kSigmaPx,
                           a.x(),
                           a.y(),
                           kSigmaArcsec,
                           group.empty() ? "" : ("," + group).c_str());
    }
  return rows;
}

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

void ExpectWithinThreeSigma(const nlohmann::json& j) {
  const auto& camera = j["cameras"][0];
  const calib::Camera truth = Truth();
  int n = 0;
  for (const char* p : {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2"}) {
    const double estimate = camera["estimated"][p], sigma = camera["sigma"][p];
    const double error = estimate - truth.interior[truth.ParamIndex(p)];
    std::printf("%-3s error %+.3e sigma %.3e (%+.2f sigma)\n", p, error, sigma, error / sigma);
    EXPECT_GT(sigma, 0.0) << p;
    EXPECT_LE(std::abs(error), 3.0 * sigma) << p;
    ++n;
  }
  EXPECT_EQ(n, 8);
}

// The rotation to the instrument (the first unit's) within 3 sigma of kTrueOpk.
void ExpectRotationWithinThreeSigma(const nlohmann::json& method) {
  for (int a = 0; a < 3; ++a) {
    const double error =
        method["instrument_from_camera_opk_deg"][a].get<double>() * kDeg - kTrueOpk[a];
    const double sigma =
        method["instrument_from_camera_sigma_arcsec"][a].get<double>() * kArcSecond;
    EXPECT_LE(std::abs(error), 3.0 * sigma) << "opk " << a;
  }
}

TEST(CalibrateDirections, CollimatorArrayRecoversTheInteriorWithinThreeSigmaAndStatesTheMethod) {
  TempDir tmp("aerocal_directions_collimator");
  std::mt19937_64 rng(3610);
  WriteText(tmp.File("camera.yaml"), kCameraYaml);
  WriteText(
      tmp.File("directions.csv"),
      "# 9 x 9 collimator array\ntarget,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec\n" +
          CollimatorRows(&rng, ""));
  WriteText(tmp.File("budget.yaml"),
            "components:\n  - {quantity: c, source: collimator focal length, value: 0.6, unit: um, "
            "distribution: rectangular}\n");
  const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --budget " + tmp.File("budget.yaml") +
                            " --out " + tmp.File("result.json") + " --write-camera " +
                            tmp.File("calibrated.yml") + " --camera-format opencv");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(tmp.File("result.json"));
  ExpectWithinThreeSigma(j);
  EXPECT_EQ(j["command"], "calibrate");
  EXPECT_EQ(j["redundancy"], 2 * 81 - 11);  // 8 interior + 3 rotation
  const double redundancy = j["redundancy"];
  EXPECT_NEAR(j["sigma0"].get<double>(), 1.0, 3.0 / std::sqrt(2.0 * redundancy));
  const auto& cal = j["calibration"];
  EXPECT_EQ(cal["method"]["kind"], "collimator array");
  EXPECT_EQ(cal["data"]["observations"], 81);
  EXPECT_EQ(cal["camera_written"]["format"], "opencv");
  EXPECT_TRUE(std::filesystem::exists(tmp.File("calibrated.yml")));
  // The rotation to the instrument within 3 sigma; the start from the known directions is close.
  ExpectRotationWithinThreeSigma(cal["method"]);
  EXPECT_NEAR(cal["start"]["opk_deg"][2].get<double>(), 3.0, 0.1);
  // The budget of c: the adjustment's covariance (the directions' sigmas are in it), the pixel
  // pitch (zero: no tolerance stated) and the --budget file's type-B component (0.6 um
  // rectangular: 0.6e-3 / sqrt(3) mm).
  bool has_c = false;
  for (const auto& q : cal["uncertainty"])
    if (q["quantity"] == "c") {
      has_c = true;
      ASSERT_EQ(q["components"].size(), 3u) << q.dump();
      const double sigma = j["cameras"][0]["sigma"]["c"].get<double>();
      EXPECT_NEAR(q["components"][0]["u"].get<double>(), sigma, 1e-9 * sigma);
      EXPECT_EQ(q["components"][1]["source"], "pixel pitch");
      EXPECT_EQ(q["components"][1]["u"].get<double>(), 0.0);
      EXPECT_EQ(q["components"][2]["type"], "B");
      EXPECT_NEAR(q["components"][2]["u"].get<double>(), 0.6e-3 / std::sqrt(3.0), 1e-12);
      EXPECT_NEAR(q["u_c"].get<double>(), std::hypot(sigma, 0.6e-3 / std::sqrt(3.0)), 1e-9 * sigma);
    }
  EXPECT_TRUE(has_c);
  // --model opencv: the same rows calibrated in OpenCV's model beside it; --write-camera writes
  // that camera.
  const auto cv =
      RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                 tmp.File("directions.csv") + " --model opencv --out " + tmp.File("cv.json") +
                 " --write-camera " + tmp.File("cv.yml") + " --camera-format opencv");
  ASSERT_EQ(cv.exit_code, 0) << cv.output;
  const nlohmann::json beside = ReadJson(tmp.File("cv.json"))["calibration"];
  EXPECT_EQ(beside["beside"]["model"], "opencv");
  EXPECT_TRUE(beside["beside"]["valid"].get<bool>());
  EXPECT_EQ(beside["camera_written"]["model"], "opencv");
  // fx in px against c / pixel size: the same camera within their sigmas (c's 1.2 um is 0.2 px).
  EXPECT_NEAR(beside["beside"]["estimated"]["fx"].get<double>(),
              j["cameras"][0]["estimated"]["c"].get<double>() / 0.006,
              1.0);

  // The certificate states the method.
  const auto c = RunAerocal("certificate --result " + tmp.File("result.json") + " --out " +
                            tmp.File("cert") + " --no-render");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json cert = ReadJson(tmp.File("cert/certificate.json"));
  EXPECT_EQ(cert["method"]["kind"], "collimator array");
  EXPECT_EQ(cert["results"].size(), cal["uncertainty"].size());
}

TEST(CalibrateDirections, GoniometerSequenceRecoversTheInteriorAndTheTarget) {
  TempDir tmp("aerocal_directions_goniometer");
  std::mt19937_64 rng(3611);
  WriteText(tmp.File("camera.yaml"), kCameraYaml);
  const Eigen::Vector2d target_deg(0.05, -0.03);
  std::string rows = "target,col,row,sigma_px,sigma_arcsec,setting,turn_deg,tilt_deg\n";
  for (int i = 0; i < 9; ++i)
    for (int j = 0; j < 9; ++j) {
      const Eigen::Vector2d s = GridDeg(i, j);
      const Eigen::Matrix3d g =
          calib::RotationFromOpk(Eigen::Vector3d(s.y() * kDeg, s.x() * kDeg, 0.0));
      const Eigen::Vector2d px = Observe(
          g * AngularError(&rng), Direction(target_deg.x() * kDeg, target_deg.y() * kDeg), &rng);
      rows += StringPrintf("cross,%.5f,%.5f,%.3f,%.2f,s%d%d,%.6f,%.6f\n",
                           px.x(),
                           px.y(),
                           kSigmaPx,
                           kSigmaArcsec,
                           i,
                           j,
                           s.x(),
                           s.y());
    }
  WriteText(tmp.File("directions.csv"), rows);
  const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --out " + tmp.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(tmp.File("result.json"));
  ExpectWithinThreeSigma(j);
  const auto& method = j["calibration"]["method"];
  EXPECT_EQ(method["kind"], "goniometer");
  EXPECT_EQ(method["settings"], 81);
  EXPECT_EQ(j["redundancy"], 2 * 81 - 13);  // 8 interior + 3 rotation + 2 target angles
  const auto& target = method["estimated_targets"]["cross"];
  for (int a = 0; a < 2; ++a) {
    const double error_arcsec =
        ((a == 0 ? target["azimuth_deg"] : target["elevation_deg"]).get<double>() - target_deg[a]) *
        3600.0;
    EXPECT_LE(std::abs(error_arcsec), 3.0 * target["sigma_arcsec"][a].get<double>()) << a;
  }
}

TEST(CalibrateDirections, TwoSeriesAsGroupsGiveTheStabilityTableAndTheReproducibility) {
  TempDir tmp("aerocal_directions_groups");
  std::mt19937_64 rng(3612);
  WriteText(tmp.File("camera.yaml"), kCameraYaml);
  WriteText(tmp.File("directions.csv"),
            "target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,group\n" +
                CollimatorRows(&rng, "monday") + CollimatorRows(&rng, "tuesday"));
  const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --out " + tmp.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(tmp.File("result.json"));
  const auto& cal = j["calibration"];
  EXPECT_EQ(cal["groups"].size(), 2u);
  EXPECT_EQ(cal["stability"]["rows"].size(), 8u);
  EXPECT_TRUE(cal["stability"]["agree"].get<bool>());
  bool reproducibility = false;
  for (const auto& c : cal["uncertainty"][0]["components"])
    reproducibility =
        reproducibility || c["source"].get<std::string>().find("group reproducibility") == 0;
  EXPECT_TRUE(reproducibility);
}

TEST(CalibrateDirections, BadRowsNameTheirLineAndNothingIsWritten) {
  TempDir tmp("aerocal_directions_bad");
  WriteText(tmp.File("camera.yaml"), kCameraYaml);
  const std::string header = "target,col,row,azimuth_deg,elevation_deg\n";
  const std::string good = "A,3000,2000,0,0\nB,4000,2000,6.8,0\nC,3000,1000,0,6.8\n";
  struct Case {
    std::string text, message;
  };
  const Case cases[] = {
      {header + good + "D,3000,2000,0,95\n",
       "directions.csv:5: column 'elevation_deg' out of range"},
      {header + good + "A,3000,2000,1,0\n", "directions.csv:5: target A: its azimuth_deg"},
      {header + good + "D,3000,9000,1,0\n", "directions.csv:5: column 'row' out of range"},
      {header + good + "D,3000,2000,1,\n",
       "directions.csv:5: azimuth_deg and elevation_deg go together"},
      {header + good + ",3000,2000,1,1\n", "directions.csv:5: target must not be empty"},
      {header + good + "B,3100,2000,6.8,0\n", "directions.csv:5: target B is observed twice"},
      {header + good + "D,3000,2000,170,0\n", "directions.csv:5: target D is"},
      {"target,col,row,azimuth\n", "directions.csv:1: unknown column 'azimuth'"},
      {"target,col\n", "directions.csv:1: missing column 'row'"},
      {"target,col,row,setting,turn_deg\nX,1,1,s1,5\nX,2,2,s1,6\n",
       "directions.csv:3: setting s1 has turn"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    WriteText(tmp.File("directions.csv"), c.text);
    const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                              tmp.File("directions.csv") + " --out " + tmp.File("result.json"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("result.json")));
  }
  // Rows without sigma_px take --sigma-px (a 3-target file calibrating c alone: redundancy 2).
  WriteText(tmp.File("directions.csv"), header + good);
  const auto sigma =
      RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                 tmp.File("directions.csv") + " --self-calibration c --sigma-px 0.2 --out " +
                 tmp.File("sigma.json"));
  ASSERT_LE(sigma.exit_code, 3) << sigma.output;
  const nlohmann::json s = ReadJson(tmp.File("sigma.json"));
  EXPECT_EQ(s["redundancy"], 2);
  EXPECT_NEAR(s["residuals"][0]["sigma_px"].get<double>(), 0.2, 1e-12);
  // Options of the test field are refused by name; a second source is refused.
  for (const std::string& extra : {std::string("--board-sigma-mm 0.1"),
                                   std::string("--no-snooping"),
                                   std::string("--points p.csv --observations o.csv")}) {
    const auto r =
        RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                   tmp.File("directions.csv") + " --out " + tmp.File("result.json") + " " + extra);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(extra.substr(0, extra.find(' '))), std::string::npos) << r.output;
  }
  // A target radius (test-field eccentricity) is refused.
  WriteText(tmp.File("budget.yaml"), "target_radius_mm: 2\n");
  const auto radius = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") +
                                 " --directions " + tmp.File("directions.csv") + " --budget " +
                                 tmp.File("budget.yaml") + " --out " + tmp.File("result.json"));
  EXPECT_EQ(radius.exit_code, 2) << radius.output;
  EXPECT_NE(radius.output.find("target_radius_mm"), std::string::npos) << radius.output;
  // One group is no stability test.
  WriteText(tmp.File("directions.csv"),
            "target,col,row,azimuth_deg,elevation_deg,group\nA,3000,2000,0,0,g\n");
  const auto one = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                              tmp.File("directions.csv") + " --out " + tmp.File("result.json"));
  EXPECT_EQ(one.exit_code, 2) << one.output;
  EXPECT_NE(one.output.find("1 group"), std::string::npos) << one.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("result.json")));
}

// A rig of three heads (pixels of 6 um, c 50 mm; A and B 6000 x 4000 px, C 5000 x 3200 px; the
// side heads turned by -+20 deg about y, with small offsets from the rig file's design mounts)
// before one collimator array of 25 x 7 directions over -36..36 x -9..9 deg: each head measures
// the directions on its format.
struct RigHeadTruth {
  const char* id;
  double interior[10];
  Eigen::Vector3d mount_deg;  // rig_from_head, the truth (the file holds the design: 0, phi, 0)
  int width_px, height_px;
};
const RigHeadTruth kHeads[] = {
    {"A", {50.012, 0.011, -0.007, -3e-5, 2e-8, -5e-12, 3e-6, -2e-6, 0, 0}, {0, 0, 0}, 6000, 4000},
    {"B",
     {49.991, -0.008, 0.013, -2e-5, 1e-8, 0, -2e-6, 1e-6, 0, 0},
     {0.05, -20.0, 0.1},
     6000,
     4000},
    {"C",
     {50.004, 0.006, 0.004, -4e-5, 3e-8, -8e-12, 1e-6, 3e-6, 0, 0},
     {-0.04, 20.0, -0.08},
     5000,
     3200}};

// Head h as a single camera file's text (its nominal c, its format).
std::string HeadYaml(const RigHeadTruth& h) {
  return StringPrintf(
      "pixel_size_mm: 0.006, format_px: [%d, %d], interior: {c: 50.0}", h.width_px, h.height_px);
}

std::string RigYaml() {
  std::string yaml = "name: lab rig\nrig:\n  reference_head: A\n  heads:\n";
  for (const auto& h : kHeads)
    yaml += StringPrintf("    - {id: %s, %s, mount_deg: [0, %.1f, 0]}\n",
                         h.id,
                         HeadYaml(h).c_str(),
                         h.mount_deg.y());
  return yaml;
}

calib::Camera HeadTruth(const RigHeadTruth& h) {
  calib::Camera camera = Truth();
  std::copy(h.interior, h.interior + 10, camera.interior.begin());
  camera.width_px = h.width_px;
  camera.height_px = h.height_px;
  return camera;
}

// instrument_from_head = R M_k (R the instrument_from_rig of the reference head A: kTrueOpk).
Eigen::Vector3d HeadOpk(const RigHeadTruth& h) {
  return calib::OpkFromRotation(calib::RotationFromOpk(kTrueOpk) *
                                calib::RotationFromOpk(h.mount_deg * kDeg));
}

// Each head's rows (target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,unit).
std::vector<std::string> RigRows(std::mt19937_64* rng) {
  std::vector<std::string> rows;
  for (const auto& h : kHeads) {
    std::string text;
    for (int i = 0; i < 25; ++i)
      for (int j = 0; j < 7; ++j) {
        const double a = -36.0 + 3.0 * i, e = -9.0 + 3.0 * j;
        const Eigen::Vector3d t = AngularError(rng) * Direction(a * kDeg, e * kDeg);
        const Eigen::Vector3d uvw = calib::RotationFromOpk(HeadOpk(h)).transpose() * t;
        if (!(uvw.z() < -0.5)) continue;  // behind or far off the head's axis
        const Eigen::Vector2d px = testing::ObserveDirection(
            HeadTruth(h), HeadOpk(h), Eigen::Matrix3d::Identity(), t, kSigmaPx, rng);
        if (!px.allFinite() || px.x() < 0 || px.y() < 0 || px.x() > h.width_px - 1 ||
            px.y() > h.height_px - 1)
          continue;
        text += StringPrintf("C%02d%d,%.5f,%.5f,%.3f,%.1f,%.1f,%.2f,%s\n",
                             i,
                             j,
                             px.x(),
                             px.y(),
                             kSigmaPx,
                             a,
                             e,
                             kSigmaArcsec,
                             h.id);
      }
    rows.push_back(text);
  }
  return rows;
}

constexpr const char* kRigHeader =
    "target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,unit\n";

// `rows` (one head's) as a single camera's: the unit column dropped.
std::string WithoutUnit(const std::string& rows) {
  std::istringstream in(rows);
  std::string out, line;
  while (std::getline(in, line)) out += line.substr(0, line.rfind(',')) + "\n";
  return out;
}

// Every head's budget is the budget of a single camera over the head's own estimate and
// covariance. Calibrated alone from its own rows, a head has the same estimate and cofactors: the
// targets are known, and the shared rotation with a head's mount is, together, that head's own
// rotation, so the joint problem separates into the heads. Its components therefore differ only by
// the two runs' sigma0 (the image component is sigma0 sqrt(q), no type-B component is stated, k = 2
// in both): U_rig / sigma0_rig = U_alone / sigma0_alone for every quantity, the distortion at the
// head's own radii included (the alone run's defaults from the same format). Measured (seed 3613):
// equal within 8e-7 relative, the values within 7e-7 U; asserted within 1e-5 and 1e-4 U.
void ExpectHeadBudgetsAsAlone(const TempDir& tmp,
                              const nlohmann::json& rig,
                              const std::vector<std::string>& rows) {
  const double sigma0_rig = rig["sigma0"];
  for (size_t k = 0; k < rows.size(); ++k) {
    const std::string id = kHeads[k].id;
    WriteText(tmp.File(id + ".yaml"), "{" + HeadYaml(kHeads[k]) + "}\n");
    WriteText(
        tmp.File(id + ".csv"),
        "target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec\n" + WithoutUnit(rows[k]));
    const auto r = RunAerocal("calibrate --camera " + tmp.File(id + ".yaml") + " --directions " +
                              tmp.File(id + ".csv") + " --out " + tmp.File(id + ".json"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json alone = ReadJson(tmp.File(id + ".json"));
    const double sigma0_alone = alone["sigma0"];
    std::map<std::string, nlohmann::json> of_alone;
    for (const auto& q : alone["calibration"]["uncertainty"]) of_alone[q["quantity"]] = q;
    int compared = 0;
    for (const auto& q : rig["calibration"]["uncertainty"]) {
      const std::string name = q["quantity"];
      if (name.rfind(id + ".", 0) != 0 || name.find(".mount_") != std::string::npos) continue;
      const auto a = of_alone.find(name.substr(id.size() + 1));
      ASSERT_NE(a, of_alone.end()) << name << " has no row alone";
      const double u_rig = q["U"], u_alone = a->second["U"];
      if (name == id + ".c")
        std::printf("%s: U %.3e mm (sigma0 %.4f) in the rig, %.3e mm (sigma0 %.4f) alone\n",
                    name.c_str(),
                    u_rig,
                    sigma0_rig,
                    u_alone,
                    sigma0_alone);
      EXPECT_NEAR(u_rig / sigma0_rig, u_alone / sigma0_alone, 1e-5 * u_alone / sigma0_alone)
          << name;
      EXPECT_NEAR(q["value"].get<double>(), a->second["value"].get<double>(), 1e-4 * u_alone)
          << name;
      ++compared;
    }
    EXPECT_EQ(compared, 16) << id;  // 8 parameters, dr and dt at 4 radii
  }
}

TEST(CalibrateDirections, RigHeadsInOneAdjustmentRecoverInteriorsAndMountsWithinThreeSigma) {
  TempDir tmp("aerocal_directions_rig");
  std::mt19937_64 rng(3613);
  WriteText(tmp.File("rig.yaml"), RigYaml());
  const std::vector<std::string> rows = RigRows(&rng);
  WriteText(tmp.File("directions.csv"), kRigHeader + rows[0] + rows[1] + rows[2]);
  const auto r = RunAerocal("calibrate --camera " + tmp.File("rig.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --out " + tmp.File("result.json") +
                            " --write-camera " + tmp.File("calibrated.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(tmp.File("result.json"));
  const auto& cal = j["calibration"];
  EXPECT_EQ(cal["method"]["kind"], "collimator array");
  ASSERT_EQ(j["cameras"].size(), 3u);
  ASSERT_EQ(cal["units"].size(), 3u);
  const double redundancy = j["redundancy"];
  EXPECT_EQ(redundancy, 2.0 * cal["data"]["observations"].get<int>() - 3 * 11);
  EXPECT_NEAR(j["sigma0"].get<double>(), 1.0, 3.0 / std::sqrt(2.0 * redundancy));
  const calib::Rig written = calib::ReadRig(tmp.File("calibrated.yaml"));
  for (int k = 0; k < 3; ++k) {
    const RigHeadTruth& h = kHeads[k];
    const auto& camera = j["cameras"][k];
    const auto& unit = cal["units"][k];
    ASSERT_EQ(camera["id"], h.id);
    ASSERT_EQ(unit["id"], h.id);
    const calib::Camera truth = HeadTruth(h);
    for (const char* p : {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2"}) {
      const double estimate = camera["estimated"][p], sigma = camera["sigma"][p];
      const double error = estimate - truth.interior[truth.ParamIndex(p)];
      std::printf(
          "%s %-3s error %+.3e sigma %.3e (%+.2f sigma)\n", h.id, p, error, sigma, error / sigma);
      EXPECT_LE(std::abs(error), 3.0 * sigma) << h.id << " " << p;
    }
    EXPECT_FALSE(camera["sigma"].contains("B1"));  // fixed: no sigma
    // The mount relative to the first unit (A, whose design mount is the identity), the written
    // rig's mount and interior.
    const calib::RigHead& head = written.heads[written.HeadIndex(h.id)];
    EXPECT_NEAR(head.camera.interior[0], camera["estimated"]["c"].get<double>(), 1e-12);
    for (int a = 0; a < 3; ++a) {
      const double mount_deg = unit["mount_opk_deg"][a];
      EXPECT_NEAR(head.mount_rad[a] / kDeg, mount_deg, 1e-9);
      if (k == 0) {
        EXPECT_TRUE(unit["mount_sigma_arcsec"].is_null());
        continue;
      }
      const double sigma = unit["mount_sigma_arcsec"][a];
      const double error_arcsec = (mount_deg - h.mount_deg[a]) * 3600.0;
      std::printf("%s mount %d error %+.2f\" sigma %.2f\"\n", h.id, a, error_arcsec, sigma);
      EXPECT_GT(sigma, 0.0);
      EXPECT_LE(std::abs(error_arcsec), 3.0 * sigma) << h.id << " mount " << a;
    }
  }
  // The shared rotation (the reference head's) within 3 sigma.
  ExpectRotationWithinThreeSigma(cal["method"]);
  // The budget per head: every head's interior as "HEAD.name", the mounts after the first head;
  // the certificate lists them with U (k = 2) and names the units and the method.
  std::map<std::string, nlohmann::json> budget;
  for (const auto& q : cal["uncertainty"]) budget[q["quantity"].get<std::string>()] = q;
  for (const char* name : {"A.c", "B.c", "C.c", "B.x0", "C.K1", "B.mount_phi", "C.mount_kappa"})
    ASSERT_TRUE(budget.count(name)) << name;
  EXPECT_FALSE(budget.count("A.mount_phi"));  // the first head is the mounts' reference
  EXPECT_NEAR(budget["B.c"]["components"][0]["u"].get<double>(),
              j["cameras"][1]["sigma"]["c"].get<double>(),
              1e-12);
  EXPECT_NEAR(budget["B.mount_phi"]["u_c"].get<double>() * 3600.0,
              cal["units"][1]["mount_sigma_arcsec"][1].get<double>(),
              1e-9);
  EXPECT_EQ(budget["C.c"]["statement"].get<std::string>().rfind("C.c = ", 0), 0u);
  const auto c = RunAerocal("certificate --result " + tmp.File("result.json") + " --out " +
                            tmp.File("cert") + " --no-render");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json cert = ReadJson(tmp.File("cert/certificate.json"));
  EXPECT_EQ(cert["method"]["kind"], "collimator array");
  EXPECT_EQ(cert["units"].size(), 3u);
  EXPECT_EQ(cert["results"].size(), cal["uncertainty"].size());
  EXPECT_NE(c.output.find("B.c = "), std::string::npos) << c.output;
  // Every head's figure data (the renderer draws one panel per head): the first head's are the
  // certificate's own distortion and correlation; the others are computed over their own estimate
  // (different interiors: different curves) with their own correlation table.
  const auto& figures = cert["heads"];
  ASSERT_EQ(figures.size(), 3u);
  EXPECT_EQ(figures[0]["distortion"], cert["distortion"]);
  EXPECT_EQ(figures[0]["correlation"], cert["correlation"]);
  EXPECT_EQ(figures[0]["radii_mm"], cert["radii_mm"]);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(figures[k]["id"], kHeads[k].id);
    // Its own budget: its rows of the results (its interior, distortion, mount), at its radii.
    nlohmann::json own = nlohmann::json::array();
    for (const auto& q : cert["results"])
      if (q["quantity"].get<std::string>().rfind(std::string(kHeads[k].id) + ".", 0) == 0)
        own.push_back(q);
    EXPECT_EQ(figures[k]["results"], own) << k;
    EXPECT_EQ(own.size(), k == 0 ? 16u : 19u) << k;
    EXPECT_EQ(figures[k]["radii_mm"], cal["units"][k]["radii_mm"]) << k;
    ASSERT_TRUE(figures[k]["distortion"].is_object()) << k;
    ASSERT_TRUE(figures[k]["correlation"].is_object()) << k;
    EXPECT_EQ(figures[k]["correlation"]["names"], cert["correlation"]["names"]);
    const auto& rho = figures[k]["correlation"]["correlation"];
    for (size_t i = 0; i < rho.size(); ++i) EXPECT_NEAR(rho[i][i].get<double>(), 1.0, 1e-12);
  }
  EXPECT_NE(figures[1]["distortion"]["profile"], figures[0]["distortion"]["profile"]);
  EXPECT_NE(figures[2]["correlation"]["covariance"], figures[0]["correlation"]["covariance"]);
  // The heads' U differ (their own covariances), head C's distortion is certified at its own
  // format's radii (quarters of its half diagonal, 17.81 mm), and every head's U is the one of a
  // run on that head alone.
  EXPECT_NE(budget["A.c"]["U"], budget["B.c"]["U"]);
  EXPECT_NE(budget["B.c"]["U"], budget["C.c"]["U"]);
  EXPECT_EQ(cal["units"][2]["radii_mm"], nlohmann::json({4.5, 8.9, 13.4, 17.8}));
  EXPECT_EQ(cal["units"][0]["radii_mm"], nlohmann::json({5.4, 10.8, 16.2, 21.6}));
  EXPECT_TRUE(budget.count("C.dr@17.8") && !budget.count("C.dr@21.6"));
  ExpectHeadBudgetsAsAlone(tmp, j, rows);
}

// A 2 x 3-CCD camera (tests/support/simulated_directions.h: six 2100 x 2100 px CCDs on a
// 6000 x 4000 px virtual image by affine mappings) before a collimator array of 25 x 17
// directions, every cross measured in the CCDs it falls on; the camera file holds the nominal
// mappings (the true ones differ by up to 2 px and 3e-4 rad, CCD A's not at all).
std::string MultiCcdYaml() {
  std::string yaml = std::string(kCameraYaml) + "subimages:\n";
  for (int k = 0; k < 6; ++k) {
    const calib::SubimageMapping m = testing::MultiCcdMapping(k);
    yaml += StringPrintf(
        "  - {id: %s, format_px: [2100, 2100], model: affine, params: [%.17g, "
        "%.17g, %.17g, %.17g, %.17g, %.17g]}\n",
        m.id.c_str(),
        m.params[0],
        m.params[1],
        m.params[2],
        m.params[3],
        m.params[4],
        m.params[5]);
  }
  return yaml;
}

calib::Camera MultiCcdTruth() {
  calib::Camera camera = Truth();
  camera.subimages = testing::TrueMultiCcdMappings();
  return camera;
}

// The rows (target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,unit[,group]).
std::string MultiCcdRows(std::mt19937_64* rng, const std::string& group) {
  std::string rows;
  for (int i = 0; i < 25; ++i)
    for (int j = 0; j < 17; ++j) {
      const double a = -19.0 + 1.55 * i, e = -13.0 + 1.6 * j;
      const Eigen::Vector3d t = AngularError(rng) * Direction(a * kDeg, e * kDeg);
      for (const auto& [sub, uv] :
           testing::ObserveInSubimages(MultiCcdTruth(), kTrueOpk, t, kSigmaPx, rng))
        rows += StringPrintf("C%02d%02d,%.5f,%.5f,%.3f,%.2f,%.2f,%.2f,%s%s\n",
                             i,
                             j,
                             uv.x(),
                             uv.y(),
                             kSigmaPx,
                             a,
                             e,
                             kSigmaArcsec,
                             sub.c_str(),
                             group.empty() ? "" : ("," + group).c_str());
    }
  return rows;
}

TEST(CalibrateDirections, MultiCcdSubImagesInOneAdjustmentWithGaugeBudgetAndCertificate) {
  TempDir tmp("aerocal_directions_multi_ccd");
  std::mt19937_64 rng(3615);
  WriteText(tmp.File("camera.yaml"), MultiCcdYaml());
  WriteText(tmp.File("directions.csv"), kRigHeader + MultiCcdRows(&rng, ""));
  const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --out " + tmp.File("result.json") +
                            " --write-camera " + tmp.File("calibrated.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json j = ReadJson(tmp.File("result.json"));
  ExpectWithinThreeSigma(j);
  const auto& cal = j["calibration"];
  ExpectRotationWithinThreeSigma(cal["method"]);
  EXPECT_EQ(cal["method"]["kind"], "collimator array");
  EXPECT_EQ(cal["camera"]["kind"], "multi-CCD");
  // The gauge: the rank defect of the normal matrix with every mapping free is 6 (an affine map
  // of the virtual plane; B1, B2 held by the default self-calibration: then it is 4), the
  // reference's entries that span it held, full rank with them.
  const auto& gauge = cal["gauge"];
  EXPECT_EQ(gauge["reference"], "A");
  EXPECT_TRUE(gauge["ok"].get<bool>());
  EXPECT_EQ(gauge["rank_defect_with_gauge"], 0);
  EXPECT_EQ(gauge["held"].size(), gauge["rank_defect"].get<size_t>());
  // Every estimated mapping entry within 3 sigma of the truth, with its U in the budget.
  std::map<std::string, nlohmann::json> budget;
  for (const auto& q : cal["uncertainty"]) budget[q["quantity"].get<std::string>()] = q;
  const calib::Camera truth = MultiCcdTruth();
  ASSERT_EQ(cal["subimages"].size(), 6u);
  for (const auto& s : cal["subimages"]) {
    const calib::SubimageMapping& m = truth.subimages[truth.SubimageIndex(s["id"])];
    for (size_t e = 0; e < 6; ++e) {
      if (s["sigma"][e].is_null()) {
        EXPECT_EQ(s["id"], "A");
        continue;
      }
      const double error = s["params"][e].get<double>() - m.params[e];
      EXPECT_LE(std::abs(error), 3.0 * s["sigma"][e].get<double>()) << s["id"] << " " << e;
      const std::string name =
          s["id"].get<std::string>() + "." + s["param_names"][e].get<std::string>();
      ASSERT_TRUE(budget.count(name)) << name;
      EXPECT_NEAR(budget[name]["U"].get<double>(),
                  budget[name]["k"].get<double>() * s["sigma"][e].get<double>(),
                  1e-12);
    }
  }
  EXPECT_TRUE(budget.count("c"));
  EXPECT_TRUE(budget.count("B.a0"));
  // --write-camera: the camera file's own format, read back with the estimated mappings.
  const calib::Camera written = calib::ReadCamera(tmp.File("calibrated.yaml"));
  ASSERT_EQ(written.subimages.size(), 6u);
  EXPECT_NEAR(written.interior[0], j["cameras"][0]["estimated"]["c"].get<double>(), 1e-12);
  for (const auto& s : cal["subimages"])
    for (size_t e = 0; e < 6; ++e)
      EXPECT_NEAR(written.subimages[written.SubimageIndex(s["id"])].params[e],
                  s["params"][e].get<double>(),
                  1e-9);
  // The certificate: the method, the virtual camera's budget and every sub-image's mapping with U.
  const auto c = RunAerocal("certificate --result " + tmp.File("result.json") + " --out " +
                            tmp.File("cert") + " --no-render");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const nlohmann::json cert = ReadJson(tmp.File("cert/certificate.json"));
  EXPECT_EQ(cert["method"]["kind"], "collimator array");
  EXPECT_EQ(cert["units"].size(), 6u);
  EXPECT_EQ(cert["results"].size(), cal["uncertainty"].size());
  EXPECT_NE(c.output.find("B.a0 = "), std::string::npos) << c.output;
}

TEST(CalibrateDirections, MultiCcdTwoSeriesAsGroupsAndBadSubimageRows) {
  TempDir tmp("aerocal_directions_multi_ccd_groups");
  std::mt19937_64 rng(3616);
  WriteText(tmp.File("camera.yaml"), MultiCcdYaml());
  const std::string header =
      "target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,unit,group\n";
  WriteText(tmp.File("directions.csv"),
            header + MultiCcdRows(&rng, "monday") + MultiCcdRows(&rng, "tuesday"));
  const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                            tmp.File("directions.csv") + " --out " + tmp.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto cal = ReadJson(tmp.File("result.json"))["calibration"];
  EXPECT_EQ(cal["groups"].size(), 2u);
  EXPECT_EQ(cal["stability"]["rows"].size(), 8u);  // the virtual camera's free interior
  EXPECT_TRUE(cal["stability"]["agree"].get<bool>());

  // Bad rows name FILE:LINE, bad options their name; nothing is written.
  const std::string head = kRigHeader + std::string("X1,1000,1000,0.05,0,0,0.5,A\n");
  struct Case {
    std::string text, extra, message;
  };
  const Case cases[] = {
      {head + "X2,1000,1000,0.05,1,0,0.5,Q\n", "", "bad.csv:3: unit Q is not a unit of"},
      {head + "X2,1000,2500,0.05,1,0,0.5,B\n", "", "bad.csv:3: column 'row' out of range"},
      {head + "X2,1000,1000,0.05,1,0,0.5,\n", "", "bad.csv:3: unit must not be empty"},
      {kRigHeader + std::string("X1,1000,1000,0.05,0,0,0.5,A\nX2,1000,1500,0.05,0,2,0.5,A\n"),
       "",
       "bad.csv:2: sub-image A: 2 directions (4 scalar) cannot determine its 6"},
      {head, "--model opencv", "--model"},
      {head, "--camera-format opencv", "--camera-format"},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.message);
    WriteText(tmp.File("bad.csv"), k.text);
    const auto b = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --directions " +
                              tmp.File("bad.csv") + " --out " + tmp.File("bad.json") +
                              " --write-camera " + tmp.File("bad.yaml") + " " + k.extra);
    EXPECT_EQ(b.exit_code, 2) << b.output;
    EXPECT_NE(b.output.find(k.message), std::string::npos) << b.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("bad.json")));
    EXPECT_FALSE(std::filesystem::exists(tmp.File("bad.yaml")));
  }
}

TEST(CalibrateDirections, BadUnitsNameTheirLineAndNothingIsWritten) {
  TempDir tmp("aerocal_directions_bad_units");
  std::mt19937_64 rng(3614);
  WriteText(tmp.File("rig.yaml"), RigYaml());
  WriteText(tmp.File("camera.yaml"), kCameraYaml);
  const std::vector<std::string> rows = RigRows(&rng);
  const std::string ab = kRigHeader + rows[0] + rows[1];
  const int next = 2 + static_cast<int>(std::count(ab.begin(), ab.end(), '\n')) - 1;
  const std::string line = "directions.csv:" + std::to_string(next) + ": ";
  struct Case {
    std::string camera, text, message;
  };
  const Case cases[] = {
      {"rig.yaml", ab + "Z,3000,2000,0.05,0,0,0.5,D\n", line + "unit D is not a unit of"},
      {"rig.yaml", ab + "Z,3000,2000,0.05,0,0,0.5,\n", line + "unit must not be empty"},
      {"rig.yaml",
       ab + "Z1,3000,2000,0.05,20,0,0.5,C\nZ2,3000,1000,0.05,20,3,0.5,C\n"
            "Z3,3000,3000,0.05,20,-3,0.5,C\n",
       line + "unit C: 3 directions (6 scalar) cannot determine its 11 unknowns"},
      {"rig.yaml",
       "target,col,row,azimuth_deg,elevation_deg\nA,3000,2000,0,0\n",
       "directions.csv:1: no 'unit' column"},
      {"camera.yaml",
       "target,col,row,azimuth_deg,elevation_deg,unit\nA,3000,2000,0,0,\nB,4000,2000,6.8,0,A\n",
       "directions.csv:3: unit A: the camera file is one camera"},
      {"rig.yaml",
       "target,col,row,azimuth_deg,elevation_deg,unit,group\nA,3000,2000,0,0,A,g1\n",
       "directions.csv:1: group: the groups' stability test of a rig's heads is not built"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message);
    WriteText(tmp.File("directions.csv"), c.text);
    const auto r = RunAerocal("calibrate --camera " + tmp.File(c.camera) + " --directions " +
                              tmp.File("directions.csv") + " --out " + tmp.File("result.json") +
                              " --write-camera " + tmp.File("written.yaml"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("result.json")));
    EXPECT_FALSE(std::filesystem::exists(tmp.File("written.yaml")));
  }
  // Options of a single camera are refused by name with a rig file.
  WriteText(tmp.File("directions.csv"), ab);
  for (const std::string& extra :
       {std::string("--model opencv"), std::string("--camera-format opencv")}) {
    const auto r =
        RunAerocal("calibrate --camera " + tmp.File("rig.yaml") + " --directions " +
                   tmp.File("directions.csv") + " --out " + tmp.File("result.json") + " " + extra);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(extra.substr(0, extra.find(' '))), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace aerocal
