// 'aerocal rig error-analysis' on the dual-lens example of configs/: the issue's JSON keys, the
// hand figures through the CLI, Monte-Carlo against linear propagation, byte-identical reruns,
// exactness with zero limits, the grid and the refusals (exit 2, FILE:LINE, nothing written).
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>

namespace aerocal::stitch {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;
using nlohmann::json;

const std::string kRig = std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml";
const std::string kLimits = std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens_limits.yaml";

std::string Analysis(const std::string& extra) {
  return "rig error-analysis --camera " + kRig + " --limits " + kLimits + " " + extra;
}

using aerocal::testing::ReadJson;

const json& SourceRow(const json& doc, const std::string& name) {
  for (const json& row : doc["per_source"])
    if (row["source"] == name) return row;
  throw std::runtime_error("no row " + name);
}

TEST(RigErrorAnalysisCommand, ExampleCameraWithTheIssueKeysAndByteIdenticalReruns) {
  TempDir a, b;
  const std::string args = "--target B:4999.5,4999.5 --samples 100000 --seed 7 --out ";
  auto run = RunAerocal(Analysis(args + a.File("result.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json doc = ReadJson(a.File("result.json"));
  EXPECT_EQ(doc["kind"], "rig_error_analysis");
  EXPECT_EQ(doc["height_m"], 1200.0) << "the rig file's virtual.height_m";
  const std::vector<std::string> names = {"x0:A",
                                          "y0:A",
                                          "c:A",
                                          "x0:B",
                                          "y0:B",
                                          "c:B",
                                          "omega:B",
                                          "phi:B",
                                          "kappa:B",
                                          "tx:B",
                                          "ty:B",
                                          "tz:B",
                                          "height"};
  ASSERT_EQ(doc["per_source"].size(), names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    const json& row = doc["per_source"][i];
    EXPECT_EQ(row["source"], names[i]);
    EXPECT_EQ(row["plus_px"].size(), 2u);
    EXPECT_EQ(row["minus_px"].size(), 2u);
    EXPECT_TRUE(doc["linear"]["share"].contains(names[i])) << names[i];
  }
  for (const char* key : {"sigma_px", "bound_px", "share"})
    EXPECT_TRUE(doc["linear"].contains(key)) << key;
  for (const char* key :
       {"n", "seed", "sigma_px", "mean_px", "bound_px", "bound_radial_px", "max_abs_px"})
    EXPECT_TRUE(doc["monte_carlo"].contains(key)) << key;
  EXPECT_EQ(doc["monte_carlo"]["n"], 100000);
  EXPECT_EQ(doc["monte_carlo"]["seed"], 7);
  EXPECT_EQ(doc["target"]["head"], "B");
  EXPECT_NEAR(doc["target"]["head_px"][0].get<double>(), 4999.5, 1e-8);
  // 10" at c = 150 mm, 6 um pixels: 1.212 px (0.3 %: the format centre is 4.2 mm off the
  // principal point, the head converges by 1 deg).
  EXPECT_NEAR(SourceRow(doc, "phi:B")["plus_px"][0].get<double>(), 1.212, 0.004);
  EXPECT_NEAR(SourceRow(doc, "omega:B")["plus_px"][1].get<double>(), -1.212, 0.004);
  // Principal points of the two heads: opposite signs.
  EXPECT_LT(SourceRow(doc, "x0:A")["plus_px"][0].get<double>() *
                SourceRow(doc, "x0:B")["plus_px"][0].get<double>(),
            0.0);
  EXPECT_LT(SourceRow(doc, "y0:A")["plus_px"][1].get<double>() *
                SourceRow(doc, "y0:B")["plus_px"][1].get<double>(),
            0.0);
  for (int axis = 0; axis < 2; ++axis)
    EXPECT_NEAR(doc["monte_carlo"]["sigma_px"][axis].get<double>() /
                    doc["linear"]["sigma_px"][axis].get<double>(),
                1.0,
                0.01)
        << axis;
  EXPECT_LT(doc["monte_carlo"]["bound_radial_px"].get<double>(), 2.0);
  // Histograms: CSV (header + 3 x 60 bins) and PNG beside the result.
  const std::string csv = ReadTextFile(a.File("result_histogram.csv"));
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 181);
  EXPECT_EQ(doc["monte_carlo"]["histogram_csv"], "result_histogram.csv");
  const std::string png = ReadTextFile(a.File("result_histogram.png"));
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  // Rerun elsewhere: the same bytes.
  run = RunAerocal(Analysis(args + b.File("result.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  for (const char* file : {"result.json", "result_histogram.csv", "result_histogram.png"})
    EXPECT_EQ(ReadTextFile(a.File(file)), ReadTextFile(b.File(file))) << file;
}

TEST(RigErrorAnalysisCommand, ZeroLimitsGiveZeroError) {
  TempDir tmp;
  std::ofstream(tmp.File("zero.yaml"))
      << "limits: {principal_point_px: 0, principal_distance_px: 0, angles_arcsec: 0, "
         "lever_arm_mm: 0, height_m: 0}\n";
  const auto run =
      RunAerocal("rig error-analysis --camera " + kRig + " --limits " + tmp.File("zero.yaml") +
                 " --samples 1000 --no-plots --out " + tmp.File("r.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json doc = ReadJson(tmp.File("r.json"));
  EXPECT_EQ(doc["limits"]["sigmas"], 3.0) << "default";
  for (const json& row : doc["per_source"])
    for (const char* key : {"plus_px", "minus_px"})
      for (int axis = 0; axis < 2; ++axis)
        EXPECT_EQ(row[key][axis].get<double>(), 0.0) << row["source"];
  EXPECT_EQ(doc["linear"]["sigma_px"], json::array({0.0, 0.0}));
  EXPECT_TRUE(doc["linear"]["share"]["phi:B"][0].is_null()) << "an unknown share is null, never 0";
  EXPECT_EQ(doc["monte_carlo"]["max_abs_px"], json::array({0.0, 0.0}));
  EXPECT_FALSE(std::filesystem::exists(tmp.File("r_histogram.png")));
}

TEST(RigErrorAnalysisCommand, GridVirtualPixelDefaultTargetAndHeight) {
  TempDir tmp;
  auto run =
      RunAerocal(Analysis("--grid 2 --samples 300 --no-plots --out " + tmp.File("grid.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  json doc = ReadJson(tmp.File("grid.json"));
  ASSERT_EQ(doc["grid"]["points"].size(), 4u);
  EXPECT_EQ(doc["grid"]["bound_map_csv"], "grid_bound_map.csv");
  const std::string map = ReadTextFile(tmp.File("grid_bound_map.csv"));
  EXPECT_EQ(std::count(map.begin(), map.end(), '\n'), 5);
  EXPECT_FALSE(std::filesystem::exists(tmp.File("grid_bound_map.png")));
  const int worst = doc["grid"]["worst_index"];
  EXPECT_EQ(doc["linear"]["bound_radial_px"],
            doc["grid"]["points"][worst]["linear"]["bound_radial_px"]);

  run = RunAerocal(Analysis("--virtual 5000,5000 --samples 0 --out " + tmp.File("v.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  doc = ReadJson(tmp.File("v.json"));
  EXPECT_EQ(doc["target"]["head"], "B");
  EXPECT_EQ(doc["target"]["virtual_px"], json::array({5000.0, 5000.0}));
  EXPECT_TRUE(doc["monte_carlo"].is_null());

  // Default target: head B's format centre; twice the height: a quarter of the height parallax.
  run = RunAerocal(Analysis("--samples 0 --out " + tmp.File("h1.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  run = RunAerocal(Analysis("--samples 0 --height-m 2400 --out " + tmp.File("h2.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json h1 = ReadJson(tmp.File("h1.json")), h2 = ReadJson(tmp.File("h2.json"));
  EXPECT_NEAR(h1["target"]["head_px"][0].get<double>(), 4999.5, 1e-8);
  EXPECT_EQ(h2["height_m"], 2400.0);
  const double ratio = SourceRow(h2, "height")["plus_px"][0].get<double>() /
                       SourceRow(h1, "height")["plus_px"][0].get<double>();
  // c b dH / (H (H + dH)): 1200 x 1350 / (2400 x 2550) = 0.2647.
  EXPECT_NEAR(ratio, 1200.0 * 1350.0 / (2400.0 * 2550.0), 0.002);
}

TEST(RigErrorAnalysisCommand, RefusesBadInputWithExitTwoAndNothingWritten) {
  TempDir tmp;
  const auto refused = [&](const std::string& arguments, const std::string& expected) {
    SCOPED_TRACE(arguments);
    const auto run = RunAerocal(arguments + " --out " + tmp.File("r.json"));
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find(expected), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("r.json")));
  };
  std::ofstream(tmp.File("neg.yaml"))
      << "limits:\n  principal_point_px: 0.5\n  principal_distance_px: -1\n  angles_arcsec: 10\n"
         "  lever_arm_mm: 1\n  height_m: 150\n";
  refused("rig error-analysis --camera " + kRig + " --limits " + tmp.File("neg.yaml"),
          "neg.yaml:3: limits.principal_distance_px must be >= 0");
  std::ofstream(tmp.File("missing.yaml")) << "limits: {principal_point_px: 0.5}\nsigmas: 3\n";
  refused("rig error-analysis --camera " + kRig + " --limits " + tmp.File("missing.yaml"),
          "missing.yaml:1: limits: missing principal_distance_px");
  std::ofstream(tmp.File("rig.yaml"))
      << "rig:\n  reference_head: A\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n"
         "      format_px: [100, 100]\n      interior: {c: 150}\n      lever_arm: [0, 0, 0]\n";
  refused("rig error-analysis --camera " + tmp.File("rig.yaml") + " --limits " + kLimits,
          "rig.yaml:8: unknown key 'lever_arm'");
  std::ofstream(tmp.File("one.yaml"))
      << "rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
         "      interior: {c: 150}\n";
  refused("rig error-analysis --camera " + tmp.File("one.yaml") + " --limits " + kLimits,
          "a rig of one head is an ordinary camera");
  refused(Analysis("--target A:100,100"), "reference head");
  refused(Analysis("--target Z:100,100"), "head 'Z' is not in");
  refused(Analysis("--target B:100"), "--target: expected COL,ROW");
  refused(Analysis("--target B:100,100 --grid 3"), "exclude each other");
  refused(Analysis("--height-m 100"), "must be below the flying height");
  refused(Analysis("--virtual 20000,5000"), "no non-reference head sees");
  refused(Analysis("--samples -5"), "--samples: must be in [0, ");
  std::string no_height = ReadTextFile(kRig);
  const auto at = no_height.find(", height_m: 1200.0");
  ASSERT_NE(at, std::string::npos);
  no_height.erase(at, std::string(", height_m: 1200.0").size());
  std::ofstream(tmp.File("no_height.yaml")) << no_height;
  refused("rig error-analysis --camera " + tmp.File("no_height.yaml") + " --limits " + kLimits,
          "no_height.yaml has no virtual.height_m");
}

TEST(RigDesignCommand, Uav4FiguresSvgAndRefusals) {
  TempDir tmp;
  const std::string uav4 = std::string(AEROCAL_CONFIGS_DIR) + "/rig_uav4.yaml";
  auto run = RunAerocal("rig design --camera " + uav4 + " --grid-cells 150 --out " +
                        tmp.File("d.json") + " --svg " + tmp.File("d.svg"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const json doc = ReadJson(tmp.File("d.json"));
  EXPECT_EQ(doc["kind"], "rig_design");
  EXPECT_EQ(doc["height_m"], 300.0) << "the rig file's virtual.height_m";
  ASSERT_EQ(doc["heads"].size(), 4u);
  for (const json& head : doc["heads"]) {
    ASSERT_EQ(head["gsd"].size(), 9u);
    const json& pp = head["gsd"][0];
    EXPECT_EQ(pp["where"], "principal_point");
    EXPECT_NEAR(
        pp["gsd_ratio"]["along_tilt"].get<double>() / pp["closed_form"]["along_tilt"].get<double>(),
        1,
        0.005);
    EXPECT_NEAR(pp["gsd_ratio"]["across_tilt"].get<double>() /
                    pp["closed_form"]["across_tilt"].get<double>(),
                1,
                0.005);
    EXPECT_TRUE(head["gsd"][5]["closed_form"].is_null()) << "a corner is off the principal line";
  }
  for (const char* key : {"virtual_format",
                          "covered_area_m2",
                          "effective_format",
                          "zones",
                          "standard_positions",
                          "grid"})
    EXPECT_TRUE(doc.contains(key)) << key;
  EXPECT_EQ(doc["standard_positions"].size(), 12u);
  EXPECT_TRUE(doc["virtual_format"]["fits"].get<bool>());
  const std::string svg = ReadTextFile(tmp.File("d.svg"));
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_EQ(std::count(svg.begin(), svg.end(), '\n') > 4, true);
  EXPECT_NE(svg.find("<polygon"), std::string::npos);
  // Readable without a caption: ground metres on both axes and a scale bar (issue 33 item 3).
  for (const char* text :
       {"X (m, from the nadir point)", "Y (m)", "class=\"scale-bar\"", " m</text>"})
    EXPECT_NE(svg.find(text), std::string::npos) << text;
  // Refusals: exit 2, the option named, nothing written.
  for (const std::string bad : {"--height-m -5", "--grid-cells 3"}) {
    run = RunAerocal("rig design --camera " + uav4 + " " + bad + " --out " + tmp.File("x.json") +
                     " --svg " + tmp.File("x.svg"));
    EXPECT_EQ(run.exit_code, 2) << bad << run.output;
    EXPECT_NE(run.output.find(bad.substr(0, bad.find(' '))), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("x.json")));
    EXPECT_FALSE(std::filesystem::exists(tmp.File("x.svg")));
  }
}

}  // namespace
}  // namespace aerocal::stitch
