// Image mode of the pushbroom commands (issue 17): `aerocal simulate --pushbroom --render-images`
// renders the line image and a reference frame strip of a scene textured with a real photograph
// (../shared/data/odm_boruszyn_kap_frames), `aerocal pushbroom control` rectifies, matches and
// intersects the cloud control on those pixels, and `aerocal pushbroom calibrate` from that control
// recovers the detector table within 1.5 x the error of the geometry-only run of the same flight
// (the acceptance). Bad input: exit 2 with the file and line, nothing written.
// The flight: 3 x 200 detectors (1.85 m nadir sampling), 800 lines (33 s: labelled `long`).
// Measured: geometry 0.0305 / 0.0179 px, image mode 0.0103 / 0.0057 px (over 10 seeds at 3 x 150
// the ratio is 0.07-0.42, module README "Measured"). The per-detector 3-sigma check does NOT hold
// in image mode (worst 7.8 sigma across here with the fit's own sigmas: a smaller smooth error of
// unknown cause remains, module README "Measured"), so it is printed, not asserted.
#include "calib/core/csv.h"
#include "calib/core/result_file.h"
#include "tests/support/test_support.h"
#include "tests/triangulation/pushbroom_commands.h"

#include <Eigen/Core>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

namespace aerocal::triangulation {
namespace {

using aerocal::testing::RunAerocal;
using aerocal::testing::TempDir;
using nlohmann::json;

// truth_detectors.csv of the flight in `dir`: detector -> (dx, dy) mm.
std::map<int, Eigen::Vector2d> TruthTable(const std::string& dir) {
  const CsvTable truth = CsvTable::Read(dir + "/truth_detectors.csv");
  std::map<int, Eigen::Vector2d> by_detector;
  for (const auto& row : truth.rows())
    by_detector[int(truth.Number(row, "i"))] =
        Eigen::Vector2d(truth.Number(row, "dx_mm"), truth.Number(row, "dy_mm"));
  return by_detector;
}

// RMS error (px) of the calibrated table against truth_detectors.csv, across (x) and along (y).
Eigen::Vector2d TableRmsPx(const std::string& dir, const json& result, double pitch_mm) {
  const std::map<int, Eigen::Vector2d> by_detector = TruthTable(dir);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& d : result["detectors"]) {
    const Eigen::Vector2d e(d["dx_mm"].get<double>(), d["dy_mm"].get<double>());
    sum += (e - by_detector.at(d["i"].get<int>())).cwiseAbs2();
  }
  return (sum / double(result["detectors"].size())).cwiseSqrt() / pitch_mm;
}

// Worst |table error| / predicted sigma over the detectors, across and along.
Eigen::Vector2d WorstNormalisedError(const std::string& dir, const json& result) {
  const std::map<int, Eigen::Vector2d> by_detector = TruthTable(dir);
  Eigen::Vector2d worst = Eigen::Vector2d::Zero();
  for (const auto& d : result["detectors"]) {
    const Eigen::Vector2d e = Eigen::Vector2d(d["dx_mm"].get<double>(), d["dy_mm"].get<double>()) -
                              by_detector.at(d["i"].get<int>());
    if (d["sigma_dx_mm"].is_number())
      worst.x() = std::max(worst.x(), std::abs(e.x()) / d["sigma_dx_mm"].get<double>());
    if (d["sigma_dy_mm"].is_number())
      worst.y() = std::max(worst.y(), std::abs(e.y()) / d["sigma_dy_mm"].get<double>());
  }
  return worst;
}

TEST(PushbroomImageMode, ControlOnRenderedPixelsCalibratesWithinOneAndAHalfTheGeometryError) {
  const std::string data = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (data.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  TempDir tmp("aerocal_pushbroom_images");
  const std::string sim = tmp.File("sim");
  const auto s =
      RunAerocal("simulate --pushbroom --render-images --texture " + data +
                 "/images/img_4880.jpg --detectors 200 --lines 800 --seed 1 --out " + sim);
  ASSERT_EQ(s.exit_code, 0) << s.output;
  for (const char* f : {"line_image.png",
                        "reference/camera.yaml",
                        "reference/exposures.csv",
                        "reference/ref1.png",
                        "reference/ref2.png"})
    EXPECT_TRUE(std::filesystem::exists(sim + "/" + f)) << f;

  const std::string control = tmp.File("control");
  const auto c = RunAerocal(PushbroomControlCommand(sim, control) + " --write-l1");
  ASSERT_EQ(c.exit_code, 0) << c.output;
  const json cj = testing::ReadJson(control + "/control.json");
  EXPECT_EQ(cj["kind"], "pushbroom_control");
  EXPECT_EQ(cj["schema_version"], ResultSchemaVersion("pushbroom_control"));
  EXPECT_GE(cj["n_points"].get<int>(), 250) << c.output;
  // Gross errors are few on clean synthetic pixels: below 5 % of the points.
  EXPECT_LT(cj["rejected"]["gross_error"].get<int>(), cj["n_points"].get<int>() / 20 + 1);
  EXPECT_TRUE(std::filesystem::exists(control + "/l1.png"));
  // The intersected points lie on the simulated terrain (relief 20 m: 10 sin(x/170 + 0.3)
  // cos(y/230 - 0.2), line_simulation.cc) within 4 of their own sigmas (RMS of the normalised
  // height error below 1.5: the sigmas are honest).
  const CsvTable points = CsvTable::Read(control + "/points.csv");
  double sum = 0;
  int n = 0;
  for (const auto& row : points.rows()) {
    const double x = points.Number(row, "X"), y = points.Number(row, "Y");
    const double dz =
        points.Number(row, "Z") - 10.0 * std::sin(x / 170.0 + 0.3) * std::cos(y / 230.0 - 0.2);
    sum += std::pow(dz / points.Number(row, "sZ"), 2);
    ++n;
  }
  EXPECT_LT(std::sqrt(sum / n), 1.5);

  const auto g = RunAerocal(PushbroomCalibrateCommand(
      sim, sim + "/observations.csv", sim + "/points.csv", tmp.File("geometry.json")));
  ASSERT_EQ(g.exit_code, 0) << g.output;
  const auto i = RunAerocal(PushbroomCalibrateCommand(
      sim, control + "/observations.csv", control + "/points.csv", tmp.File("image.json")));
  ASSERT_EQ(i.exit_code, 0) << i.output;
  const json gj = testing::ReadJson(tmp.File("geometry.json")),
             ij = testing::ReadJson(tmp.File("image.json"));
  ASSERT_TRUE(ij["valid"].get<bool>()) << i.output;
  const Eigen::Vector2d geometry = TableRmsPx(sim, gj, 0.01), image = TableRmsPx(sim, ij, 0.01);
  std::printf(
      "table RMS error across / along: geometry %.4f / %.4f px, image mode %.4f / %.4f px\n",
      geometry.x(),
      geometry.y(),
      image.x(),
      image.y());
  const Eigen::Vector2d worst = WorstNormalisedError(sim, ij);
  std::printf("image mode: worst |error| / sigma over the detectors across / along: %.2f / %.2f\n",
              worst.x(),
              worst.y());
  EXPECT_LE(image.x(), 1.5 * geometry.x());
  EXPECT_LE(image.y(), 1.5 * geometry.y());
}

}  // namespace
}  // namespace aerocal::triangulation
