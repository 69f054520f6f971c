// The two readers of a laboratory calibration's files, called directly (issue 37: the sanitizer
// job runs `unit` tests; the CLI tests of these files are `cli`): the budget YAML of
// `calibrate --budget` (units converted, FILE:LINE on bad content) and the directions file of
// `calibrate --directions` (docs/formats.md "Directions file"). Good files give the values they
// hold; each bad one an aerocal::Error naming the file, its line and the rule.
#include "calib/camera/camera_io.h"
#include "calib/core/error.h"
#include "calib/core/yaml_util.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"
#include "triangulation/calibration/direction_io.h"
#include "triangulation/calibration/uncertainty_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace aerocal::triangulation {
namespace {

using testing::TempDir;

// `text` as the file `name` in `dir`; its path.
std::string Write(const TempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.File(name);
  testing::WriteFileText(path, text);
  return path;
}

template <typename Read>
std::string ErrorOf(Read read) {
  try {
    read();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// The reader keeps each component's unit (known ones only); UncertaintyBudget converts it to the
// quantity's unit (BudgetUnits.AComponentInMicrometresIsConvertedToTheQuantitysUnit, tools).
TEST(BudgetReader, ComponentsKeepValueUnitSensitivityAndLine) {
  TempDir dir("aerocal_budget_reader");
  const BudgetOptions b = ReadBudgetOptions(Write(
      dir,
      "budget.yaml",
      "radii_mm: [2.0, 4.0]\ntarget_radius_mm: 0.5\ncomponents:\n"
      "  - {quantity: c, source: temperature, value: 0.6, unit: um, distribution: rectangular}\n"
      "  - {quantity: x0, source: mount, value: 2, unit: K, sensitivity: 0.001, dof: 8}\n"));
  EXPECT_EQ(b.radii_mm, (std::vector<double>{2.0, 4.0}));
  EXPECT_EQ(b.target_radius_mm, 0.5);
  ASSERT_EQ(b.user.size(), 2u);
  EXPECT_EQ(b.user[0].value, 0.6);
  EXPECT_EQ(b.user[0].unit, "um");
  EXPECT_FALSE(b.user[0].sensitivity_given);
  EXPECT_EQ(b.user[0].distribution, "rectangular");
  EXPECT_EQ(b.user[1].unit, "K");
  EXPECT_TRUE(b.user[1].sensitivity_given);
  EXPECT_EQ(b.user[1].sensitivity, 0.001);
  EXPECT_EQ(b.user[1].dof, 8);
  EXPECT_NE(b.user[1].where.find("budget.yaml:5"), std::string::npos) << b.user[1].where;
}

TEST(BudgetReader, BadFilesNameTheirLine) {
  TempDir dir("aerocal_budget_reader");
  const std::string c = "components:\n  - {quantity: c, source: t, ";
  const struct {
    std::string text, message;
  } cases[] = {
      {"# nothing\n", "budget.yaml:1: an empty budget file"},
      {c + "value: 0.002, unit: furlong}\n", "budget.yaml:2: unknown unit 'furlong'"},
      {c + "value: 0.5, distribution: uniformish}\n", "budget.yaml:2"},
      {c + "value: 0.5, dof: 0}\n", "budget.yaml:2"},
      {c + "value: 0.5, unit: K, sensitivity: 1e308}\n", "budget.yaml:2: sensitivity out of range"},
      {c + "value: .nan, unit: mm}\n", "budget.yaml:2"},
      {c + "value: 1e400, unit: mm}\n", "budget.yaml:2"},
      {"radii_mm: [2.0, -1]\n", "budget.yaml:1"},
      {"radii_mm: [2.0, 1e308]\n", "budget.yaml:1"},
      {"components: [\n", "budget.yaml"},
      {"radii_mm: [2.0]\npixel_size_tolerance_mm: -1e-6\n",
       "budget.yaml:2: pixel_size_tolerance_mm out of range"},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.text);
    const std::string path = Write(dir, "budget.yaml", k.text);
    EXPECT_NE(ErrorOf([&] { ReadBudgetOptions(path); }).find(k.message), std::string::npos)
        << ErrorOf([&] { ReadBudgetOptions(path); });
  }
}

// A 6000 x 4000 px camera of 4 um, c = 24 mm: it bounds the image positions.
calib::Camera SmallCamera() {
  return calib::ParseCamera(
      LoadYamlText("pixel_size_mm: 0.004\nformat_px: [6000, 4000]\ninterior: {c: 24}\n",
                   "camera.yaml"),
      "camera.yaml");
}

TEST(DirectionReader, CollimatorsAndGoniometerSettingsAsWritten) {
  TempDir dir("aerocal_direction_reader");
  const calib::Camera camera = SmallCamera();
  const DirectionData known =
      ReadDirections(Write(dir,
                           "c.csv",
                           "target,col,row,sigma_px,azimuth_deg,elevation_deg,sigma_arcsec,group\n"
                           "A,3000,2000,0.3,0,0,1,monday\nB,4000.5,2000,,6.8,0,1,monday\n"
                           "A,3000.1,2000.2,0.3,0,0,1,tuesday\n"),
                     camera,
                     0.2);
  ASSERT_EQ(known.targets.size(), 2u);
  EXPECT_TRUE(known.targets[1].known);
  EXPECT_NEAR(known.targets[1].angles_rad.x(), 6.8 * M_PI / 180, 1e-15);
  ASSERT_EQ(known.observations.size(), 3u);
  EXPECT_EQ(known.observations[1].pixel.x(), 4000.5);
  EXPECT_EQ(known.observations[1].sigma_px, 0.2);  // empty sigma_px: the default
  EXPECT_NEAR(known.observations[0].sigma_rad, M_PI / 180 / 3600, 1e-18);
  EXPECT_EQ(known.groups, (std::vector<std::string>{"monday", "monday", "tuesday"}));
  EXPECT_EQ(known.settings, 0);

  const DirectionData gonio = ReadDirections(
      Write(dir,
            "g.csv",
            "target,col,row,setting,turn_deg,tilt_deg\nT,3000,2000,s1,0,0\nT,3410.7,2000,s2,5,0\n"
            "T,3000,1589.3,s3,0,-5\n"),
      camera,
      0.2);
  ASSERT_EQ(gonio.targets.size(), 1u);
  EXPECT_FALSE(gonio.targets[0].known);
  EXPECT_EQ(gonio.settings, 3);
  EXPECT_TRUE(gonio.groups.empty());
}

TEST(DirectionReader, BadRowsNameTheirLine) {
  TempDir dir("aerocal_direction_reader");
  const calib::Camera camera = SmallCamera();
  const std::string header = "target,col,row,azimuth_deg,elevation_deg\n";
  const std::string good = "A,3000,2000,0,0\nB,4000,2000,6.8,0\n";
  const struct {
    std::string text, message;
  } cases[] = {
      {header + good + "C,nan,2000,1,1\n", "d.csv:4: column 'col'"},
      {header + good + "C,3000,1e308,1,1\n", "d.csv:4: column 'row' out of range"},
      {header + good + "C,3000,2000,inf,1\n", "d.csv:4: column 'azimuth_deg'"},
      {header + good + "C,3000,2000,0,95\n", "d.csv:4: column 'elevation_deg' out of range"},
      {header + good + "C,3000,2000,1,\n", "d.csv:4: azimuth_deg and elevation_deg go together"},
      {header + good + ",3000,2000,1,1\n", "d.csv:4: target must not be empty"},
      {header + good + "B,3100,2000,6.8,0\n", "d.csv:4: target B is observed twice"},
      {"target,col,row,sigma_px\nA,1,1,-0.3\n", "d.csv:2: column 'sigma_px'"},
      {"target,col,row,setting,turn_deg\nX,1,1,s1,5\nX,2,2,s1,6\n", "d.csv:3: setting s1 has turn"},
      {"target,col,row,azimuth\n", "d.csv:1: unknown column 'azimuth'"},
      {"target,col\n", "d.csv:1: missing column 'row'"},
      {"", "d.csv"},
  };
  for (const auto& k : cases) {
    SCOPED_TRACE(k.text);
    const std::string path = Write(dir, "d.csv", k.text);
    const std::string error = ErrorOf([&] { ReadDirections(path, camera, 0.2); });
    EXPECT_NE(error.find(k.message), std::string::npos) << error;
  }
}

}  // namespace
}  // namespace aerocal::triangulation
