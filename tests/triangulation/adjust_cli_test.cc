// aerocal adjust on the simulated example flight: exit codes, result keys, --compare,
// --write-camera (the in-flight calibration loop), bad input with nothing written.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace aerocal {
namespace {

using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

class AdjustCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto r = RunAerocal("simulate --out " + dir_.File("flight"));
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
  TempDir dir_{"aerocal_adjust_cli"};
};

TEST_F(AdjustCommand, CompareWritesBothRunsAndTheCamera) {
  const auto r = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                            " --mkdir --compare --write-camera " + dir_.File("next/camera.yaml") +
                            " --out " + dir_.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("conventional"), std::string::npos);
  EXPECT_NE(r.output.find("check RMSE Z"), std::string::npos);
  EXPECT_NE(r.output.find("is not separable"), std::string::npos);  // c ~ heights, no GNSS
  const auto j = ReadJson(dir_.File("result.json"));
  for (const char* key : {"kind",
                          "sigma0",
                          "sigma0_px",
                          "sigma0_um",
                          "redundancy",
                          "iterations",
                          "converged",
                          "cameras",
                          "control",
                          "check",
                          "exposures",
                          "rejected",
                          "comparison",
                          "frame"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["converged"].get<bool>());
  const auto& cmp = j["comparison"];
  EXPECT_GE(cmp["check_spatial_rmse_ratio"].get<double>(), 1.5);
  EXPECT_EQ(cmp["calibration"].size(), 10u);
  // Each free parameter carries its test statistic |correction| / sigma. Without GNSS, c is
  // tied to the flying heights (sigma ~0.3 mm): its 0.04 mm correction cannot be significant.
  for (const auto& row : cmp["calibration"]) {
    if (row["sigma"].is_null()) continue;
    EXPECT_NEAR(row["t"].get<double>(),
                std::abs(row["correction"].get<double>()) / row["sigma"].get<double>(),
                1e-9 * (1 + row["t"].get<double>()));
    if (row["parameter"] == "c") {
      EXPECT_LT(row["t"].get<double>(), 1.96);
    }
  }
  // The written camera holds the estimate and carries the sub-images along.
  const calib::Camera camera = calib::ReadCamera(dir_.File("next/camera.yaml"));
  const calib::Camera nominal = calib::ReadCamera(dir_.File("flight/camera_nominal.yaml"));
  EXPECT_NEAR(camera.c_mm(), j["cameras"][0]["estimated"]["c"].get<double>(), 1e-9);
  EXPECT_EQ(camera.subimages.size(), nominal.subimages.size());
  // Next run from the written camera: the conventional adjustment now fits like the calibrated one.
  std::string project = ReadTextFile(dir_.File("flight/project.yaml"));
  project.replace(project.find("camera_nominal.yaml"), 19, dir_.File("next/camera.yaml"));
  WriteFileAtomically(dir_.File("flight/project_next.yaml"), project);
  const auto next = RunAerocal("adjust --project " + dir_.File("flight/project_next.yaml") +
                               " --out " + dir_.File("next.json"));
  ASSERT_EQ(next.exit_code, 0) << next.output;
  const auto n = ReadJson(dir_.File("next.json"));
  EXPECT_NEAR(n["check"]["spatial_rmse_m"].get<double>(),
              cmp["self_calibration"]["check"]["spatial_rmse_m"].get<double>(),
              0.05);
}

TEST_F(AdjustCommand, BadInputExitsTwoAndWritesNothing) {
  std::ofstream(dir_.File("flight/exposures.csv"), std::ios::app) << "0099,cam1,1,2,x,0,0,0\n";
  const auto r = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                            " --self-calibration all --out " + dir_.File("bad.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("exposures.csv:39"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.File("bad.json")));
  const auto unknown = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                                  " --self-calibration c,k1 --out " + dir_.File("bad.json"));
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.File("bad.json")));
}

TEST_F(AdjustCommand, NotConvergedExitsThreeWithTheResultWritten) {
  const auto r = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                            " --self-calibration all --max-iterations 1 --write-camera " +
                            dir_.File("cam.yaml") + " --out " + dir_.File("r.json"));
  EXPECT_EQ(r.exit_code, 3) << r.output;
  EXPECT_FALSE(ReadJson(dir_.File("r.json"))["converged"].get<bool>());
  EXPECT_FALSE(std::filesystem::exists(dir_.File("cam.yaml")));
}

// Issue 31: --threads chooses the solver's threads; the adjustment is the same bits for every
// count.
TEST_F(AdjustCommand, ThreadsGiveTheSameResultAndANegativeCountIsRefused) {
  const std::string base = "adjust --project " + dir_.File("flight/project.yaml") +
                           " --self-calibration all --no-snooping --threads ";
  const auto one = RunAerocal(base + "1 --out " + dir_.File("one.json"));
  const auto two = RunAerocal(base + "2 --out " + dir_.File("two.json"));
  ASSERT_EQ(one.exit_code, 0) << one.output;
  ASSERT_EQ(two.exit_code, 0) << two.output;
  const auto a = ReadJson(dir_.File("one.json")), b = ReadJson(dir_.File("two.json"));
  for (const char* key : {"sigma0", "cameras", "exposures", "residuals"})
    EXPECT_EQ(a[key], b[key]) << key;
  const auto bad = RunAerocal(base + "-1 --out " + dir_.File("bad.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--threads"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_.File("bad.json")));
}

