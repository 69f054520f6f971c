// `aerocal pushbroom control` in the default suite (issue 17; the 1.5 x acceptance study is the
// long test triangulation/pushbroom_images): on a small image-mode flight (3 x 100 detectors, 300
// lines, a scene textured with a real photograph) the control is matched and intersected on
// pixels, `pushbroom calibrate` reads it, fits it at the matching precision and removes most of
// the detector errors; bad input: exit 2 with the file and line, nothing written.
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/result_file.h"
#include "tests/support/test_support.h"
#include "tests/triangulation/pushbroom_commands.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace aerocal::triangulation {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;
using nlohmann::json;

TEST(PushbroomControl, MatchedControlCalibratesTheDetectors) {
  const std::string photo = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (photo.empty())
    GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent (the scene's texture)";
  TempDir tmp("aerocal_pushbroom_control");
  const std::string sim = tmp.File("sim");
  const auto s = RunAerocal("simulate --pushbroom --render-images --texture " + photo +
                            "/images/img_4880.jpg --detectors 100 --lines 300 --out " + sim);
  ASSERT_EQ(s.exit_code, 0) << s.output;
  const auto c = RunAerocal(PushbroomControlCommand(sim, tmp.File("control")));
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const json control = testing::ReadJson(tmp.File("control/control.json"));
  EXPECT_GE(control["n_points"].get<int>(), 100);
  EXPECT_GE(control["n_rays"].get<int>(),
            2 * control["n_points"].get<int>());  // forward intersections
  const double match_sigma = control["median_match_sigma_px"].get<double>();
  EXPECT_GT(match_sigma, 0.0);
  EXPECT_LT(match_sigma, 0.3);  // least-squares matching, not pixel-level correlation
  const CsvTable points = CsvTable::Read(tmp.File("control/points.csv"));
  for (const auto& row : points.rows())
    for (const char* sigma : {"sX", "sY", "sZ"}) EXPECT_GT(points.Number(row, sigma), 0.0) << sigma;

  const auto cal = RunAerocal(PushbroomCalibrateCommand(sim,
                                                        tmp.File("control/observations.csv"),
                                                        tmp.File("control/points.csv"),
                                                        tmp.File("cal.json")));
  ASSERT_EQ(cal.exit_code, 0) << cal.output;
  const json j = testing::ReadJson(tmp.File("cal.json"));
  // The fit reaches the matching precision in every sub-camera (2 x: the intersection's own
  // error adds to the line image's).
  for (const auto& sub : j["subcameras"]) {
    for (const char* axis : {"across", "along"})
      EXPECT_LT(sub["rms_after_px"][axis].get<double>(), 2.0 * match_sigma)
          << sub["id"] << " " << axis;
  }
  // Most of the detector errors are removed: the table error against the truth is below a
  // quarter of the nominal camera's (the nominal table is zero, so its error is the truth).
  const CsvTable truth = CsvTable::Read(sim + "/truth_detectors.csv");
  std::map<int, std::pair<double, double>> t;
  for (const auto& row : truth.rows())
    t[static_cast<int>(truth.Number(row, "i"))] = {truth.Number(row, "dx_mm"),
                                                   truth.Number(row, "dy_mm")};
  double e2[2] = {0, 0}, n2[2] = {0, 0};
  for (const auto& d : j["detectors"]) {
    const auto& [dx, dy] = t.at(d["i"].get<int>());
    e2[0] += std::pow(d["dx_mm"].get<double>() - dx, 2);
    e2[1] += std::pow(d["dy_mm"].get<double>() - dy, 2);
    n2[0] += dx * dx;
    n2[1] += dy * dy;
  }
  EXPECT_LT(std::sqrt(e2[0] / n2[0]), 0.25) << "across track";
  EXPECT_LT(std::sqrt(e2[1] / n2[1]), 0.25) << "along track";
}

// The reference orientation straight from `aerocal adjust`'s result.json (--reference-result):
// the simulated strip's exposures.csv written as the adjustment's `exposures` (deg), plus one
// exposure the adjustment did not use, must give the very control of --reference-exposures.
// Another kind, `valid: false`, a missing angle and both options are refused (exit 2), nothing
// written.
TEST(PushbroomControl, ReferenceOrientationFromTheBlockResult) {
  const std::string photo = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (photo.empty())
    GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent (the scene's texture)";
  TempDir tmp("aerocal_pushbroom_reference_result");
  const std::string sim = tmp.File("sim");
  ASSERT_EQ(RunAerocal("simulate --pushbroom --render-images --texture " + photo +
                       "/images/img_4880.jpg --detectors 60 --lines 200 --out " + sim)
                .exit_code,
            0);
  const CsvTable csv = CsvTable::Read(sim + "/reference/exposures.csv");
  json exposures = json::array();
  for (const auto& row : csv.rows()) {
    json e = {{"image", csv.String(row, "image")}, {"used", true}};
    for (const char* key : {"X", "Y", "Z", "omega", "phi", "kappa"}) e[key] = csv.Number(row, key);
    exposures.push_back(e);
  }
  exposures.push_back({{"image", "not_oriented"}, {"X", nullptr}, {"used", false}});
  auto write = [&](const std::string& path, const json& doc) {
    std::ofstream(path) << doc.dump(1);
  };
  const json result = {{"kind", "adjust"},
                       {"schema_version", ResultSchemaVersion("adjust")},
                       {"valid", true},
                       {"exposures", exposures}};
  write(tmp.File("result.json"), result);
  const std::string common =
      PushbroomControlInputs(sim) + " --line-outlier-k 5 --line-outlier-min-px 0.25";
  const auto from_csv = RunAerocal(common + " --reference-exposures " + sim +
                                   "/reference/exposures.csv --out " + tmp.File("a"));
  ASSERT_EQ(from_csv.exit_code, 0) << from_csv.output;
  const auto from_result = RunAerocal(common + " --reference-result " + tmp.File("result.json") +
                                      " --out " + tmp.File("b"));
  ASSERT_EQ(from_result.exit_code, 0) << from_result.output;
  EXPECT_NE(from_result.output.find("1 not used by the adjustment"), std::string::npos)
      << from_result.output;
  EXPECT_EQ(ReadTextFile(tmp.File("a/points.csv")), ReadTextFile(tmp.File("b/points.csv")));
  EXPECT_EQ(ReadTextFile(tmp.File("a/observations.csv")),
            ReadTextFile(tmp.File("b/observations.csv")));

  auto refused = [&](const json& doc, const std::string& expected) {
    write(tmp.File("bad.json"), doc);
    const auto run = RunAerocal(common + " --reference-result " + tmp.File("bad.json") + " --out " +
                                tmp.File("c"));
    EXPECT_EQ(run.exit_code, 2) << run.output;
    EXPECT_NE(run.output.find(expected), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(tmp.File("c")));
  };
  json other = result;
  other["kind"] = "pushbroom";
  refused(other, "bad.json: not a result of `aerocal adjust`");
  json invalid = result;
  invalid["valid"] = false;
  refused(invalid, "valid: false");
  json no_kappa = result;
  no_kappa["exposures"][1].erase("kappa");
  refused(no_kappa,
          "bad.json: exposures[1] (" + csv.String(csv.rows()[1], "image") +
              "): kappa must be a finite number");
  const auto both = RunAerocal(common + " --reference-result " + tmp.File("result.json") +
                               " --reference-exposures " + sim + "/reference/exposures.csv --out " +
                               tmp.File("c"));
  EXPECT_EQ(both.exit_code, 2) << both.output;
  const auto neither = RunAerocal(common + " --out " + tmp.File("c"));
  EXPECT_EQ(neither.exit_code, 2) << neither.output;
  EXPECT_NE(neither.output.find("--reference-result"), std::string::npos) << neither.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("c")));
}

