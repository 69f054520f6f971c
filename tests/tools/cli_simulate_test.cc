// The command line: help, version, exit codes, determinism of `simulate`, bad options.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

namespace aerocal {
namespace {

TEST(Cli, HelpListsTheCommandsAndVersionPrints) {
  const auto help = testing::RunAerocal("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.output.find("simulate"), std::string::npos);
  const auto sub = testing::RunAerocal("simulate --help");
  EXPECT_EQ(sub.exit_code, 0);
  EXPECT_NE(sub.output.find("--seed"), std::string::npos);
  const auto version = testing::RunAerocal("--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_NE(version.output.find("aerocal "), std::string::npos);
  EXPECT_EQ(testing::RunAerocal("").exit_code, 2) << "a command is required";
  EXPECT_EQ(testing::RunAerocal("no-such-command").exit_code, 2);
}

TEST(Cli, SimulateIsDeterministicAndWritesTheFormatsFiles) {
  testing::TempDir dir;
  const std::string a = dir.File("a"), b = dir.File("b");
  ASSERT_EQ(testing::RunAerocal("simulate --out " + a +
                                " --seed 5 --exposures 9 --surveyed-points 60 --tie-points 50")
                .exit_code,
            0);
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b +
                                " --seed 5 --exposures 9 --surveyed-points 60 --tie-points 50")
                .exit_code,
            0);
  for (const char* f : {"camera_nominal.yaml",
                        "camera_truth.yaml",
                        "exposures.csv",
                        "observations.csv",
                        "observations_subimage.csv",
                        "points.csv",
                        "stitch_obs.csv",
                        "project.yaml",
                        "project_subimage.yaml",
                        "truth/exposures.csv",
                        "truth/points.csv"}) {
    ASSERT_TRUE(std::filesystem::exists(a + "/" + f)) << f;
    EXPECT_EQ(ReadTextFile(a + "/" + f), ReadTextFile(b + "/" + f)) << f << " differs between runs";
  }
  // The written project reads back and is consistent.
  const auto project = triangulation::ReadProject(a + "/project.yaml");
  EXPECT_EQ(project.exposures.size(), 9u);
  int control = 0;
  for (const auto& p : project.points) control += p.role == triangulation::PointRole::kControl;
  EXPECT_EQ(control, 5);
  const auto camera = calib::ReadCamera(a + "/camera_truth.yaml");
  EXPECT_EQ(camera.subimages.size(), 6u);
  EXPECT_EQ(camera.width_px, 14000);
  // Another seed gives other data.
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b +
                                " --seed 6 --exposures 9 --surveyed-points 60 --tie-points 50")
                .exit_code,
            0);
  EXPECT_NE(ReadTextFile(a + "/observations.csv"), ReadTextFile(b + "/observations.csv"));
}

TEST(Cli, BadOptionsExitWithTwoAndWriteNothing) {
  testing::TempDir dir;
  const auto r = testing::RunAerocal("simulate --out " + dir.File("x") + " --layout 1x1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--layout"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.File("x")));
  EXPECT_EQ(testing::RunAerocal("simulate --out " + dir.File("y") + " --exposures -3").exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(dir.File("y")));
  const auto model =
      testing::RunAerocal("simulate --out " + dir.File("z") + " --nominal-mapping shear");
  EXPECT_EQ(model.exit_code, 2);
  EXPECT_NE(model.output.find("--nominal-mapping"), std::string::npos) << model.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("z")));
  EXPECT_EQ(testing::RunAerocal("simulate --out " + dir.File("z") + " --ccd-shear -1").exit_code,
            2);
  EXPECT_FALSE(std::filesystem::exists(dir.File("z")));
}

TEST(Cli, OtherLayoutsSimulate) {
  testing::TempDir dir;
  ASSERT_EQ(testing::RunAerocal("simulate --out " + dir.path() +
                                " --layout 3x4 --exposures 6 --surveyed-points 30 --tie-points 20")
                .exit_code,
            0);
  const auto camera = calib::ReadCamera(dir.File("camera_nominal.yaml"));
  EXPECT_EQ(camera.subimages.size(), 12u);
  EXPECT_FALSE(camera.reference_points.empty());
}

TEST(Cli, SimulateRigDualLensWritesHeadObservationsAndTruth) {
  testing::TempDir dir;
  const std::string a = dir.File("a"), b = dir.File("b");
  const std::string args =
      " --rig dual-lens --seed 3 --exposures 8 --surveyed-points 12 --tie-points 40 "
      "--gnss-sigma-m 0.05 --imu-sigma-deg 0.005 --speed-mps 60 "
      "--head-time-offset-ms 0.5 --head-increment-arcsec 2";
  const auto run = testing::RunAerocal("simulate --out " + a + args);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("x 2 heads"), std::string::npos) << run.output;
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b + args).exit_code, 0);
  for (const char* f : {"rig_nominal.yaml",
                        "rig_truth.yaml",
                        "exposures.csv",
                        "observations.csv",
                        "points.csv",
                        "project.yaml",
                        "truth/exposures.csv",
                        "truth/points.csv",
                        "truth/rig_exposures.csv"}) {
    ASSERT_TRUE(std::filesystem::exists(a + "/" + f)) << f;
    EXPECT_EQ(ReadTextFile(a + "/" + f), ReadTextFile(b + "/" + f)) << f << " differs between runs";
  }
  EXPECT_EQ(ReadTextFile(a + "/observations.csv").rfind("image,head,point,col,row,sigma_px\n", 0),
            0u);
  const auto exposures = triangulation::ReadExposures(a + "/exposures.csv");
  ASSERT_EQ(exposures.size(), 8u);  // --exposures overrides the rig default (30)
  EXPECT_TRUE(exposures[0].velocity_mps && exposures[0].center_sigma_m &&
              exposures[0].opk_sigma_rad);
  // The rig default flying height (1200 m above a 200..300 m terrain), and --height-m over it.
  EXPECT_NEAR(
      triangulation::ReadExposures(a + "/truth/exposures.csv")[0].center_m.z(), 1450.0, 1e-6);
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b + args + " --height-m 2000").exit_code, 0);
  EXPECT_NEAR(
      triangulation::ReadExposures(b + "/truth/exposures.csv")[0].center_m.z(), 2250.0, 1e-6);
}

