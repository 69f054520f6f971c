// The command line: help, version, exit codes, determinism of `simulate`, bad options.
#include <filesystem>

#include <gtest/gtest.h>

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"

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
  ASSERT_EQ(testing::RunAerocal("simulate --out " + a + " --seed 5 --exposures 9 --points 60 --tie-points 50").exit_code, 0);
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b + " --seed 5 --exposures 9 --points 60 --tie-points 50").exit_code, 0);
  for (const char* f : {"camera_nominal.yaml", "camera_truth.yaml", "exposures.csv", "observations.csv",
                        "observations_subimage.csv", "points.csv", "stitch_obs.csv", "project.yaml",
                        "project_subimage.yaml", "truth/exposures.csv", "truth/points.csv"}) {
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
  ASSERT_EQ(testing::RunAerocal("simulate --out " + b + " --seed 6 --exposures 9 --points 60 --tie-points 50").exit_code, 0);
  EXPECT_NE(ReadTextFile(a + "/observations.csv"), ReadTextFile(b + "/observations.csv"));
}

TEST(Cli, BadOptionsExitWithTwoAndWriteNothing) {
  testing::TempDir dir;
  const auto r = testing::RunAerocal("simulate --out " + dir.File("x") + " --layout 1x1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--layout"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.File("x")));
  EXPECT_EQ(testing::RunAerocal("simulate --out " + dir.File("y") + " --exposures -3").exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir.File("y")));
  const auto model = testing::RunAerocal("simulate --out " + dir.File("z") + " --nominal-mapping shear");
  EXPECT_EQ(model.exit_code, 2);
  EXPECT_NE(model.output.find("--nominal-mapping"), std::string::npos) << model.output;
  EXPECT_FALSE(std::filesystem::exists(dir.File("z")));
  EXPECT_EQ(testing::RunAerocal("simulate --out " + dir.File("z") + " --ccd-shear -1").exit_code, 2);
  EXPECT_FALSE(std::filesystem::exists(dir.File("z")));
}

TEST(Cli, OtherLayoutsSimulate) {
  testing::TempDir dir;
  ASSERT_EQ(testing::RunAerocal("simulate --out " + dir.path() + " --layout 3x4 --exposures 6 --points 30 --tie-points 20").exit_code, 0);
  const auto camera = calib::ReadCamera(dir.File("camera_nominal.yaml"));
  EXPECT_EQ(camera.subimages.size(), 12u);
  EXPECT_FALSE(camera.reference_points.empty());
}

}  // namespace
}  // namespace aerocal