TEST(PushbroomImageMode, BadInputIsRefused) {
  TempDir tmp("aerocal_pushbroom_images_bad");
  // --render-images needs the photograph.
  const auto no_texture = RunAerocal("simulate --pushbroom --render-images --out " + tmp.File("a"));
  EXPECT_EQ(no_texture.exit_code, 2) << no_texture.output;
  EXPECT_NE(no_texture.output.find("--texture"), std::string::npos) << no_texture.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("a")));
  // A reference image missing: exposures.csv:LINE names it, nothing written.
  const std::string sim = tmp.File("sim");
  ASSERT_EQ(RunAerocal("simulate --pushbroom --detectors 60 --lines 200 --control 50 --out " + sim)
                .exit_code,
            0);
  std::filesystem::create_directories(sim + "/reference");
  std::ofstream(sim + "/line_image.png");  // never read: the reference images are found first
  std::ofstream(sim + "/reference/camera.yaml")
      << "name: ref\nmodel: brown_fraser_10\npixel_size_mm: 0.006\nformat_px: [1000, 800]\n"
         "interior: {c: 10}\n";
  std::ofstream(sim + "/reference/exposures.csv")
      << "image,camera,X,Y,Z,omega,phi,kappa\nref9,reference,0,0,1000,0,0,0\n";
  const auto missing = RunAerocal(PushbroomControlCommand(sim, tmp.File("out")));
  EXPECT_EQ(missing.exit_code, 2) << missing.output;
  EXPECT_NE(missing.output.find("ref9"), std::string::npos) << missing.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("out")));
}

}  // namespace
}  // namespace aerocal::triangulation
