// `aerocal flight` on a simulated flight: the workflow finishes, result.json has the FORMATS.md
// keys of every step, the calibrated camera is written, and report.html holds the tables and plots.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/file_digest.h"
#include "calib/core/result_file.h"
#include "stitch/image_io/image_io.h"
#include "tests/support/rendered_targets.h"
#include "tests/support/test_support.h"
#include "tools/observation_tables.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

namespace aerocal {
namespace {

// The rows of simulate --edge-targets' patches.csv (docs/formats.md "Edge target patches"), split.
std::vector<std::vector<std::string>> PatchRows(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::vector<std::string>> rows;
  std::string line;
  for (int n = 0; std::getline(in, line); ++n) {
    if (n < 2) continue;  // the comment and the header
    std::vector<std::string> f;
    std::stringstream fields(line);
    for (std::string v; std::getline(fields, v, ',');) f.push_back(v);
    rows.push_back(f);
  }
  return rows;
}

// A patch's top-left pixel in the full image less its tile's place in the mosaic (tiles of 112 px,
// the region at `region_col`, `region_row` lies in the tile): the --image-origin of the mosaic
// file.
std::string MosaicOrigin(const std::string& origin_col,
                         const std::string& origin_row,
                         const std::string& region_col,
                         const std::string& region_row) {
  constexpr int kTile = 112;
  return std::to_string(std::stoi(origin_col) - std::stoi(region_col) / kTile * kTile) + "," +
         std::to_string(std::stoi(origin_row) - std::stoi(region_row) / kTile * kTile);
}

class FlightWorkflow : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("aerocal_flight");
    const auto sim =
        testing::RunAerocal("simulate --out " + dir_->File("data") +
                            " --seed 3 --stitch-ties 200 --gnss-sigma-m 0.05 --edge-targets");
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
    MeasureEdgeTargetPatches();
    WriteFileAtomically(dir_->File("lab.yaml"),
                        "certificate: {number: F-7, date: 2026-11-24}\n"
                        "camera: {make: Sim, model: Four-CCD}\n");
    // A Siemens star's reading (`quality star`) for the certificate's resolution section.
    stitch::WriteGrayImage(
        dir_->File("star.png"),
        testing::RenderSiemensStar(220, 12, {109.5, 109.5}, 0.0, 1.0, 30.0, 220.0),
        8);
    const auto star =
        testing::RunAerocal("quality star --image " + dir_->File("star.png") +
                            " --centre 109.5,109.5 --cycles 12 --outer-radius-px 100 --gsd-m 0.05 "
                            "--out " +
                            dir_->File("star.json"));
    ASSERT_EQ(star.exit_code, 0) << star.output;
    run_ = new testing::CommandResult(testing::RunAerocal(
        "flight --camera " + dir_->File("data/camera_nominal.yaml") + " --data " +
        dir_->File("data") + " --base III,IV --out " + dir_->File("report") +
        " --camera-format metashape --certificate --lab " + dir_->File("lab.yaml") + " --quality " +
        dir_->File("star.json") + *quality_options_));
  }
  // simulate --edge-targets wrote mosaics of edge patches (raw_<SUB>.tif per sub-image and
  // virtual.tif) and patches.csv with the regions to measure: `quality mtf` on each mosaic,
  // quality_<mosaic>.json (named raw sub-image or virtual); all go into result.json (the report's
  // resolution section) and the certificate.
  static void MeasureEdgeTargetPatches() {
    std::map<std::string, std::string> rois;  // by mosaic file
    for (const auto& f : PatchRows(dir_->File("data/edge_targets/patches.csv"))) {
      ASSERT_EQ(f.size(), 21u);
      rois[f[4]] += " --roi " + f[5] + "," + f[6] + "," + f[7] + "," + f[8];
      rois[f[9]] += " --roi " + f[10] + "," + f[11] + "," + f[12] + "," + f[13];
      ++edge_patches_;
    }
    ASSERT_GE(edge_patches_, 8);
    quality_options_ = new std::string;
    for (const auto& [file, roi] : rois) {
      const std::string stem = file.substr(0, file.find('.'));  // raw_<SUB> or virtual
      const std::string which = stem == "virtual" ? " --virtual" : " --sub-image " + stem.substr(4);
      const std::string out = dir_->File("quality_" + stem + ".json");
      const auto r =
          testing::RunAerocal("quality mtf --image " + dir_->File("data/edge_targets/" + file) +
                              roi + which + " --flight-axis x --pixel-size-mm 0.009 --out " + out);
      ASSERT_EQ(r.exit_code, 0) << file << ": " << r.output;
      *quality_options_ += " --quality " + out;
    }
  }
  static void TearDownTestSuite() {
    delete quality_options_;
    delete run_;
    delete dir_;
  }
  static testing::TempDir* dir_;
  static testing::CommandResult* run_;
  static int edge_patches_;
  static std::string* quality_options_;  // --quality of every edge targets' result
};
testing::TempDir* FlightWorkflow::dir_ = nullptr;
testing::CommandResult* FlightWorkflow::run_ = nullptr;
int FlightWorkflow::edge_patches_ = 0;
std::string* FlightWorkflow::quality_options_ = nullptr;

