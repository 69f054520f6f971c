// `aerocal simulate --pushbroom` and `aerocal pushbroom calibrate`: the files a simulation writes,
// the calibration's JSON keys, the updated camera read back, every option of the command, the
// degenerate runs (exit 3, named warnings, no camera written) and bad input (exit 2, FILE:LINE,
// nothing written). Also the example camera of configs/.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "calib/camera/line_camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

namespace aerocal::triangulation {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;
using nlohmann::json;

const char* kSmall = " --detectors 60 --lines 400 --control 300 --seed 3";

std::string Calibrate(const std::string& dir, const std::string& extra) {
  return "pushbroom calibrate --camera " + dir + "/camera_nominal.yaml --pos " + dir +
         "/pos.csv --observations " + dir + "/observations.csv --points " + dir + "/points.csv " +
         extra;
}

TEST(PushbroomCommands, SimulateThenCalibrate) {
  TempDir dir;
  auto sim = RunAerocal("simulate --pushbroom --out " + dir.path() + kSmall +
                        " --tilt-deg 20 --pos-error-m 0.05 --pos-error-deg 0.005"
                        " --detector-error-px 0.5 --node-spacing 50 --control-noise-m 0.1"
                        " --image-noise-px 0.25 --image-sigma-px 0.25 --height-m 1000 --relief-m 80"
                        " --survey-sigma-m 0.1");
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  for (const char* f : {"camera_nominal.yaml", "camera_truth.yaml", "pos.csv", "pos_truth.csv",
                        "observations.csv", "points.csv", "points_truth.csv",
                        "truth_detectors.csv", "truth_trajectory.csv"})
    EXPECT_TRUE(std::filesystem::exists(dir.File(f))) << f;
  auto run = RunAerocal(Calibrate(dir.path(),
                                  "--out " + dir.File("result.json") + " --write-camera " +
                                      dir.File("calibrated.yaml") + " --lines " + dir.File("lines.csv") +
                                      " --node-spacing 50 --degree auto --max-degree 4 --degree-alpha 0.05"
                                      " --datum reference --reference -1 --pos-prior on"
                                      " --pos-sigma-m 0.05 --pos-sigma-deg 0.005 --sigma-px 0.25"
                                      " --min-per-segment 5"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json doc = json::parse(ReadTextFile(dir.File("result.json")));
  for (const char* key : {"kind", "sigma0", "sigma0_px", "redundancy", "iterations", "converged",
                          "valid", "subcameras", "detectors", "trajectory", "correlations",
                          "warnings", "c_mm", "c_sigma_mm"})
    EXPECT_TRUE(doc.contains(key)) << key;
  EXPECT_EQ(doc["kind"], "pushbroom");
  EXPECT_TRUE(doc["c_sigma_mm"].is_null()) << "c fixed: unknown sigma is null";
  ASSERT_EQ(doc["subcameras"].size(), 3u);
  for (const json& s : doc["subcameras"]) {
    EXPECT_LT(s["rms_after_px"]["across"].get<double>(), 0.35);
    EXPECT_LT(s["rms_after_px"]["along"].get<double>(), 0.35);
    EXPECT_GT(s["rms_before_px"]["across"].get<double>(), s["rms_after_px"]["across"].get<double>());
    EXPECT_LE(s["degree_x"].get<int>(), 4);
  }
  EXPECT_EQ(doc["detectors"].size(), 180u);
  const calib::LineCamera cam = calib::ReadLineCamera(dir.File("calibrated.yaml"));
  EXPECT_EQ(cam.calibration.size(), 3u);
  EXPECT_TRUE(std::filesystem::exists(dir.File("lines.csv")));

  // A fixed degree and c free: the scale is named; exit 3 only when ill-posed beyond 0.999.
  auto c_run = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("c.json") + " --free-c --degree 3"));
  ASSERT_TRUE(c_run.exit_code == 0 || c_run.exit_code == 3) << c_run.output;
  EXPECT_NE(c_run.output.find("correlation scale_vs_c"), std::string::npos) << c_run.output;

  // No datum, no POS prior: ill-posed by name, exit 3, no camera written.
  auto bad = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("none.json") +
                                                  " --datum none --pos-prior off --write-camera " +
                                                  dir.File("none.yaml")));
  EXPECT_EQ(bad.exit_code, 3) << bad.output;
  EXPECT_TRUE(bad.output.find("warning: offset_vs_pitch") != std::string::npos ||
              bad.output.find("warning: undetermined") != std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("none.yaml")));
  EXPECT_EQ(json::parse(ReadTextFile(dir.File("none.json")))["valid"], false);
}

TEST(PushbroomCommands, BadInputIsRefusedWithFileAndLine) {
  TempDir dir;
  ASSERT_EQ(RunAerocal("simulate --pushbroom --out " + dir.path() + kSmall).exit_code, 0);
  // An observation beyond the POS lines.
  std::string obs = ReadTextFile(dir.File("observations.csv"));
  obs += "strip,c1,10,99999,0.25\n";
  const int bad_line = int(std::count(obs.begin(), obs.end(), '\n'));
  std::ofstream(dir.File("obs_bad.csv")) << obs;
  auto run = RunAerocal("pushbroom calibrate --camera " + dir.File("camera_nominal.yaml") + " --pos " +
                        dir.File("pos.csv") + " --observations " + dir.File("obs_bad.csv") +
                        " --points " + dir.File("points.csv") + " --out " + dir.File("r.json"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("obs_bad.csv:" + std::to_string(bad_line) + ": row (scan line) 99999"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
  // A bad option.
  run = RunAerocal(Calibrate(dir.path(), "--out " + dir.File("r.json") + " --degree 7"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("--degree"), std::string::npos) << run.output;
  // A bad camera file line.
  std::ofstream(dir.File("cam.yaml")) << "line:\n  detectors: 180\n  pitch_mm: 0.01\n  c: -3\n";
  run = RunAerocal("pushbroom calibrate --camera " + dir.File("cam.yaml") + " --pos " +
                   dir.File("pos.csv") + " --observations " + dir.File("observations.csv") +
                   " --points " + dir.File("points.csv") + " --out " + dir.File("r.json"));
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("cam.yaml:4: line.c must be within"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("r.json")));
}

TEST(PushbroomCommands, ExampleCameraOfConfigsIsRead) {
  const calib::LineCamera cam =
      calib::ReadLineCamera(std::string(AEROCAL_CONFIGS_DIR) + "/line_camera_three.yaml");
  EXPECT_EQ(cam.subcameras.size(), 3u);
  EXPECT_EQ(cam.detectors, 3000);
}

}  // namespace
}  // namespace aerocal::triangulation