// Issue 28: an image id that starts with '#' ('#0001') was read as a comment, and the exposure and
// its observations vanished with exit 0. It is an id: the exposure is adjusted under its name. An
// exposure no observation names is named in the notes, never silently unused.
TEST_F(AdjustCommand, AnImageIdStartingWithHashIsAdjustedAndAnUnobservedImageIsNamed) {
  auto rename = [&](const std::string& file) {
    std::string text = ReadTextFile(dir_.File("flight/" + file));
    std::string out;
    size_t begin = 0;
    while (begin < text.size()) {  // every line that starts with the id 0001
      const size_t end = text.find('\n', begin);
      std::string line =
          text.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
      if (line.rfind("0001,", 0) == 0) line = "#" + line;
      out += line + "\n";
      if (end == std::string::npos) break;
      begin = end + 1;
    }
    WriteFileAtomically(dir_.File("flight/" + file), out);
  };
  rename("exposures.csv");
  rename("observations.csv");
  // One more exposure that no observation names.
  std::string exposures = ReadTextFile(dir_.File("flight/exposures.csv"));
  const size_t first_row = exposures.find("#0001,");
  ASSERT_NE(first_row, std::string::npos);
  const std::string row = exposures.substr(first_row, exposures.find('\n', first_row) - first_row);
  exposures += "9999" + row.substr(5) + "\n";
  WriteFileAtomically(dir_.File("flight/exposures.csv"), exposures);
  const auto r = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") + " --out " +
                            dir_.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(dir_.File("result.json"));
  bool hash_used = false;
  for (const auto& e : j["exposures"])
    if (e["image"] == "#0001") hash_used = e["used"].get<bool>();
  EXPECT_TRUE(hash_used) << "exposure #0001 not adjusted";
  bool named = false;
  for (const auto& note : j["notes"])
    named = named || note.get<std::string>().find("image 9999") != std::string::npos;
  EXPECT_TRUE(named) << j["notes"].dump();
}

// Issue 28: --self-calibration auto names what it holds and why; --suspect-effect-limit is
// range-checked by name (NaN, zero, negative and huge values refused with exit 2, nothing written).
TEST_F(AdjustCommand, SelfCalibrationAutoAndTheSuspectEffectLimit) {
  const auto r = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                            " --self-calibration auto --suspect-effect-limit 2 --out " +
                            dir_.File("auto.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(dir_.File("auto.json"));
  ASSERT_TRUE(j.contains("self_calibration_choice")) << j.dump().substr(0, 300);
  const auto& choice = j["self_calibration_choice"];
  EXPECT_EQ(choice["candidates"].size(), 10u);
  EXPECT_EQ(choice["chosen"].size() + choice["held"].size(), 10u);
  for (const auto& h : choice["held"]) EXPECT_FALSE(h["reason"].get<std::string>().empty());
  // Without GNSS the simulated flight cannot separate c from the flying heights.
  bool c_held = false;
  for (const auto& h : choice["held"]) c_held = c_held || h["parameter"] == "c";
  EXPECT_TRUE(c_held) << choice.dump();
  for (const char* bad : {"0", "-1", "nan", "inf", "1e9"}) {
    const auto b = RunAerocal("adjust --project " + dir_.File("flight/project.yaml") +
                              " --suspect-effect-limit " + bad + " --out " + dir_.File("bad.json"));
    EXPECT_EQ(b.exit_code, 2) << bad << ": " << b.output;
    EXPECT_NE(b.output.find("suspect"), std::string::npos) << b.output;
    EXPECT_FALSE(std::filesystem::exists(dir_.File("bad.json")));
  }
}

// The GNSS/IMU platform: simulate plants a lever arm and a GNSS time offset, adjust estimates
// them (options over the project YAML) and writes them with sigmas; a bad mode is exit 2.
TEST(AdjustPlatform, SimulatedLeverArmAndTimeOffsetComeBack) {
  TempDir dir{"aerocal_adjust_platform"};
  const auto sim = RunAerocal(
      "simulate --gnss-sigma-m 0.05 --speed-mps 70 --lever-arm-m "
      "0.15,-0.25,1.3 --gnss-time-offset-ms 20 --out " +
      dir.File("flight"));
  ASSERT_EQ(sim.exit_code, 0) << sim.output;
  const auto r = RunAerocal("adjust --project " + dir.File("flight") +
                            " --self-calibration all --lever-arm free --gnss-time-offset free "
                            "--out " +
                            dir.File("result.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(dir.File("result.json"));
  ASSERT_TRUE(j.contains("platform")) << j.dump().substr(0, 400);
  const auto& lever = j["platform"]["lever_arm_m"];
  EXPECT_EQ(lever["mode"], "free");
  const double truth[3] = {0.15, -0.25, 1.3};
  for (int i = 0; i < 3; ++i)
    EXPECT_LE(std::abs(lever["value"][i].get<double>() - truth[i]),
              3.0 * lever["sigma"][i].get<double>())
        << i;
  const auto& dt = j["platform"]["time_offset_ms"];
  EXPECT_LE(std::abs(dt["value"][0].get<double>() - 20.0), 3.0 * dt["sigma"][0].get<double>());
  // A mode that is not one of fixed | free | weighted: exit 2, nothing written.
  const auto bad = RunAerocal("adjust --project " + dir.File("flight") +
                              " --lever-arm loose --out " + dir.File("bad.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--lever-arm"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad.json")));
  // Weighted without a sigma: named, exit 2.
  const auto no_sigma = RunAerocal("adjust --project " + dir.File("flight") +
                                   " --gnss-time-offset weighted --out " + dir.File("bad.json"));
  EXPECT_EQ(no_sigma.exit_code, 2) << no_sigma.output;
  EXPECT_NE(no_sigma.output.find("time_offset_sigma_ms"), std::string::npos) << no_sigma.output;
}

}  // namespace
}  // namespace aerocal