TEST_F(FlightWorkflow, FinishesAndWritesResultsWithTheFormatsKeys) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto doc = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  EXPECT_EQ(doc["kind"], "flight");
  EXPECT_EQ(doc["schema_version"], kResultSchemaVersion);
  EXPECT_EQ(doc["camera_model"]["name"], "brown_fraser_10");
  // Every file read, with its SHA-256 (issue 33 item 1): the virtual project's and the joint
  // step's sub-image project's, each once.
  std::set<std::string> roles, paths;
  for (const auto& f : doc["inputs"]) {
    roles.insert(f["role"].get<std::string>());
    EXPECT_TRUE(paths.insert(f["path"].get<std::string>()).second) << f.dump();
    EXPECT_EQ(f["sha256"].get<std::string>().size(), 64u);
    EXPECT_EQ(f["bytes"].get<std::uintmax_t>(),
              std::filesystem::file_size(f["path"].get<std::string>()));
  }
  for (const char* role : {"project", "exposures", "observations", "points", "stitching"})
    EXPECT_EQ(roles.count(role), 1u) << role;
  // Not a terminal: one progress line per stage (issue 33 item 6), the report the last.
  for (const char* line :
       {"flight: 1/6 stitching (", "flight: 5/6 result (", "flight: 6/6 report ("})
    EXPECT_NE(run_->output.find(line), std::string::npos) << line << "\n" << run_->output;
  const auto& stitching = doc["stitching"];
  for (const char* key : {"kind",
                          "sigma0",
                          "sigma0_px",
                          "redundancy",
                          "iterations",
                          "converged",
                          "model",
                          "subimages",
                          "frames",
                          "stability"})
    EXPECT_TRUE(stitching.contains(key)) << "stitching." << key;
  EXPECT_EQ(stitching["frames"].size(), 37u);
  EXPECT_NEAR(stitching["stability"]["mean_sigma0_px"].get<double>(), 0.1, 0.01);
  ASSERT_EQ(doc["adjustments"].size(), 3u);
  const char* names[] = {"conventional", "self_calibration", "joint"};
  for (int i = 0; i < 3; ++i) {
    const auto& a = doc["adjustments"][i];
    EXPECT_EQ(a["name"], names[i]);
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
                            "rejected"})
      EXPECT_TRUE(a.contains(key)) << names[i] << "." << key;
    EXPECT_EQ(a["kind"], "adjust");
    EXPECT_TRUE(a["converged"].get<bool>());
    EXPECT_EQ(a["check"]["rmse_m"].size(), 3u);
    // Every image observation has its residual (the report's residual plot), at the noise level.
    const auto& residuals = a["residuals"];
    ASSERT_GT(residuals.size(), 1000u) << names[i];
    double sum2 = 0.0;
    for (const auto& v : residuals)
      for (const char* key : {"image", "point", "col", "row", "v_col_px", "v_row_px", "used"})
        ASSERT_TRUE(v.contains(key)) << names[i] << ".residuals[]." << key;
    for (const auto& v : residuals)
      sum2 += std::pow(v["v_col_px"].get<double>(), 2) + std::pow(v["v_row_px"].get<double>(), 2);
    EXPECT_LT(std::sqrt(sum2 / (2.0 * residuals.size())), 0.35) << names[i] << ": RMS residual, px";
    // Check points are counted with all their rays, virtual or raw sub-image.
    for (const auto& p : a["check"]["points"]) ASSERT_GE(p["rays"].get<int>(), 2) << names[i];
  }
  // The joint run measures in raw sub-images: its residuals name the sub-image and its (u, v).
  EXPECT_TRUE(doc["adjustments"][2]["residuals"][0].contains("subimage"));
  // Image sigma 0.2 px injected: sigma0 in px at the noise level for the self-calibrating runs.
  EXPECT_NEAR(doc["adjustments"][1]["sigma0_px"].get<double>(), 0.2, 0.02);
  EXPECT_NEAR(doc["adjustments"][2]["sigma0_px"].get<double>(), 0.2, 0.02);
  EXPECT_TRUE(doc["adjustments"][2].contains("subimages"));
  // Self-calibration removes the systematic error the conventional run shows in the check points.
  const auto spatial = [&](int i) {
    const auto& r = doc["adjustments"][i]["check"]["rmse_m"];
    return std::sqrt(std::pow(r[0].get<double>(), 2) + std::pow(r[1].get<double>(), 2) +
                     std::pow(r[2].get<double>(), 2));
  };
  EXPECT_GT(spatial(0), 1.5 * spatial(1));
  // The calibrated camera reads back and carries the estimate.
  const auto camera = calib::ReadCamera(dir_->File("report/camera_calibrated.yaml"));
  const auto truth = calib::ReadCamera(dir_->File("data/camera_truth.yaml"));
  EXPECT_NEAR(camera.interior[0], truth.interior[0], 0.01);
  EXPECT_EQ(camera.subimages.size(), 6u);
  // --camera-format metashape: the same camera for Metashape (a forward model: a fit, its residual
  // printed), with the interior sigmas as a covariance.
  const std::string metashape = ReadTextFile(dir_->File("report/camera_calibrated.metashape"));
  EXPECT_NE(metashape.find("<calibration"), std::string::npos);
  EXPECT_NE(run_->output.find("camera as metashape (metashape_frame): least-squares fit"),
            std::string::npos)
      << run_->output;
}

TEST_F(FlightWorkflow, CertificateOfTheInFlightCalibration) {
  // `flight --certificate` writes the certificate form of the in-flight calibration (the joint
  // adjustment's camera and its budget) as `aerocal certificate --result result.json` does; HTML
  // and PDF rendered.
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto cert = aerocal::testing::ReadJson(dir_->File("report/certificate/certificate.json"));
  EXPECT_EQ(cert["method"]["kind"], "in-flight calibration");
  EXPECT_EQ(cert["lab"]["certificate"]["number"], "F-7");
  // The certificate names the flight's result.json where it ends, not where it was staged.
  EXPECT_EQ(cert["source"], dir_->File("report/result.json"));
  const auto doc = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  const auto& joint = doc["adjustments"][2];  // the joint adjustment's camera is the certified one
  ASSERT_EQ(joint["name"], "joint");
  bool has_c = false;
  for (const auto& q : cert["results"]) {
    if (q["quantity"] != "c") continue;
    has_c = true;
    const double sigma = joint["cameras"][0]["sigma"]["c"].get<double>();
    EXPECT_DOUBLE_EQ(q["value"].get<double>(), joint["cameras"][0]["estimated"]["c"].get<double>());
    // The test field's default components (issue 33): A image measurements, B control
    // coordinates (the joint adjustment's Q N_control Q), B pixel pitch (no tolerance in the
    // simulated camera file: zero, said so). The adjustment's variance splits as
    // sigma^2 = u_image^2 + sigma0^2 u_control^2; U = k u_c.
    const auto& c = q["components"];
    ASSERT_EQ(c.size(), 3u) << c.dump();
    EXPECT_EQ(c[0]["source"], "image measurements");
    EXPECT_EQ(c[0]["type"], "A");
    EXPECT_EQ(c[1]["source"], "control coordinates");
    EXPECT_EQ(c[1]["type"], "B");
    EXPECT_EQ(c[2]["source"], "pixel pitch");
    const double u_image = c[0]["u"], u_control = c[1]["u"], u_pitch = c[2]["u"];
    const double s0 = joint["sigma0"];
    EXPECT_GT(u_control, 0.0);
    EXPECT_EQ(u_pitch, 0.0);
    EXPECT_NEAR(
        u_image * u_image + s0 * s0 * u_control * u_control, sigma * sigma, 1e-9 * sigma * sigma);
    const double u_c = std::sqrt(u_image * u_image + u_control * u_control);
    EXPECT_NEAR(q["U"].get<double>(), q["k"].get<double>() * u_c, 1e-12 * u_c);
    EXPECT_NE(q["statement"].get<std::string>().find("(k = 2)"), std::string::npos)
        << q["statement"];
  }
  EXPECT_TRUE(has_c);
  // --quality: the dynamic image resolution section from the star's reading and the edge targets
  // of the raw sub-images and of the virtual image (each patch in both), as result.json has it.
  ASSERT_EQ(cert["dynamic_image_resolution"]["stars"].size(), 1u);
  EXPECT_EQ(cert["dynamic_image_resolution"]["edges"].size(),
            2 * static_cast<size_t>(edge_patches_));
  EXPECT_GE(cert["dynamic_image_resolution"]["axes"].size(), 6u);  // virtual x, y + raw per CCD
  EXPECT_EQ(cert["dynamic_image_resolution"]["resampling_loss"].size(), 2u);
  EXPECT_EQ(cert["dynamic_image_resolution"], doc["dynamic_image_resolution"]);
  EXPECT_EQ(cert["dynamic_image_resolution"]["stars"][0]["limiting_frequency_cy_px"],
            aerocal::testing::ReadJson(dir_->File("star.json"))["limiting_frequency_cy_px"]);
  const std::string html = ReadTextFile(dir_->File("report/certificate/certificate.html"));
  for (const char* text : {"Calibration certificate",
                           "F-7",
                           "in-flight calibration",
                           "Uncertainty budget",
                           "9. Dynamic image resolution",
                           "resampling loss",
                           "Siemens star"})
    EXPECT_NE(html.find(text), std::string::npos) << text;
  // The certificate command on the flight's result.json gives the same data (its source apart).
  const auto r =
      testing::RunAerocal("certificate --result " + dir_->File("report/result.json") + " --lab " +
                          dir_->File("lab.yaml") + " --quality " + dir_->File("star.json") +
                          *quality_options_ + " --no-render --out " + dir_->File("cert"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto again = aerocal::testing::ReadJson(dir_->File("cert/certificate.json"));
  auto first = cert;
  again.erase("source");
  first.erase("source");
  EXPECT_EQ(first, again);
  // Every PDF page rendered to PNG (poppler's pdftoppm).
  if (testing::RunCommand("command -v pdftoppm").exit_code != 0)
    GTEST_SKIP()
        << "pdftoppm is absent (Debian package poppler-utils): the PDF pages are not rendered";
  const auto png = testing::RunCommand("pdftoppm -r 30 -png " +
                                       dir_->File("report/certificate/certificate.pdf") + " " +
                                       dir_->File("page"));
  ASSERT_EQ(png.exit_code, 0) << png.output;
  int pages = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir_->path()))
    if (e.path().extension() == ".png" && std::filesystem::file_size(e.path()) > 1000) ++pages;
  EXPECT_GE(pages, 2);
}

