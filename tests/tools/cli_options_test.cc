// Options the READMEs name that no other CLI test runs: `stitch --model auto --alpha` and
// `import dbat` (then `adjust` on the imported block, against DBAT's published calibration);
// the platform's weighted and boresight options, `--critical-value`, `--correlation-threshold`;
// `calibrate --no-closed-form --radii-mm --budget --board-sigma-mm`; `simulate --test-field
// --distance-m`; `rig error-analysis --bins`. Each against what the math must give.
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

namespace aerocal {
namespace {

using testing::RunAerocal;

TEST(CliOptions, StitchModelAutoTestsAtTheGivenAlpha) {
  testing::TempDir dir("aerocal_cli_options");
  ASSERT_EQ(RunAerocal("simulate --out " + dir.File("data") +
                       " --exposures 2 --strips 1 --surveyed-points 20 --tie-points 30 "
                       "--stitch-ties 300 --ccd-shear 2e-4")
                .exit_code,
            0);
  const auto run =
      RunAerocal("stitch --camera " + dir.File("data/camera_nominal.yaml") + " --obs " +
                 dir.File("data/stitch_obs.csv") +
                 " --model auto --alpha 0.01 --base III,IV --out " + dir.File("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto doc = aerocal::testing::ReadJson(dir.File("r.json"));
  ASSERT_EQ(doc["frames"].size(), 2u);
  for (const auto& frame : doc["frames"]) {
    EXPECT_EQ(frame["model_choice"]["alpha"].get<double>(), 0.01);
    EXPECT_NE(frame["model_choice"]["test"].get<std::string>().find("alpha 0.01"),
              std::string::npos);
    // CCD shears of 2e-4 (0.7 px across a sub-image): at 1 % the F test still accepts affine over
    // conformal with 300 ties per frame (with the default 2e-5 it keeps conformal).
    EXPECT_EQ(frame["model"], "affine") << frame["model_choice"]["reason"];
  }
  const auto bad =
      RunAerocal("stitch --camera " + dir.File("data/camera_nominal.yaml") + " --obs " +
                 dir.File("data/stitch_obs.csv") + " --alpha 2 --out " + dir.File("bad.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--alpha"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad.json")));
}

// The DBAT camcal demo imported as a block (the published run: the four control points fixed, 1
// um).
testing::CommandResult ImportDbatCamcal(const std::string& data, const testing::TempDir& dir) {
  return RunAerocal("import dbat --camera-xml " + data + "/c4040z.xml --marks " + data +
                    "/measurements/markpts.txt --images " + data + "/images/images.txt --control " +
                    data +
                    "/reference/camcal-fixed.txt --control-sigma-m 1e-6 --photomodeler-export " +
                    data + "/photomodeler/camcal-pmexport.txt --out " + dir.File("block"));
}

TEST(CliOptions, ImportDbatThenAdjustGivesThePublishedCalibration) {
  const std::string data = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (data.empty()) GTEST_SKIP() << "../shared/data/dbat_camcal_olympus_c4040z is absent";
  testing::TempDir dir("aerocal_cli_dbat");
  // The published run holds the four control points fixed (camcal-fixed.txt): 1 um here.
  const auto imported = ImportDbatCamcal(data, dir);
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto adjusted = RunAerocal(
      "adjust --project " + dir.File("block/project.yaml") +
      " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping --out " + dir.File("r.json"));
  ASSERT_EQ(adjusted.exit_code, 0) << adjusted.output;
  const auto doc = aerocal::testing::ReadJson(dir.File("r.json"));
  // Published (DBAT 0.9.2.0): c 7.45700 (0.00105) mm, sigma0 0.16148 px.
  const auto& camera = doc["cameras"][0];
  EXPECT_LT(std::abs(camera["estimated"]["c"].get<double>() - 7.45700),
            3.0 * camera["sigma"]["c"].get<double>());
  EXPECT_NEAR(doc["sigma0_px"].get<double>() / 0.16148, 1.0, 0.10);
}

TEST(CliOptions, AdjustWritesTheCameraInAnotherToolsFormat) {
  // --write-camera with --camera-format: the DBAT test field's self-calibration written as an
  // Australis report (the same model: exact, the sigmas carried) and as a PhotoModeler camera
  // (no B1: a fit whose residual is printed), both read back by `camera show`.
  const std::string data = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (data.empty()) GTEST_SKIP() << "../shared/data/dbat_camcal_olympus_c4040z is absent";
  testing::TempDir dir("aerocal_cli_camera_format");
  const auto imported = ImportDbatCamcal(data, dir);
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const std::string adjust = "adjust --project " + dir.File("block/project.yaml") +
                             " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping --out ";
  auto r = RunAerocal(adjust + dir.File("a.json") + " --write-camera " + dir.File("cam.aus.txt") +
                      " --camera-format australis");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("camera as australis (brown_fraser_10): exact"), std::string::npos)
      << r.output;
  const auto doc = aerocal::testing::ReadJson(dir.File("a.json"));
  const double c = doc["cameras"][0]["estimated"]["c"].get<double>();
  const double sigma_c = doc["cameras"][0]["sigma"]["c"].get<double>();
  auto shown = RunAerocal("camera show --from australis " + dir.File("cam.aus.txt"));
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  // The table prints c with 15 digits and its sigma with 6.
  char c_text[64], sigma_text[64];
  std::snprintf(c_text, sizeof(c_text), "%.6f", c);
  std::snprintf(sigma_text, sizeof(sigma_text), "%.4g", sigma_c);
  EXPECT_NE(shown.output.find(std::string(c_text).substr(0, 7)), std::string::npos) << shown.output;
  EXPECT_NE(shown.output.find(std::string(sigma_text).substr(0, 5)), std::string::npos)
      << shown.output;
  r = RunAerocal(adjust + dir.File("b.json") + " --write-camera " + dir.File("cam.pm.txt") +
                 " --camera-format photomodeler");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("least-squares fit over the format"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("interior sigmas not written"), std::string::npos) << r.output;
  shown = RunAerocal("camera show --from photomodeler " + dir.File("cam.pm.txt"));
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("2272 x 1704 px"), std::string::npos) << shown.output;
}

// One simulated flight with a planted GNSS lever arm, IMU boresight and GNSS time offset.
class PlatformFlight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("aerocal_cli_platform");
    const auto sim = RunAerocal(
        "simulate --seed 6 --gnss-sigma-m 0.05 --imu-sigma-deg 0.005 --speed-mps 70 "
        "--lever-arm-m 0.15,-0.25,1.3 --boresight-deg 0.05,-0.03,0.1 "
        "--gnss-time-offset-ms 20 --out " +
        dir_->File("flight"));
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static nlohmann::json Adjust(const std::string& options, const std::string& name) {
    const auto r = RunAerocal("adjust --project " + dir_->File("flight") +
                              " --self-calibration all " + options + " --out " + dir_->File(name));
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return r.exit_code == 0 ? testing::ReadJson(dir_->File(name)) : nlohmann::json::object();
  }
  static inline testing::TempDir* dir_ = nullptr;
};

// |value - truth| <= 3 sigma for each component; each a-posteriori sigma at most the prior sigma
// scaled by sigma0 (a weighted parameter is known at least as well as its prior says).
void ExpectRecovered(const nlohmann::json& entry,
                     const std::vector<double>& truth,
                     double prior_sigma,
                     double sigma0) {
  for (size_t i = 0; i < truth.size(); ++i) {
    const double sigma = entry["sigma"][i].get<double>();
    EXPECT_LE(std::abs(entry["value"][i].get<double>() - truth[i]), 3.0 * sigma) << i;
    if (prior_sigma > 0) {
      EXPECT_LE(sigma, prior_sigma * std::max(1.0, sigma0) * (1 + 1e-9)) << i;
    }
  }
}

TEST_F(PlatformFlight, WeightedLeverArmAndTimeOffsetWithAFreeBoresight) {
  const auto j = Adjust(
      "--lever-arm weighted --lever-arm-m 0.15,-0.25,1.3 --lever-arm-sigma-m 0.02 "
      "--gnss-time-offset weighted --gnss-time-offset-ms 20 --gnss-time-offset-sigma-ms 5 "
      "--boresight free",
      "weighted.json");
  ASSERT_TRUE(j.contains("platform"));
  const double sigma0 = j["sigma0"].get<double>();
  EXPECT_EQ(j["platform"]["lever_arm_m"]["mode"], "weighted");
  ExpectRecovered(j["platform"]["lever_arm_m"], {0.15, -0.25, 1.3}, 0.02, sigma0);
  ExpectRecovered(j["platform"]["time_offset_ms"], {20.0}, 5.0, sigma0);
  EXPECT_EQ(j["platform"]["boresight_deg"]["mode"], "free");
  ExpectRecovered(j["platform"]["boresight_deg"], {0.05, -0.03, 0.1}, 0.0, sigma0);
}

TEST_F(PlatformFlight, WeightedBoresightKeepsItsPriorSigma) {
  const auto j =
      Adjust("--boresight weighted --boresight-deg 0.05,-0.03,0.1 --boresight-sigma-deg 0.001",
             "boresight.json");
  ASSERT_TRUE(j.contains("platform"));
  EXPECT_EQ(j["platform"]["boresight_deg"]["mode"], "weighted");
  ExpectRecovered(
      j["platform"]["boresight_deg"], {0.05, -0.03, 0.1}, 0.001, j["sigma0"].get<double>());
}

TEST(CliOptions, CriticalValueDecidesWhatSnoopingRejects) {
  // One image coordinate moved by 25 px (125 sigma): the default test rejects exactly that
  // observation; a critical value of 1e6 rejects nothing and sigma0 carries the blunder.
  testing::TempDir dir("aerocal_cli_critical");
  ASSERT_EQ(RunAerocal("simulate --seed 5 --out " + dir.File("s")).exit_code, 0);
  std::ifstream in(dir.File("s/observations.csv"));
  std::string header, line, text;
  std::getline(in, header);
  text = header + "\n";
  std::string image, point;
  for (int n = 0; std::getline(in, line); ++n) {
    if (n == 199) {  // image,point,col,row,sigma_px
      const auto c1 = line.find(','), c2 = line.find(',', c1 + 1), c3 = line.find(',', c2 + 1);
      image = line.substr(0, c1);
      point = line.substr(c1 + 1, c2 - c1 - 1);
      line = line.substr(0, c2 + 1) +
             std::to_string(std::stod(line.substr(c2 + 1, c3 - c2 - 1)) + 25.0) + line.substr(c3);
    }
    text += line + "\n";
  }
  ASSERT_EQ(header, "image,point,col,row,sigma_px");
  WriteFileAtomically(dir.File("s/observations.csv"), text);
  const std::string adjust =
      "adjust --project " + dir.File("s/project.yaml") + " --self-calibration all ";
  auto r = RunAerocal(adjust + "--out " + dir.File("default.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto d = testing::ReadJson(dir.File("default.json"));
  ASSERT_EQ(d["rejected"].size(), 1u) << d["rejected"].dump();
  EXPECT_EQ(d["rejected"][0]["image"], image);
  EXPECT_EQ(d["rejected"][0]["point"], point);
  r = RunAerocal(adjust + "--critical-value 1e6 --out " + dir.File("loose.json"));
  const auto loose = testing::ReadJson(dir.File("loose.json"));
  EXPECT_TRUE(loose["rejected"].empty());
  EXPECT_GT(loose["sigma0"].get<double>(), 1.5 * d["sigma0"].get<double>());
}

TEST(CliOptions, CorrelationThresholdSelectsTheReportedCorrelations) {
  testing::TempDir dir("aerocal_cli_correlation");
  ASSERT_EQ(RunAerocal("simulate --seed 5 --out " + dir.File("s")).exit_code, 0);
  std::map<double, size_t> count;
  for (const double t : {0.3, 0.95}) {
    const std::string out = dir.File("c" + std::to_string(t) + ".json");
    const auto r = RunAerocal("adjust --project " + dir.File("s/project.yaml") +
                              " --self-calibration all --correlation-threshold " +
                              std::to_string(t) + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const nlohmann::json result = testing::ReadJson(out);
    const nlohmann::json& high = result["determinability"]["high_correlations"];
    for (const auto& h : high) EXPECT_GT(std::abs(h["correlation"].get<double>()), t) << h.dump();
    count[t] = high.size();
  }
  EXPECT_GT(count[0.3], count[0.95]);
  EXPECT_GT(count[0.95], 0u);  // c with the centres' Z at least
}

TEST(CliOptions, TestFieldDistanceNoClosedFormRadiiAndBudget) {
  testing::TempDir dir("aerocal_cli_testfield");
  // --distance-m: the stations stand that far in front of the facade (Y = 0), up to the jitter.
  ASSERT_EQ(
      RunAerocal(
          "simulate --test-field --planar --images-per-group 8 --distance-m 12 --seed 2 --out " +
          dir.File("tf"))
          .exit_code,
      0);
  const CsvTable stations = CsvTable::Read(dir.File("tf/truth/exposures.csv"));
  double mean = 0;
  for (const auto& row : stations.rows())
    mean += std::abs(stations.Number(row, "Y")) / stations.rows().size();
  EXPECT_NEAR(mean, 12.0, 0.5);
  const std::string calibrate = "calibrate --camera " + dir.File("tf/camera_nominal.yaml") +
                                " --observations " + dir.File("tf/observations.csv") +
                                " --points " + dir.File("tf/points.csv") + " --groups " +
                                dir.File("tf/groups.csv") + " ";
  ASSERT_EQ(RunAerocal(calibrate + "--out " + dir.File("a.json")).exit_code, 0);
  const auto a = testing::ReadJson(dir.File("a.json"));
  // --no-closed-form: no Zhang start (null), the same minimum; --radii-mm: those radii.
  ASSERT_EQ(RunAerocal(calibrate + "--no-closed-form --radii-mm 3 6 --out " + dir.File("b.json"))
                .exit_code,
            0);
  const auto b = testing::ReadJson(dir.File("b.json"));
  EXPECT_TRUE(a["calibration"]["start"]["c_closed_form_mm"].is_number());
  EXPECT_TRUE(b["calibration"]["start"]["c_closed_form_mm"].is_null());
  EXPECT_NEAR(a["cameras"][0]["estimated"]["c"].get<double>(),
              b["cameras"][0]["estimated"]["c"].get<double>(),
              1e-6);
  EXPECT_EQ(b["calibration"]["radii_mm"], nlohmann::json::array({3.0, 6.0}));
  std::vector<std::string> names;
  for (const auto& q : b["calibration"]["uncertainty"]) names.push_back(q["quantity"]);
  for (const char* q : {"dr@3", "dt@3", "dr@6", "dt@6"})
    EXPECT_NE(std::find(names.begin(), names.end(), q), names.end()) << q;
  // --budget: a rectangular user component of half-width 0.002 mm on c adds (0.002 / sqrt 3)^2
  // to the variance of c (GUM 4.3.7; sensitivity 1).
  WriteFileAtomically(dir.File("budget.yaml"),
                      "components:\n  - {quantity: c, source: temperature, value: 0.002, "
                      "unit: mm, distribution: rectangular, sensitivity: 1}\n");
  ASSERT_EQ(
      RunAerocal(calibrate + "--budget " + dir.File("budget.yaml") + " --out " + dir.File("c.json"))
          .exit_code,
      0);
  const auto c = testing::ReadJson(dir.File("c.json"));
  const auto u_of_c = [](const nlohmann::json& j) {
    for (const auto& q : j["calibration"]["uncertainty"])
      if (q["quantity"] == "c") return q["u_c"].get<double>();
    return -1.0;
  };
  EXPECT_NEAR(u_of_c(c), std::hypot(u_of_c(a), 0.002 / std::sqrt(3.0)), 1e-9);
}

TEST(CliOptions, BoardSigmaWeighsTheBoardPoints) {
  // OpenCV's chessboard: the board's design coordinates as control of sigma --board-sigma-mm; a
  // looser board gives c a larger cofactor sigma (sigma / sigma0), and the run states the value.
  const std::string dir = testing::SharedDataDir("opencv_stereo_chessboard_9x6");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/opencv_stereo_chessboard_9x6 is absent";
  testing::TempDir tmp("aerocal_cli_board_sigma");
  WriteFileAtomically(
      tmp.File("camera.yaml"),
      "name: left\npixel_size_mm: 0.006\nformat_px: [640, 480]\ninterior: {c: 3.0}\n");
  std::map<double, double> cofactor_sigma_c;
  for (const double s : {0.01, 0.5}) {
    const std::string out = tmp.File("b" + std::to_string(s) + ".json");
    const auto r = RunAerocal("calibrate --camera " + tmp.File("camera.yaml") + " --images '" +
                              dir + "/left*.jpg' --board chessboard:9x6:25 --board-sigma-mm " +
                              std::to_string(s) + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const auto j = testing::ReadJson(out);
    EXPECT_DOUBLE_EQ(j["calibration"]["method"]["board_sigma_mm"].get<double>(), s);
    cofactor_sigma_c[s] = j["cameras"][0]["sigma"]["c"].get<double>() / j["sigma0"].get<double>();
  }
  EXPECT_GT(cofactor_sigma_c[0.5], 1.1 * cofactor_sigma_c[0.01]);
}

TEST(CliOptions, RigErrorAnalysisHistogramHasTheGivenBins) {
  // --bins 7: the Monte-Carlo histogram CSV has 7 bins per quantity, contiguous, whose counts add
  // up to the samples that did not fail.
  testing::TempDir dir("aerocal_cli_bins");
  const std::string configs = AEROCAL_CONFIGS_DIR;
  const auto r = RunAerocal(
      "rig error-analysis --camera " + configs + "/rig_dual_lens.yaml --limits " + configs +
      "/rig_dual_lens_limits.yaml --samples 2000 --bins 7 --no-plots --out " + dir.File("ea.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = testing::ReadJson(dir.File("ea.json"));
  // (the CSV is named relative to the result's folder)
  const CsvTable h = CsvTable::Read(dir.File(j["monte_carlo"]["histogram_csv"].get<std::string>()));
  std::map<std::string, std::vector<std::pair<double, double>>> bins;
  std::map<std::string, long> total;
  for (const auto& row : h.rows()) {
    const std::string q = h.String(row, "quantity");
    bins[q].emplace_back(h.Number(row, "bin_low_px"), h.Number(row, "bin_high_px"));
    total[q] += static_cast<long>(h.Number(row, "count"));
  }
  ASSERT_FALSE(bins.empty());
  const long used = 2000 - j["monte_carlo"]["failed"].get<long>();
  for (const auto& [q, b] : bins) {
    EXPECT_EQ(b.size(), 7u) << q;
    for (size_t i = 1; i < b.size(); ++i) EXPECT_DOUBLE_EQ(b[i].first, b[i - 1].second) << q;
    EXPECT_EQ(total[q], used) << q;
  }
}

}  // namespace
}  // namespace aerocal
