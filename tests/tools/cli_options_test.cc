// Options the READMEs name that no other CLI test runs: `stitch --model auto --alpha` and
// `import dbat` (then `adjust` on the imported block, against DBAT's published calibration).
#include <filesystem>

#include <cstdio>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

namespace aerocal {
namespace {

using testing::RunAerocal;

TEST(CliOptions, StitchModelAutoTestsAtTheGivenAlpha) {
  testing::TempDir dir("aerocal_cli_options");
  ASSERT_EQ(RunAerocal("simulate --out " + dir.File("data") +
                       " --exposures 2 --strips 1 --points 20 --tie-points 30 --stitch-ties 300 --ccd-shear 2e-4")
                .exit_code,
            0);
  const auto run = RunAerocal("stitch --camera " + dir.File("data/camera_nominal.yaml") + " --obs " +
                              dir.File("data/stitch_obs.csv") + " --model auto --alpha 0.01 --base III,IV --out " +
                              dir.File("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto doc = nlohmann::json::parse(ReadTextFile(dir.File("r.json")));
  ASSERT_EQ(doc["frames"].size(), 2u);
  for (const auto& frame : doc["frames"]) {
    EXPECT_EQ(frame["model_choice"]["alpha"].get<double>(), 0.01);
    EXPECT_NE(frame["model_choice"]["test"].get<std::string>().find("alpha 0.01"), std::string::npos);
    // CCD shears of 2e-4 (0.7 px across a sub-image): at 1 % the F test still accepts affine over
    // conformal with 300 ties per frame (with the default 2e-5 it keeps conformal).
    EXPECT_EQ(frame["model"], "affine") << frame["model_choice"]["reason"];
  }
  const auto bad = RunAerocal("stitch --camera " + dir.File("data/camera_nominal.yaml") + " --obs " +
                              dir.File("data/stitch_obs.csv") + " --alpha 2 --out " + dir.File("bad.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--alpha"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("bad.json")));
}

// The DBAT camcal demo imported as a block (the published run: the four control points fixed, 1 um).
testing::CommandResult ImportDbatCamcal(const std::string& data, const testing::TempDir& dir) {
  return RunAerocal("import dbat --camera-xml " + data + "/c4040z.xml --marks " + data +
                    "/measurements/markpts.txt --images " + data + "/images/images.txt --control " +
                    data + "/reference/camcal-fixed.txt --control-sigma-m 1e-6 --photomodeler-export " +
                    data + "/photomodeler/camcal-pmexport.txt --out " + dir.File("block"));
}

TEST(CliOptions, ImportDbatThenAdjustGivesThePublishedCalibration) {
  const std::string data = testing::SharedDataDir("dbat_camcal_olympus_c4040z");
  if (data.empty()) GTEST_SKIP() << "../shared/data/dbat_camcal_olympus_c4040z is absent";
  testing::TempDir dir("aerocal_cli_dbat");
  // The published run holds the four control points fixed (camcal-fixed.txt): 1 um here.
  const auto imported = ImportDbatCamcal(data, dir);
  ASSERT_EQ(imported.exit_code, 0) << imported.output;
  const auto adjusted = RunAerocal("adjust --project " + dir.File("block/project.yaml") +
                                   " --self-calibration c,x0,y0,K1,K2,K3,P1,P2,B1 --no-snooping --out " +
                                   dir.File("r.json"));
  ASSERT_EQ(adjusted.exit_code, 0) << adjusted.output;
  const auto doc = nlohmann::json::parse(ReadTextFile(dir.File("r.json")));
  // Published (DBAT 0.9.2.0): c 7.45700 (0.00105) mm, sigma0 0.16148 px.
  const auto& camera = doc["cameras"][0];
  EXPECT_LT(std::abs(camera["estimated"]["c"].get<double>() - 7.45700), 3.0 * camera["sigma"]["c"].get<double>());
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
  EXPECT_NE(r.output.find("camera as australis (brown_fraser_10): exact"), std::string::npos) << r.output;
  const auto doc = nlohmann::json::parse(ReadTextFile(dir.File("a.json")));
  const double c = doc["cameras"][0]["estimated"]["c"].get<double>();
  const double sigma_c = doc["cameras"][0]["sigma"]["c"].get<double>();
  auto shown = RunAerocal("camera show --from australis " + dir.File("cam.aus.txt"));
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  // The table prints c with 15 digits and its sigma with 6.
  char c_text[64], sigma_text[64];
  std::snprintf(c_text, sizeof(c_text), "%.6f", c);
  std::snprintf(sigma_text, sizeof(sigma_text), "%.4g", sigma_c);
  EXPECT_NE(shown.output.find(std::string(c_text).substr(0, 7)), std::string::npos) << shown.output;
  EXPECT_NE(shown.output.find(std::string(sigma_text).substr(0, 5)), std::string::npos) << shown.output;
  r = RunAerocal(adjust + dir.File("b.json") + " --write-camera " + dir.File("cam.pm.txt") +
                 " --camera-format photomodeler");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("least-squares fit over the format"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("interior sigmas not written"), std::string::npos) << r.output;
  shown = RunAerocal("camera show --from photomodeler " + dir.File("cam.pm.txt"));
  ASSERT_EQ(shown.exit_code, 0) << shown.output;
  EXPECT_NE(shown.output.find("2272 x 1704 px"), std::string::npos) << shown.output;
}

}  // namespace
}  // namespace aerocal