TEST_F(FlightWorkflow, CertificatePixelPitchComponentFromTheCameraFile) {
  // The flight's camera file states the pitch's tolerance +-T: the pixel pitch component of c is
  // |dc/dpitch| T / sqrt 3 with dc/dpitch = c / pitch (a pitch s times the stated one makes
  // every photo length, c among them, s times longer; uncertainty_budget.h).
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  constexpr double kTolerance = 2e-5;  // mm
  WriteFileAtomically(dir_->File("camera_tolerance.yaml"),
                      ReadTextFile(dir_->File("data/camera_nominal.yaml")) +
                          "pixel_size_tolerance_mm: " + std::to_string(kTolerance) + "\n");
  auto doc = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  doc["camera"] = dir_->File("camera_tolerance.yaml");
  WriteFileAtomically(dir_->File("pitch/result.json"), doc.dump());
  const auto r = testing::RunAerocal("certificate --result " + dir_->File("pitch/result.json") +
                                     " --no-render --out " + dir_->File("pitch"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto cert = aerocal::testing::ReadJson(dir_->File("pitch/certificate.json"));
  const double pitch = doc["camera_format"]["pixel_size_mm"];
  bool has_c = false;
  for (const auto& q : cert["results"]) {
    if (q["quantity"] != "c") continue;
    has_c = true;
    const auto& pixel = q["components"][2];
    ASSERT_EQ(pixel["source"], "pixel pitch");
    const double c = q["value"];
    EXPECT_NEAR(pixel["u"].get<double>(),
                c / pitch * kTolerance / std::sqrt(3.0),
                1e-6 * c / pitch * kTolerance);
    EXPECT_NE(pixel["origin"].get<std::string>().find("camera_tolerance.yaml"), std::string::npos);
  }
  EXPECT_TRUE(has_c);
}

// Every file under `folder` (relative path -> content).
std::map<std::string, std::string> Snapshot(const std::string& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(folder))
    if (e.is_regular_file())
      files[std::filesystem::relative(e.path(), folder).string()] = ReadTextFile(e.path().string());
  return files;
}

// The flight example of issue 36: the edge targets' MTF50 per axis, measured by `quality mtf` on
// the raw sub-images' patches and on the virtual image's (resampled bilinearly from them). Raw:
// the PSF's (s = 1 px) and the pixel's analytic 0.1800 cycles/px at a 5 deg slant; virtual: lower
// by bilinear interpolation's loss at the mappings' sub-pixel shifts, 1-10 % per patch (the
// per-patch prediction is tested in triangulation/flight_simulator).
TEST_F(FlightWorkflow, EdgeTargetsShowTheLossOfBilinearResampling) {
  std::map<std::string, std::vector<double>> raw;  // MTF50 by axis, over the sub-images
  for (const auto& e : std::filesystem::directory_iterator(dir_->path()))
    if (e.path().filename().string().rfind("quality_raw_", 0) == 0) {
      const auto doc = aerocal::testing::ReadJson(e.path().string());
      for (const auto& edge : doc["edges"])
        raw[edge["axis"].get<std::string>()].push_back(edge["mtf50_cy_px"].get<double>());
    }
  const auto virt = aerocal::testing::ReadJson(dir_->File("quality_virtual.json"));
  EXPECT_EQ(virt["edges"].size(), static_cast<size_t>(edge_patches_));
  for (const char* axis : {"x", "y"}) {
    ASSERT_GE(raw[axis].size(), 4u) << axis;
    double mean = 0.0;
    for (double v : raw[axis]) mean += v / raw[axis].size();
    const auto& a = virt["axes"][axis];
    EXPECT_EQ(a["direction"], std::string(axis) == "x" ? "along_track" : "across_track");
    EXPECT_NEAR(mean, 0.1800, 0.002) << axis;  // 1.1 %: the raw edges' U is about 1.2 %
    // The virtual image's combined MTF50 and its U (k = 2) lie below the raw mean.
    EXPECT_LT(a["mtf50_cy_px"].get<double>() + a["mtf50_expanded_cy_px"].get<double>(), mean)
        << axis;
  }
}

// `quality mtf --targets` (issue 36 item 1): each virtual patch's edge region found by projecting
// the target's ground ends with the flight's adjusted camera and exposure, instead of the --roi
// the simulator wrote. The tile of patch k is a window of the virtual image whose top-left pixel
// is the patch's origin less the tile's place in the mosaic (8 tiles of 112 px a row). The MTF50
// agrees with the --roi measurement's within its U (k = 2), and the projected edge lies within a
// pixel of the measured one (the adjustment's orientation error is a few hundredths of a px).
TEST_F(FlightWorkflow, EdgeRegionsFoundFromTargetsAndTheAdjustedOrientation) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto by_roi = aerocal::testing::ReadJson(dir_->File("quality_virtual.json"));
  const auto rows = PatchRows(dir_->File("data/edge_targets/patches.csv"));
  const std::string common = "quality mtf --image " + dir_->File("data/edge_targets/virtual.tif") +
                             " --virtual --targets " + dir_->File("data/edge_targets/targets.csv") +
                             " --camera " + dir_->File("report/camera_calibrated.yaml") +
                             " --orientation " + dir_->File("report/result.json") +
                             " --target-length-px 64 --target-half-width-px 32";
  int k = -1;
  while (k < 5 && k + 1 < static_cast<int>(rows.size())) {
    const auto& f = rows[++k];
    const std::string line = f[0] + " in " + f[1];
    const std::string out = dir_->File("targets_" + std::to_string(k) + ".json");
    const auto r = testing::RunAerocal(common + " --image-id " + f[1] + " --target " + f[0] +
                                       " --image-origin " +
                                       MosaicOrigin(f[16], f[17], f[10], f[11]) + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << line << "\n" << r.output;
    const auto doc = aerocal::testing::ReadJson(out);
    ASSERT_EQ(doc["edges"].size(), 1u) << line;
    const auto& found = doc["edges"][0];
    const auto& given = by_roi["edges"][k];
    EXPECT_EQ(found["target"], f[0]);
    EXPECT_EQ(found["axis"], f[3]);
    EXPECT_NEAR(found["mtf50_cy_px"].get<double>(),
                given["mtf50_cy_px"].get<double>(),
                given["mtf50_expanded_cy_px"].get<double>())
        << line;
    EXPECT_NEAR(
        found["edge_offset_px"].get<double>(), found["projected_offset_px"].get<double>(), 1.0)
        << line;
  }
  ASSERT_EQ(k, 5);
  // The whole mosaic taken as the image's top-left corner: every target of the image lies outside
  // the file; each is skipped by name and counted, nothing is measured (exit 3).
  const auto none =
      testing::RunAerocal(common + " --image-id 0003 --out " + dir_->File("targets_none.json"));
  EXPECT_EQ(none.exit_code, 3) << none.output;
  const auto doc = aerocal::testing::ReadJson(dir_->File("targets_none.json"));
  EXPECT_EQ(doc["targets"]["found"], 0);
  EXPECT_EQ(doc["targets"]["skipped_count"], 8);
  EXPECT_EQ(doc["targets"]["skipped"].size(), 8u);
  // Bad input: an image the result does not hold, a target row with a bad number (exit 2,
  // FILE:LINE).
  const auto unknown =
      testing::RunAerocal(common + " --image-id 9999 --out " + dir_->File("targets_bad.json"));
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("no exposure of image '9999'"), std::string::npos)
      << unknown.output;
  WriteFileAtomically(
      dir_->File("bad_targets.csv"),
      "id,start_x,start_y,start_z,end_x,end_y,end_z\nT1,0,0,0,1,1,0\nT2,0,x,0,1,1,0\n");
  const auto bad = testing::RunAerocal(
      "quality mtf --image " + dir_->File("data/edge_targets/virtual.tif") + " --targets " +
      dir_->File("bad_targets.csv") + " --camera " + dir_->File("report/camera_calibrated.yaml") +
      " --orientation " + dir_->File("report/result.json") + " --image-id 0003 --out " +
      dir_->File("targets_bad.json"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("bad_targets.csv:3"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("targets_bad.json")));
}

// `flight --quality`: result.json and report.html state the resampling loss per axis, the virtual
// image's MTF50 against the mean of the raw sub-images' (each the combined MTF50 of its edges),
// with its U (k = 2) from the results' standard uncertainties.
TEST_F(FlightWorkflow, TheReportStatesTheResamplingLossWithItsUncertainty) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto doc = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  const auto& section = doc["dynamic_image_resolution"];
  const auto virt = aerocal::testing::ReadJson(dir_->File("quality_virtual.json"));
  const std::string html = ReadTextFile(dir_->File("report/report.html"));
  for (const char* text : {"10. Dynamic image resolution",
                           "id=\"resolution-axes\"",
                           "id=\"resolution-loss\"",
                           "id=\"resolution-limits\"",
                           "id=\"resolution-edges\"",
                           "sub-image I",
                           "virtual image"})
    EXPECT_NE(html.find(text), std::string::npos) << text;
  ASSERT_EQ(section["resampling_loss"].size(), 2u);
  for (const auto& loss : section["resampling_loss"]) {
    const std::string axis = loss["axis"];
    double sum = 0.0, sum_u2 = 0.0;
    int n = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_->path()))
      if (e.path().filename().string().rfind("quality_raw_", 0) == 0) {
        const auto raw = aerocal::testing::ReadJson(e.path().string());
        if (!raw["axes"].contains(axis)) continue;
        sum += raw["axes"][axis]["mtf50_cy_px"].get<double>();
        sum_u2 += std::pow(raw["axes"][axis]["mtf50_u_cy_px"].get<double>(), 2);
        ++n;
      }
    ASSERT_GE(n, 2) << axis;
    EXPECT_EQ(loss["sub_images"].size(), static_cast<size_t>(n));
    const double raw_mean = sum / n, virtual_mtf50 = virt["axes"][axis]["mtf50_cy_px"];
    const double u = std::hypot(std::sqrt(sum_u2) / n, virt["axes"][axis]["mtf50_u_cy_px"]);
    EXPECT_NEAR(loss["raw_mean_mtf50_cy_px"].get<double>(), raw_mean, 1e-12);
    EXPECT_NEAR(loss["loss_cy_px"].get<double>(), raw_mean - virtual_mtf50, 1e-12);
    EXPECT_NEAR(loss["loss_expanded_cy_px"].get<double>(), 2.0 * u, 1e-12);
    // Bilinear resampling at the CCDs' sub-pixel shifts: 4.6 % and 7.5 % (stitch/quality/README),
    // both more than their U.
    const double percent = loss["loss_percent"];
    EXPECT_GT(percent, 2.0) << axis;
    EXPECT_LT(percent, 10.0) << axis;
    EXPECT_GT(loss["loss_cy_px"].get<double>(), loss["loss_expanded_cy_px"].get<double>()) << axis;
    char shown[32];
    std::snprintf(shown, sizeof shown, ">%.2f<", percent);
    EXPECT_NE(html.find(shown), std::string::npos) << shown;
  }
}

