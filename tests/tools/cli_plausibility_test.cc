// Plausibility before solving (issue 33 item 5): the usual mistakes of units and files are said by
// name with their likely cause before anything is solved: a CSV separated by ';', another tool's
// camera file where aerocal's is expected, image coordinates off the camera's format (a list
// measured on resized images), a principal distance given in pixels as millimetres. And the
// global options' vocabulary (item 4): --verbose / --quiet after the command's name too.
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

namespace aerocal {
namespace {

using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

std::string Read(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}
void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

class Plausibility : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("aerocal_cli_plausibility");
    const auto flight = RunAerocal("simulate --out " + dir_->File("flight"));
    ASSERT_EQ(flight.exit_code, 0) << flight.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  // A copy of the simulated flight whose file `name` is replaced by `text`.
  static std::string FlightWith(const std::string& copy,
                                const std::string& name,
                                const std::string& text) {
    namespace fs = std::filesystem;
    const std::string to = dir_->File(copy);
    fs::copy(dir_->File("flight"), to, fs::copy_options::recursive);
    Write(to + "/" + name, text);
    return to;
  }
  static std::string Original(const std::string& name) {
    return Read(dir_->File("flight/" + name));
  }
  static TempDir* dir_;
};
TempDir* Plausibility::dir_ = nullptr;

TEST_F(Plausibility, ACsvSeparatedBySemicolonsIsNamedAsSuch) {
  const std::string semicolons =
      std::regex_replace(Original("observations.csv"), std::regex(","), ";");
  const std::string flight = FlightWith("semicolons", "observations.csv", semicolons);
  const auto r =
      RunAerocal("adjust --project " + flight + "/project.yaml --out " + flight + "/r.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("observations.csv:1: the fields are separated by ';'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(flight + "/r.json"));
}

TEST_F(Plausibility, AnotherToolsCameraFileGetsTheConversionCommand) {
  const std::string dir = dir_->File("foreign");
  std::filesystem::create_directories(dir);
  const auto convert =
      RunAerocal("camera convert --from aerocal --to metashape " +
                 dir_->File("flight/camera_nominal.yaml") + " " + dir + "/camera.xml");
  ASSERT_EQ(convert.exit_code, 0) << convert.output;
  // Where a project names it, and where a command takes it directly.
  const std::string flight = FlightWith(
      "foreign_project",
      "project.yaml",
      std::regex_replace(
          Original("project.yaml"), std::regex("camera_nominal\\.yaml"), dir + "/camera.xml"));
  const auto adjust =
      RunAerocal("adjust --project " + flight + "/project.yaml --out " + dir + "/r.json");
  EXPECT_EQ(adjust.exit_code, 2) << adjust.output;
  EXPECT_NE(adjust.output.find("looks like a metashape camera file"), std::string::npos)
      << adjust.output;
  EXPECT_NE(adjust.output.find("aerocal camera convert --from metashape --to aerocal " + dir +
                               "/camera.xml"),
            std::string::npos)
      << adjust.output;
  const auto stitch = RunAerocal("stitch --camera " + dir + "/camera.xml --obs " +
                                 dir_->File("flight/stitch_obs.csv") + " --out " + dir + "/s.json");
  EXPECT_EQ(stitch.exit_code, 2) << stitch.output;
  EXPECT_NE(stitch.output.find("--from metashape"), std::string::npos) << stitch.output;
  // Our own file gets no such hint when it is wrong.
  const std::string broken = dir + "/broken.yaml";
  Write(broken, std::regex_replace(Original("camera_nominal.yaml"), std::regex("c: 170"), "c: -1"));
  const auto own = RunAerocal("stitch --camera " + broken + " --obs " +
                              dir_->File("flight/stitch_obs.csv") + " --out " + dir + "/s.json");
  EXPECT_EQ(own.exit_code, 2) << own.output;
  EXPECT_EQ(own.output.find("camera convert"), std::string::npos) << own.output;
}

TEST_F(Plausibility, CoordinatesOffTheFormatNameTheLineAndTheLikelyCause) {
  std::string text = Original("observations.csv");
  // The second data row (line 3): its column moved past the 14000 px wide format.
  const size_t row = text.find('\n', text.find('\n') + 1) + 1;
  const size_t col = text.find(',', text.find(',', row) + 1) + 1;
  text.replace(col, text.find(',', col) - col, "15000.5");
  const std::string flight = FlightWith("off_format", "observations.csv", text);
  const auto r =
      RunAerocal("adjust --project " + flight + "/project.yaml --out " + flight + "/r.json");
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("observations.csv:3: image"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1001.5 px outside the 14000 x 12000 px format"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("--pixel-scale"), std::string::npos) << r.output;
}

TEST_F(Plausibility, APrincipalDistanceInPixelsIsWarnedBeforeTheSolveAndInTheResult) {
  // c = 170 mm with 0.02 mm pixels written as 8500 "mm": 23 times the format diagonal.
  std::string camera =
      std::regex_replace(Original("camera_nominal.yaml"), std::regex("c: 170"), "c: 8500");
  camera = std::regex_replace(camera, std::regex("pixel_size_mm: [0-9.]+"), "pixel_size_mm: 0.02");
  const std::string flight = FlightWith("pixels_as_mm", "camera_nominal.yaml", camera);
  const auto r = RunAerocal("adjust --project " + flight +
                            "/project.yaml --max-iterations 3 --out " + flight + "/r.json");
  ASSERT_LE(r.exit_code, 3) << r.output;
  EXPECT_NE(
      r.output.find(
          "implausible_principal_distance: camera cam1: c = 8500 mm is 23 times the 369 mm format "
          "diagonal (a field of view of 2.5 deg)"),
      std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("if c was given in pixels, it is 170 mm with 0.02 mm pixels"),
            std::string::npos)
      << r.output;
  const auto doc = ReadJson(flight + "/r.json");
  bool found = false;
  for (const auto& w : doc["warnings"])
    if (w["name"] == "implausible_principal_distance") {
      found = true;
      EXPECT_NEAR(w["value"].get<double>(), 8500 / (0.02 * std::hypot(14000, 12000)), 1e-9);
      EXPECT_EQ(w["limit"], 20);
    }
  EXPECT_TRUE(found);
  // The simulated camera itself (c / diagonal 1.02) is not warned about.
  const auto plain = RunAerocal("adjust --project " + dir_->File("flight/project.yaml") +
                                " --out " + dir_->File("plain.json"));
  EXPECT_EQ(plain.output.find("implausible_principal_distance"), std::string::npos);
}

// One vocabulary (issue 33 item 4): the global --verbose and --quiet after the command's name too;
// --verbose says what was read and prints the solver's iterations, --quiet silences warnings.
TEST(Vocabulary, GlobalOptionsAfterTheCommandAndWhatVerbosePrints) {
  TempDir dir("aerocal_cli_vocabulary");
  ASSERT_EQ(RunAerocal("simulate --out " + dir.File("f") +
                       " --exposures 3 --strips 1 --surveyed-points 20 --tie-points 30 --quiet")
                .exit_code,
            0);
  const std::string project = dir.File("f/project.yaml");
  const auto verbose =
      RunAerocal("adjust --project " + project + " --out " + dir.File("v.json") + " --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.output;
  EXPECT_NE(verbose.output.find("read " + project + ": 1 camera(s), 3 exposures"),
            std::string::npos)
      << verbose.output;
  EXPECT_NE(verbose.output.find("iter      cost"), std::string::npos) << verbose.output;  // Ceres
  const auto before =
      RunAerocal("--verbose adjust --project " + project + " --out " + dir.File("b.json"));
  EXPECT_NE(before.output.find("iter      cost"), std::string::npos);
  const auto plain = RunAerocal("adjust --project " + project + " --out " + dir.File("p.json"));
  EXPECT_EQ(plain.output.find("iter      cost"), std::string::npos);
  EXPECT_EQ(plain.output.find("read " + project), std::string::npos);
}

}  // namespace
}  // namespace aerocal