TEST(Cli, SimulateRigRefusesUnknownRigsAndFrameOptions) {
  testing::TempDir dir;
  const auto unknown = testing::RunAerocal("simulate --out " + dir.File("x") + " --rig triple");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.output.find("--rig"), std::string::npos) << unknown.output;
  const auto layout =
      testing::RunAerocal("simulate --out " + dir.File("x") + " --rig dual-lens --layout 2x2");
  EXPECT_EQ(layout.exit_code, 2);
  EXPECT_NE(layout.output.find("--layout"), std::string::npos) << layout.output;
  // A head option without --rig (--speed-mps applies to the frame flight too: its velocity
  // columns feed the GNSS time offset, triangulation/README.md).
  const auto head =
      testing::RunAerocal("simulate --out " + dir.File("x") + " --head-time-offset-ms 5");
  EXPECT_EQ(head.exit_code, 2);
  EXPECT_NE(head.output.find("--head-time-offset-ms"), std::string::npos) << head.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("x")));
}

TEST(Cli, SimulateTestFieldThenCalibrateWithItsGroups) {
  // simulate --test-field: deterministic files that `calibrate` takes as they are (no exposures:
  // aerocal's own resections), its groups from groups.csv; the c of the truth within 3 sigma.
  testing::TempDir dir;
  const std::string sim = "simulate --test-field --groups 2 --images-per-group 8 --seed 4 --out ";
  ASSERT_EQ(testing::RunAerocal(sim + dir.File("a")).exit_code, 0);
  ASSERT_EQ(testing::RunAerocal(sim + dir.File("b")).exit_code, 0);
  for (const char* f : {"camera_nominal.yaml",
                        "camera_truth.yaml",
                        "observations.csv",
                        "points.csv",
                        "groups.csv",
                        "truth/exposures.csv",
                        "truth/points.csv"}) {
    ASSERT_TRUE(std::filesystem::exists(dir.File("a/") + f)) << f;
    EXPECT_EQ(ReadTextFile(dir.File("a/") + f), ReadTextFile(dir.File("b/") + f)) << f;
  }
  const std::string a = dir.File("a/");
  const auto r = testing::RunAerocal(
      "calibrate --camera " + a + "camera_nominal.yaml --observations " + a +
      "observations.csv --points " + a + "points.csv --groups " + a +
      "groups.csv --self-calibration c,x0,y0,K1,K2,P1,P2 --out " + dir.File("calib.json"));
  ASSERT_NE(r.exit_code, 2) << r.output;  // 0, or 3 when the two groups happen to disagree
  const auto j = aerocal::testing::ReadJson(dir.File("calib.json"));
  EXPECT_EQ(j["calibration"]["groups"].size(), 2u);
  EXPECT_EQ(j["calibration"]["start"]["resections"].size(), 16u);
  const double truth = calib::ReadCamera(a + "camera_truth.yaml").interior[0];
  EXPECT_LE(std::abs(j["cameras"][0]["estimated"]["c"].get<double>() - truth),
            3.0 * j["cameras"][0]["sigma"]["c"].get<double>());
  // Test-field options belong to --test-field; flight options do not apply to it.
  EXPECT_EQ(testing::RunAerocal("simulate --planar --out " + dir.File("c")).exit_code, 2);
  EXPECT_EQ(
      testing::RunAerocal("simulate --test-field --strips 3 --out " + dir.File("d")).exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir.File("d")));
}

}  // namespace

TEST(Cli, SimulateRigUav4WritesTheStitchingLine) {
  testing::TempDir dir;
  const std::string out = dir.File("uav4");
  const auto run =
      testing::RunAerocal("simulate --out " + out + " --rig uav4 --exposures 3 --seed 5");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto exposures = triangulation::ReadExposures(out + "/exposures.csv");
  ASSERT_EQ(exposures.size(), 3u);
  for (const auto& e : exposures) {
    EXPECT_TRUE(e.velocity_mps && e.z_ref_m) << e.image;
    EXPECT_NEAR(e.velocity_mps->norm(), 10.0, 0.1);
  }
  const auto points = triangulation::ReadPoints(out + "/points.csv");
  int check = 0;
  for (const auto& p : points) check += p.role == triangulation::PointRole::kCheck && !p.xyz_m;
  EXPECT_EQ(check, 30) << "10 check ties per exposure, without coordinates";
  EXPECT_EQ(points.size(), 3u * (12 * 3 + 40 + 10));
  const auto truth = ReadTextFile(out + "/truth/rig_exposures.csv");
  EXPECT_NE(truth.find(",D,"), std::string::npos);
  EXPECT_NE(truth.find(",3.500000\n"), std::string::npos) << "head D's shutter offset";
}

}  // namespace aerocal