TEST_F(FlightWorkflow, AFailingLastPartReplacesNothingOfThePreviousFlight) {
  // result.json, camera_calibrated.yaml / .xml, report.html and certificate/ are one set (issue 37
  // class 8): the certificate renderer, the last part, fails; the previous flight stays as it was.
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const std::string out = dir_->File("report_set");
  std::filesystem::copy(dir_->File("report"), out, std::filesystem::copy_options::recursive);
  const auto before = Snapshot(out);
  ASSERT_GE(before.size(), 6u);
  WriteFileAtomically(dir_->File("fail.py"), "import sys\nsys.exit(1)\n");
  // The same flight from a copy of the camera file: result.json (which names it) would differ.
  std::filesystem::copy_file(dir_->File("data/camera_nominal.yaml"),
                             dir_->File("camera_copy.yaml"),
                             std::filesystem::copy_options::overwrite_existing);
  const auto r = testing::RunCommand(
      "AEROCAL_CERTIFICATE_SCRIPT=" + dir_->File("fail.py") + " " + testing::AerocalBinary() +
      " flight --camera " + dir_->File("camera_copy.yaml") + " --data " + dir_->File("data") +
      " --base III,IV --out " + out + " --camera-format metashape --certificate --lab " +
      dir_->File("lab.yaml"));
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("nothing written"), std::string::npos) << r.output;
  EXPECT_EQ(Snapshot(out), before);  // no file replaced, added (no staging folder) or removed
}

TEST_F(FlightWorkflow, CertificateOptionsAreCheckedBeforeTheFlightRuns) {
  // A bad lab file: FILE:LINE, exit 2, nothing written; --lab without --certificate: exit 2.
  WriteFileAtomically(dir_->File("bad_lab.yaml"), "certificate: {numbr: 1}\n");
  const std::string flight = "flight --camera " + dir_->File("data/camera_nominal.yaml") +
                             " --data " + dir_->File("data") + " --base III,IV --out " +
                             dir_->File("bad_report");
  const auto bad =
      testing::RunAerocal(flight + " --certificate --lab " + dir_->File("bad_lab.yaml"));
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("bad_lab.yaml:1"), std::string::npos) << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad_report/result.json")));
  const auto lone = testing::RunAerocal(flight + " --lab " + dir_->File("lab.yaml"));
  EXPECT_EQ(lone.exit_code, 2) << lone.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad_report/result.json")));
  // --quality with a file that is no quality result: exit 2 naming it, before the flight runs.
  const auto quality =
      testing::RunAerocal(flight + " --certificate --quality " + dir_->File("lab.yaml"));
  EXPECT_EQ(quality.exit_code, 2) << quality.output;
  EXPECT_NE(quality.output.find("lab.yaml"), std::string::npos) << quality.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad_report/result.json")));
}

TEST_F(FlightWorkflow, ReportHoldsTablesAndPlots) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const std::string html = ReadTextFile(dir_->File("report/report.html"));
  int images = 0;  // (std::regex recurses per character: too deep for base64 images)
  for (size_t at = html.find("src=\"data:image/png;base64,"); at != std::string::npos;
       at = html.find("src=\"data:image/png;base64,", at + 1))
    ++images;
  EXPECT_GE(images, 4)
      << "sigma0 per exposure, residual vectors, distortion curves, check-point map";
  EXPECT_GE(std::count(html.begin(), html.end(), '<'), 100);
  for (const char* text :
       {"<table", "conventional", "self", "joint", "sigma0", "RMSE", "K1", "stability"})
    EXPECT_NE(html.find(text), std::string::npos) << text;
  EXPECT_EQ(html.find("http://"), std::string::npos) << "the page must not need the network";
  EXPECT_EQ(html.find("https://"), std::string::npos) << "the page must not need the network";
}

// Issue 28: flight's self-calibration is `auto` by default (held parameters named), the
// check-point test and the origin of the written camera are in result.json; `none` is refused
// (flight calibrates), and so is a bad --suspect-effect-limit, each by name with exit 2.
TEST_F(FlightWorkflow, AutoSelfCalibrationCheckPointTestAndCameraOrigin) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto doc = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  const auto& self = doc["adjustments"][1];
  ASSERT_TRUE(self.contains("self_calibration_choice"));
  EXPECT_EQ(self["self_calibration_choice"]["candidates"].size(), 10u);
  ASSERT_TRUE(doc["check_point_test"]["tested"].get<bool>());
  EXPECT_FALSE(doc["check_point_test"]["worse"].get<bool>());
  EXPECT_EQ(doc["camera_written_from"]["adjustment"], "joint");
  for (const std::string bad :
       {"--self-calibration none", "--self-calibration Q7", "--suspect-effect-limit -1"}) {
    const auto r = testing::RunAerocal("flight --camera " + dir_->File("data/camera_nominal.yaml") +
                                       " --data " + dir_->File("data") + " --out " +
                                       dir_->File("bad") + " " + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_->File("bad/result.json"))) << bad;
  }
}

// The flight report's renderer, as `aerocal flight` runs it.
std::string ReportScript() { return AEROCAL_REPORT_SCRIPT; }

// The fixture's flight again with its residual tables as CSV beside result.json
// (--residuals-csv), report and certificate, with the same quality results (`quality`: the edge
// targets' --quality options): run once, for the tests below.
const testing::CommandResult& SplitFlight(const testing::TempDir& dir, const std::string& quality) {
  static const testing::CommandResult run = testing::RunAerocal(
      "flight --camera " + dir.File("data/camera_nominal.yaml") + " --data " + dir.File("data") +
      " --base III,IV --residuals-csv --certificate --lab " + dir.File("lab.yaml") + " --quality " +
      dir.File("star.json") + quality + " --out " + dir.File("again"));
  return run;
}

// Issue 33 item 7: a lab checksums its re-runs. `flight` twice on the same data gives the same
// result, the clock's timings aside (`seconds`, `timing`, `seconds_testing`): the
// flight runs several adjustments in one process, and the reduced system's layout once followed
// heap addresses (calib/problem/problem_builder.cc, the Ceres ordering).
TEST_F(FlightWorkflow, TwiceGivesTheSameResult) {
  // The second run (SplitFlight) writes its residual tables as CSV beside result.json
  // (--residuals-csv): read back, they must be the first run's inline arrays to the bit.
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto& r = SplitFlight(*dir_, *quality_options_);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::function<void(nlohmann::json&)> strip = [&](nlohmann::json& j) {
    if (j.is_object()) {
      for (const char* clock : {"seconds", "timing", "seconds_testing", "aerocal_version"})
        j.erase(clock);
      for (auto& [key, value] : j.items()) strip(value);
    } else if (j.is_array()) {
      for (auto& value : j) strip(value);
    }
  };
  auto first = aerocal::testing::ReadJson(dir_->File("report/result.json"));
  auto second = aerocal::testing::ReadJson(dir_->File("again/result.json"));
  testing::ExpectValidResult(second, dir_->File("again/result.json"));
  for (const auto& a : second["adjustments"]) {
    const std::string name = a["name"];
    ASSERT_FALSE(a.contains("residuals")) << name;
    ASSERT_TRUE(a.contains("residuals_file")) << name;
    EXPECT_EQ(a["residuals_file"]["path"], "residuals_" + name + ".csv");
    EXPECT_EQ(a["residuals_file"]["sha256"],
              Sha256Hex(ReadTextFile(dir_->File("again/residuals_" + name + ".csv"))));
  }
  // The stitching frames' residuals: one table, the frames without their arrays.
  const auto& stitching = second["stitching"];
  ASSERT_TRUE(stitching.contains("residuals_file"));
  EXPECT_EQ(stitching["residuals_file"]["path"], "residuals_stitching.csv");
  EXPECT_EQ(stitching["residuals_file"]["sha256"],
            Sha256Hex(ReadTextFile(dir_->File("again/residuals_stitching.csv"))));
  size_t frame_rows = 0;
  for (const auto& f : first["stitching"]["frames"]) frame_rows += f["residuals"].size();
  EXPECT_EQ(stitching["residuals_file"]["rows"], frame_rows);
  for (const auto& f : stitching["frames"]) ASSERT_FALSE(f.contains("residuals")) << f["frame"];
  // Every per-observation table is out of result.json: what stays is a small fraction (measured:
  // 10.7 MB inline, 5.6 MB with the adjustments' tables beside it, 2.0 MB with the stitching
  // frames' too; the rest is mostly the snooping and check-point tables).
  EXPECT_LT(std::filesystem::file_size(dir_->File("again/result.json")),
            0.25 * std::filesystem::file_size(dir_->File("report/result.json")));
  tools::InflateResidualTables(&second, dir_->File("again/result.json"));
  strip(first);
  strip(second);
  // The numbers of every step, to the last bit (issue 33 item 7: a lab checksums its re-runs; paths
  // and the written files' names differ between the runs). The solve and the covariance run on
  // copies of the blocks in BlockId order (ProblemBuilder::CopyInBlockOrder), so no heap address
  // reaches a number.
  std::function<int(const nlohmann::json&, const nlohmann::json&, const std::string&)> differ =
      [&](const nlohmann::json& a, const nlohmann::json& b, const std::string& path) -> int {
    if (a.is_number() && b.is_number()) {
      const double x = a.get<double>(), y = b.get<double>();
      const bool same = x == y;
      if (!same) ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump();
      return same ? 0 : 1;
    }
    if (a.type() != b.type() || a.size() != b.size()) {
      ADD_FAILURE() << path << ": differs in type or size";
      return 1;
    }
    int n = 0;
    if (a.is_object()) {
      for (auto it = a.begin(); it != a.end() && n < 5; ++it)
        n += b.contains(it.key()) ? differ(it.value(), b[it.key()], path + "/" + it.key()) : 1;
    } else if (a.is_array()) {
      for (size_t i = 0; i < a.size() && n < 5; ++i)
        n += differ(a[i], b[i], path + "[" + std::to_string(i) + "]");
    } else if (a != b) {
      ADD_FAILURE() << path << ": " << a.dump() << " vs " << b.dump();
      ++n;
    }
    return n;
  };
  for (const char* part : {"stitching", "adjustments", "comparison", "check_point_test"}) {
    ASSERT_TRUE(first.contains(part)) << part;
    EXPECT_EQ(differ(first[part], second[part], part), 0) << part;
  }
  EXPECT_EQ(ReadTextFile(dir_->File("report/camera_calibrated.yaml")),
            ReadTextFile(dir_->File("again/camera_calibrated.yaml")));
  // The Python readers (report_data.load, here through `export --tables`) see the same residuals.
  for (const char* out : {"report", "again"}) {
    const auto e =
        testing::RunAerocal("export --result " + dir_->File(std::string(out) + "/result.json") +
                            " --tables " + dir_->File(std::string(out) + "_tables"));
    ASSERT_EQ(e.exit_code, 0) << e.output;
  }
  for (const char* name : {"conventional", "self_calibration", "joint"})
    EXPECT_EQ(ReadTextFile(dir_->File(std::string("report_tables/") + name + "/residuals.csv")),
              ReadTextFile(dir_->File(std::string("again_tables/") + name + "/residuals.csv")))
        << name;
}

// Issue 33: `flight --certificate --residuals-csv` end to end. The certificate and the report
// are written from result.json with its tables beside it (the certificate's residual vectors are
// the inline run's), and a table changed afterwards is refused by every reader, by name, exit 2.
TEST_F(FlightWorkflow, CertificateAndReportReadTheResidualTables) {
  ASSERT_EQ(run_->exit_code, 0) << run_->output;
  const auto& r = SplitFlight(*dir_, *quality_options_);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  auto inline_cert = aerocal::testing::ReadJson(dir_->File("report/certificate/certificate.json"));
  auto split_cert = aerocal::testing::ReadJson(dir_->File("again/certificate/certificate.json"));
  ASSERT_GT(split_cert["residuals"].size(), 1000u);
  inline_cert.erase("source");
  split_cert.erase("source");
  EXPECT_EQ(inline_cert, split_cert);
  // The report: its residual figures and tables from the inflated arrays, as the inline run's.
  // (The row of the clock, "report written (UTC)", apart.)
  const auto without_clock = [](std::string html) {
    const size_t at = html.find("<tr><td>report written (UTC)</td>");
    if (at != std::string::npos) html.erase(at, html.find("</tr>", at) - at);
    return html;
  };
  const std::string html = ReadTextFile(dir_->File("again/report.html"));
  EXPECT_NE(html.find("<tr><td>report written (UTC)</td>"), std::string::npos);
  EXPECT_EQ(without_clock(html), without_clock(ReadTextFile(dir_->File("report/report.html"))));
  // A copy of the output with one table changed (a row's residual): each reader refuses it.
  const std::string copy = dir_->File("tampered");
  std::filesystem::copy(dir_->File("again"), copy, std::filesystem::copy_options::recursive);
  for (const std::string table : {"residuals_stitching.csv", "residuals_joint.csv"}) {
    const std::string path = copy + "/" + table;
    const std::string original = ReadTextFile(path);
    std::string changed = original;
    const size_t comma = changed.find(',', changed.find('\n') + 1);
    changed.insert(comma + 1, "X");
    WriteFileAtomically(path, changed);
    const std::string refused = table + ": SHA-256 differs";
    const auto cert = testing::RunAerocal("certificate --result " + copy + "/result.json --lab " +
                                          dir_->File("lab.yaml") + " --no-render --out " +
                                          dir_->File("tampered_cert"));
    EXPECT_EQ(cert.exit_code, 2) << table << ": " << cert.output;
    EXPECT_NE(cert.output.find(refused), std::string::npos) << cert.output;
    EXPECT_FALSE(std::filesystem::exists(dir_->File("tampered_cert/certificate.json")));
    const auto report = testing::RunCommand("python3 " + ReportScript() + " " + copy +
                                            "/result.json " + dir_->File("tampered.html"));
    EXPECT_EQ(report.exit_code, 2) << table << ": " << report.output;
    EXPECT_NE(report.output.find(refused), std::string::npos) << report.output;
    EXPECT_FALSE(std::filesystem::exists(dir_->File("tampered.html")));
    WriteFileAtomically(path, original);
  }
}

TEST(ResidualTables, EveryValueReadsBackAndQuotedTextSurvives) {
  // Untested and tested entries, a null w, a sub-image, a reason with commas and quotes.
  const nlohmann::json residuals = nlohmann::json::parse(R"([
    {"image": "A", "point": "P1", "col": 100.0, "row": 0.1, "v_col_px": 0.30000000000000004,
     "v_row_px": -1e-300, "sigma_px": 0.5, "used": true},
    {"image": "B", "point": "P,2", "col": 1.5, "row": 2.5, "v_col_px": 0.0, "v_row_px": 0.0,
     "sigma_px": 0.25, "used": false, "subimage": "III", "u": 10.25, "v": 20.5, "head": "h1",
     "r": [0.5, 0.0], "w_xy": [3.5, null], "mdb_sigma": [4.1, null], "mdb_px": [2.0, null],
     "group_size": 2, "verdict": "rejected", "reason": "w = 3.5 > 3.29, \"gross\" error"}
  ])");
  const std::string csv = tools::ResidualTableCsv(residuals);
  EXPECT_EQ(tools::ResidualTableFromCsv(csv, "t.csv"), residuals) << csv;
  EXPECT_NE(csv.find("\"P,2\""), std::string::npos) << csv;
  // A row with a field too few is refused with its line.
  try {
    tools::ResidualTableFromCsv(csv.substr(0, csv.rfind(',')) + "\n", "t.csv");
    ADD_FAILURE() << "a short row was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("t.csv:3:"), std::string::npos) << e.what();
  }
}

TEST(ResidualTables, StitchingFramesGoToOneTableAndComeBack) {
  // Four frames (one without residuals, an id with a comma), a null sigma; the table is written
  // beside result.json, the frames lose their arrays and get them back, bit for bit.
  testing::TempDir dir("aerocal_tables");
  const nlohmann::json frames = nlohmann::json::parse(R"([
    {"frame": "E1", "sigma0": 1.0, "residuals": [
      {"point": "t1", "subimage": "I", "kind": "tie", "vU_px": 0.1, "vV_px": -2e-17,
       "sigma_px": 0.25},
      {"point": "r1", "subimage": "II", "kind": "reference", "vU_px": 0.0, "vV_px": 1.5,
       "sigma_px": null}]},
    {"frame": "E,2", "residuals": [
      {"point": "t9", "subimage": "I", "kind": "tie", "vU_px": 1e-300, "vV_px": 3.0,
       "sigma_px": 0.25}]},
    {"frame": "E3", "residuals": []},
    {"frame": "E4", "residuals": [
      {"point": "t1", "subimage": "III", "kind": "tie", "vU_px": -0.30000000000000004,
       "vV_px": 7.0, "sigma_px": 0.5}]}])");
  const nlohmann::json original = {{"adjustments", nlohmann::json::array()},
                                   {"stitching", {{"frames", frames}}}};
  nlohmann::json doc = original;
  const auto written = tools::SplitResidualTables(&doc, dir.path());
  ASSERT_EQ(written, std::vector<std::string>{"residuals_stitching.csv"});
  const std::string table = dir.File("residuals_stitching.csv");
  EXPECT_EQ(doc["stitching"]["residuals_file"]["rows"], 4);
  EXPECT_EQ(doc["stitching"]["residuals_file"]["sha256"], Sha256Hex(ReadTextFile(table)));
  for (const auto& f : doc["stitching"]["frames"]) EXPECT_FALSE(f.contains("residuals"));
  EXPECT_NE(ReadTextFile(table).find("\n\"E,2\",t9,"), std::string::npos) << ReadTextFile(table);
  const nlohmann::json split = doc;
  tools::InflateResidualTables(&doc, dir.File("result.json"));
  EXPECT_EQ(doc, original);
  // A table naming a frame the result does not have (after the previous row's): FILE:LINE.
  const std::string text =
      "frame,point,subimage,kind,vU_px,vV_px,sigma_px\nE4,t1,I,tie,0,0,\nE1,t1,I,tie,0,0,\n";
  WriteFileAtomically(table, text);
  const auto expect_refused = [&](nlohmann::json doc, const std::string& message) {
    try {
      tools::InflateResidualTables(&doc, dir.File("result.json"));
      ADD_FAILURE() << "accepted: " << message;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  doc = split;
  doc["stitching"]["residuals_file"]["sha256"] = Sha256Hex(text);
  expect_refused(doc, "residuals_stitching.csv:3: frame 'E1'");
  // A changed table: refused by its checksum.
  expect_refused(split, "residuals_stitching.csv: SHA-256 differs");
  // Two frames with one id: their rows could not be given back; the arrays stay inline.
  doc = original;
  doc["stitching"]["frames"][3]["frame"] = "E1";
  std::filesystem::remove(table);
  EXPECT_TRUE(tools::SplitResidualTables(&doc, dir.path()).empty());
  EXPECT_TRUE(doc["stitching"]["frames"][0].contains("residuals"));
  EXPECT_FALSE(std::filesystem::exists(table));
}

TEST(FlightWorkflowInput, MissingProjectIsABadInput) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir.File("data"));
  std::ofstream(dir.File("cam.yaml"))
      << "pixel_size_mm: 0.009\nformat_px: [100, 100]\ninterior: {c: 50}\n";
  const auto r = testing::RunAerocal("flight --camera " + dir.File("cam.yaml") + " --data " +
                                     dir.File("data") + " --out " + dir.File("out"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("project.yaml"), std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(dir.File("out/result.json")));
}

// `quality mtf --targets --sub-image --mapping --virtual-image` (issue 36 item 3): a patch's edge
// found in its raw sub-image (the target projected into the virtual image with the flight's
// adjusted camera and exposure, then through the flight's stitching mappings, the flight's mean,
// into the sub-image), measured there and, in the same run, in the virtual image resampled from
// it. (One exposure's own mappings, --frame, are off the true ones by up to 1 px here: a frame has
// few ties; the simulator resampled with the true mappings, which the mean meets within 0.1 px.)
// Per edge: the raw MTF50 at least the virtual one less its U; the virtual MTF50 within U (k = 2)
// of the one predicted from the raw edge by bilinear interpolation at the mapping's sub-pixel
// shifts. The first patch of every sub-image and axis (8 of the 33: a run costs 0.2-0.4 s, mostly
// the program's start); the second flight's result.json (SplitFlight, the same result with its
// residuals in CSV tables) is read, 2 MB instead of 10 MB, twice a run.
TEST_F(FlightWorkflow, RawSubImageEdgesFromTargetsStateTheResamplingLossPerEdge) {
  ASSERT_EQ(SplitFlight(*dir_, *quality_options_).exit_code, 0);
  const std::string patches = dir_->File("data/edge_targets/"), result = dir_->File("again/");
  const std::string common = "quality mtf --targets " + patches + "targets.csv --camera " + result +
                             "camera_calibrated.yaml --orientation " + result +
                             "result.json --mapping " + result + "result.json --virtual-image " +
                             patches + "virtual.tif --flight-axis x";
  const auto rows = PatchRows(patches + "patches.csv");
  ASSERT_EQ(rows.size(), static_cast<size_t>(edge_patches_));
  double worst_prediction = 0.0;   // |measured - predicted| / U over the edges
  std::set<std::string> measured;  // sub-image and axis
  for (size_t k = 0; k < rows.size(); ++k) {
    const auto& f = rows[k];
    if (!measured.insert(f[2] + "/" + f[3]).second) continue;
    const std::string out = dir_->File("raw_targets_" + std::to_string(k) + ".json");
    const auto r = testing::RunAerocal(
        common + " --image " + patches + f[4] + " --sub-image " + f[2] + " --image-id " + f[1] +
        " --target " + f[0] + " --image-origin " + MosaicOrigin(f[14], f[15], f[5], f[6]) +
        " --virtual-origin " + MosaicOrigin(f[16], f[17], f[10], f[11]) + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << f[0] << " in " << f[1] << "/" << f[2] << "\n" << r.output;
    const auto doc = aerocal::testing::ReadJson(out);
    ASSERT_EQ(doc["edges"].size(), 1u) << f[0];
    const auto& edge = doc["edges"][0];
    EXPECT_EQ(doc["sub_image"], f[2]);
    EXPECT_EQ(edge["target"], f[0]);
    EXPECT_EQ(edge["axis"], f[3]);
    const auto& loss = edge["resampling"];
    ASSERT_TRUE(loss["virtual_mtf50_cy_px"].is_number()) << loss.dump();
    const double raw = edge["mtf50_cy_px"], virt = loss["virtual_mtf50_cy_px"];
    EXPECT_GE(raw, virt - loss["virtual_mtf50_expanded_cy_px"].get<double>()) << f[0];
    const double u = loss["measured_minus_predicted_expanded_cy_px"];
    EXPECT_NEAR(loss["measured_minus_predicted_cy_px"].get<double>(), 0.0, u) << f[0];
    worst_prediction = std::max(worst_prediction,
                                std::abs(loss["measured_minus_predicted_cy_px"].get<double>()) / u);
  }
  EXPECT_EQ(measured.size(), 8u);  // 4 sub-images (I, II, V, VI) x 2 axes
  // Without --mapping the camera file's own mappings: a flight's camera_calibrated.yaml holds the
  // flight-mean mappings, so the shifts agree.
  const auto& f = rows.front();
  const auto own = testing::RunAerocal(
      "quality mtf --targets " + patches + "targets.csv --camera " + result +
      "camera_calibrated.yaml --orientation " + result + "result.json --image " + patches + f[4] +
      " --sub-image " + f[2] + " --image-id " + f[1] + " --target " + f[0] + " --image-origin " +
      MosaicOrigin(f[14], f[15], f[5], f[6]) + " --out " + dir_->File("raw_own.json"));
  ASSERT_EQ(own.exit_code, 0) << own.output;
  const auto by_camera = aerocal::testing::ReadJson(dir_->File("raw_own.json"))["edges"][0];
  const auto by_stitch = aerocal::testing::ReadJson(dir_->File("raw_targets_0.json"))["edges"][0];
  for (int i = 0; i < 2; ++i)
    EXPECT_NEAR(by_camera["resampling"]["mean_shift_px"][i].get<double>(),
                by_stitch["resampling"]["mean_shift_px"][i].get<double>(),
                0.01);
  EXPECT_FALSE(by_camera["resampling"].contains("virtual_mtf50_cy_px"));  // no --virtual-image
  std::printf("worst |measured - predicted| / U: %.2f\n", worst_prediction);
}

// Bad input to --targets on a raw sub-image: a sub-image the camera lacks names --sub-image, a
// stitch result whose sub-images do not match the camera, or without the --frame asked for, names
// the file (exit 2, nothing written). A sub-image that does not see the edge skips it by name
// (exit 3: nothing measured).
TEST_F(FlightWorkflow, RawSubImageTargetsRefuseMappingsThatDoNotMatch) {
  ASSERT_EQ(SplitFlight(*dir_, *quality_options_).exit_code, 0);
  const std::string patches = dir_->File("data/edge_targets/"), result = dir_->File("again/");
  const auto f = PatchRows(patches + "patches.csv").front();
  const std::string out = dir_->File("raw_bad.json");
  const std::string common = "quality mtf --image " + patches + f[4] + " --targets " + patches +
                             "targets.csv --camera " + result + "camera_calibrated.yaml" +
                             " --orientation " + result + "result.json --image-id " + f[1] +
                             " --target " + f[0] + " --out " + out;
  const std::string mapping = " --mapping " + result + "result.json";
  const auto unknown = testing::RunAerocal(common + mapping + " --sub-image IX");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("--sub-image: no sub-image 'IX'"), std::string::npos)
      << unknown.output;
  const auto frame =
      testing::RunAerocal(common + mapping + " --sub-image " + f[2] + " --frame 9999");
  EXPECT_EQ(frame.exit_code, 2) << frame.output;
  EXPECT_NE(frame.output.find("no result for frame 9999"), std::string::npos) << frame.output;
  // The flight's stitching with one sub-image renamed: it no longer matches the camera.
  auto doc = aerocal::testing::ReadJson(result + "result.json");
  doc["stitching"]["subimages"][0]["id"] = "Z";
  WriteFileAtomically(dir_->File("bad_mapping.json"), doc.dump());
  const auto mismatch = testing::RunAerocal(common + " --sub-image " + f[2] + " --mapping " +
                                            dir_->File("bad_mapping.json"));
  EXPECT_EQ(mismatch.exit_code, 2) << mismatch.output;
  EXPECT_NE(mismatch.output.find("bad_mapping.json: stitching: sub-image Z is not in the camera"),
            std::string::npos)
      << mismatch.output;
  EXPECT_FALSE(std::filesystem::exists(out));
  // The edge mapped into another sub-image: outside it, skipped by name.
  const std::string other = f[2] == "I" ? "VI" : "I";
  const auto outside = testing::RunAerocal(common + mapping + " --sub-image " + other);
  EXPECT_EQ(outside.exit_code, 3) << outside.output;
  const auto skipped = aerocal::testing::ReadJson(out);
  ASSERT_EQ(skipped["targets"]["skipped"].size(), 1u);
  EXPECT_NE(skipped["targets"]["skipped"][0]["reason"].get<std::string>().find("not in sub-image " +
                                                                               other),
            std::string::npos)
      << skipped.dump();
}

}  // namespace
}  // namespace aerocal
