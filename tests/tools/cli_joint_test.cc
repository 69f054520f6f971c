// The joint stitching + triangulation adjustment from the command line, on a flight whose nominal
// camera maps its CCDs by translations only (a maker's design) while the true CCDs carry shears
// (`aerocal simulate --nominal-mapping translation --ccd-shear 2e-4`):
// - `aerocal flight` refines the mappings with the model the flight's stitching chose (affine),
//   from the stitching's flight means, says so, fits like the self-calibration (sigma0 within
//   10 %) and recovers the affine mappings within 3 sigma; forced to translation it warns;
// - `aerocal adjust --joint-stitching` writes the joint result (mappings with sigmas, stitching
//   sigma0 before/after, mapping/interior correlations) and recovers mappings and interior within
//   3 sigma; without stitching measurements it converts the camera file's mappings to the model
//   given; per exposure it estimates one mapping per exposure;
// - a model that does not fit warns by residual group; bad options exit 2 and write nothing.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace aerocal {
namespace {

using testing::RunAerocal;

using testing::ReadJson;

// |estimate - truth| / sigma of every free mapping parameter of a joint result.
std::vector<double> MappingErrors(const nlohmann::json& joint, const calib::Camera& truth) {
  std::vector<double> z;
  for (const auto& s : joint["subimages"]) {
    if (s["base"].get<bool>()) continue;
    const auto& t = truth.subimages[truth.SubimageIndex(s["id"].get<std::string>())];
    EXPECT_EQ(s["model"], "affine") << s["id"];
    const auto params = s["params"].get<std::vector<double>>();
    const auto sigma = s["sigma"].get<std::vector<double>>();
    EXPECT_EQ(params.size(), t.params.size());
    for (size_t i = 0; i < params.size() && i < t.params.size(); ++i) {
      EXPECT_GT(sigma[i], 0.0);
      z.push_back(std::abs(params[i] - t.params[i]) / sigma[i]);
    }
  }
  return z;
}

// "Within 3 sigma" for the 24 parameters of four affine mappings (seed 3: largest 2.1 sigma).
void ExpectWithinThreeSigma(const std::vector<double>& z) {
  ASSERT_EQ(z.size(), 24u);
  EXPECT_LT(*std::max_element(z.begin(), z.end()), 3.0);
}

// One simulated flight (`simulate` with Flight::kOptions into FOLDER/data) for a suite's tests.
template <typename Flight>
class SimulatedFlight : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("aerocal_joint_cli");
    const auto sim = RunAerocal("simulate --out " + dir_->File("data") + " " + Flight::kOptions);
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  static std::string File(const std::string& name) { return dir_->File(name); }
  static calib::Camera Truth() { return calib::ReadCamera(File("data/camera_truth.yaml")); }
  // `aerocal adjust` of the raw sub-image block with `options`, expected to finish: its result
  // (empty when it did not).
  static nlohmann::json AdjustJoint(const std::string& options,
                                    const std::string& name,
                                    const std::string& project = "data/project_subimage.yaml") {
    const auto run =
        RunAerocal("adjust --project " + File(project) + " " + options + " --out " + File(name));
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return run.exit_code == 0 ? ReadJson(File(name)) : nlohmann::json::object();
  }
  static inline testing::TempDir* dir_ = nullptr;
};

// The 37-exposure flight, translation-only nominal camera, CCD shears of 2e-4 (0.7 px across a
// sub-image).
struct Sheared {
  static constexpr const char* kOptions =
      "--seed 3 --stitch-ties 200 --gnss-sigma-m 0.05 --nominal-mapping translation --ccd-shear "
      "2e-4";
};
using ShearedFlight = SimulatedFlight<Sheared>;

// A small flight (9 exposures) with CCD shears of 2e-3 (7 px across a sub-image).
struct StronglySheared {
  static constexpr const char* kOptions =
      "--seed 4 --exposures 9 --surveyed-points 60 --tie-points 150 --stitch-ties 100 "
      "--gnss-sigma-m 0.05 "
      "--nominal-mapping translation --ccd-shear 2e-3";
};
using StronglyShearedFlight = SimulatedFlight<StronglySheared>;

TEST_F(ShearedFlight, TheNominalCameraMapsByTranslationsAndTheTruthIsSheared) {
  const calib::Camera nominal = calib::ReadCamera(File("data/camera_nominal.yaml"));
  for (const auto& s : nominal.subimages)
    EXPECT_EQ(s.model, calib::MappingModel::kTranslation) << s.id;
  const calib::Camera truth = Truth();
  const auto& i = truth.subimages[truth.SubimageIndex("I")];
  ASSERT_EQ(i.model, calib::MappingModel::kAffine);
  // x-scale minus y-scale and skew of +-2e-4 each (plus the conformal misplacement of ~5e-5).
  EXPECT_GT(std::abs(i.params[1]), 1e-4);
}

TEST_F(ShearedFlight, FlightRefinesTheMappingsWithTheModelTheStitchingChose) {
  const auto run =
      RunAerocal("flight --camera " + File("data/camera_nominal.yaml") + " --data " + File("data") +
                 " --base III,IV --joint-model auto --stitch-sigma-px 0.1 --no-report --out " +
                 File("flight"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("joint: mappings affine (chosen by the stitching F test"),
            std::string::npos)
      << run.output;
  EXPECT_EQ(run.output.find("warning"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(File("flight/report.html"))) << "--no-report";
  const auto doc = ReadJson(File("flight/result.json"));
  EXPECT_EQ(doc["stitching"]["model"], "affine");
  ASSERT_EQ(doc["adjustments"].size(), 3u);
  const auto& self = doc["adjustments"][1];
  const auto& joint = doc["adjustments"][2];
  EXPECT_EQ(joint["mapping_model"], "affine");
  EXPECT_NE(joint["mapping_model_reason"].get<std::string>().find("flight-mean affine mappings"),
            std::string::npos);
  EXPECT_TRUE(doc["warnings"].empty()) << doc["warnings"].dump();
  // The joint step fits the sub-images as well as the self-calibration fits the virtual image
  // (seed 3: 0.199 against 0.204 px); with translation mappings it was 0.40 px.
  const double ratio = joint["sigma0_px"].get<double>() / self["sigma0_px"].get<double>();
  std::printf(
      "joint sigma0 %.4f px, self-calibration %.4f px; check spatial RMSE joint %.3f m, self %.3f "
      "m\n",
      joint["sigma0_px"].get<double>(),
      self["sigma0_px"].get<double>(),
      joint["check"]["spatial_rmse_m"].get<double>(),
      self["check"]["spatial_rmse_m"].get<double>());
  EXPECT_NEAR(ratio, 1.0, 0.10);
  for (const auto& g : joint["groups"]) EXPECT_LT(g["rms_sigma"].get<double>(), 1.5) << g["name"];
  ExpectWithinThreeSigma(MappingErrors(joint, Truth()));
  // The calibrated camera carries the refined affine mappings.
  const calib::Camera calibrated = calib::ReadCamera(File("flight/camera_calibrated.yaml"));
  const auto& i = calibrated.subimages[calibrated.SubimageIndex("I")];
  EXPECT_EQ(i.model, calib::MappingModel::kAffine);
  for (const auto& s : joint["subimages"]) {
    if (s["id"] == "I") {
      EXPECT_EQ(i.params, s["params"].get<std::vector<double>>());
    }
  }
}

TEST_F(ShearedFlight, FlightWithTranslationMappingsWarnsThatTheModelDoesNotFit) {
  const auto run = RunAerocal(
      "flight --camera " + File("data/camera_nominal.yaml") + " --data " + File("data") +
      " --base III,IV --joint-model translation --no-report --out " + File("translation"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("joint: mappings translation (given by the user"), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("warning (joint): sigma0"), std::string::npos) << run.output;
  const auto doc = ReadJson(File("translation/result.json"));
  ASSERT_EQ(doc["warnings"].size(), 1u) << doc["warnings"].dump();
  const auto& w = doc["warnings"][0];
  EXPECT_EQ(w["name"], "joint_sigma0_ratio");
  EXPECT_EQ(w["adjustment"], "joint");
  EXPECT_GT(w["value"].get<double>(), w["limit"].get<double>());
  EXPECT_EQ(doc["adjustments"][2]["warnings"].size(), 1u);
}

TEST_F(ShearedFlight, FlightWithoutTheJointStepRunsTheOthers) {
  const auto run =
      RunAerocal("flight --camera " + File("data/camera_nominal.yaml") + " --data " + File("data") +
                 " --base III,IV --no-joint --no-report --out " + File("nojoint"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto doc = ReadJson(File("nojoint/result.json"));
  ASSERT_EQ(doc["adjustments"].size(), 2u);
  EXPECT_EQ(doc["adjustments"][1]["name"], "self_calibration");
}

TEST_F(ShearedFlight, AdjustJointRecoversMappingsAndInteriorWithTheStitchingModel) {
  const auto run = RunAerocal("adjust --project " + File("data/project_subimage.yaml") +
                              " --joint-stitching per-flight --base III,IV --self-calibration all "
                              "--stitch-sigma-px 0.1 --write-camera " +
                              File("joint_camera.yaml") + " --out " + File("joint.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(
      run.output.find("joint mappings: affine, per-flight, 4 free (chosen by the stitching F test"),
      std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("stitching sigma0 per exposure"), std::string::npos) << run.output;
  const auto j = ReadJson(File("joint.json"));
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
                          "groups",
                          "warnings",
                          "subimages",
                          "datum",
                          "mapping_scope",
                          "mapping_model",
                          "mapping_model_reason",
                          "stitching_per_exposure",
                          "mapping_interior_correlations"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_TRUE(j["converged"].get<bool>());
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();
  EXPECT_EQ(j["mapping_model"], "affine");
  EXPECT_EQ(j["mapping_scope"], "per-flight");
  EXPECT_NEAR(j["sigma0"].get<double>(), 1.0, 0.1);
  const calib::Camera truth = Truth();
  ExpectWithinThreeSigma(MappingErrors(j, truth));
  // Interior: all 10 parameters within 3 sigma of the truth.
  const auto& cam = j["cameras"][0];
  const char* names[] = {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};
  for (int k = 0; k < 10; ++k) {
    const double sigma = cam["sigma"][names[k]].get<double>();
    EXPECT_GT(sigma, 0.0) << names[k];
    EXPECT_LT(std::abs(cam["estimated"][names[k]].get<double>() - truth.interior[k]), 3.0 * sigma)
        << names[k];
  }
  // Stitching precision per exposure, before (own adjustment) and after (in the joint solution):
  // both at the simulated 0.1 px.
  ASSERT_EQ(j["stitching_per_exposure"].size(), 37u);
  for (const auto& e : j["stitching_per_exposure"]) {
    EXPECT_NEAR(e["sigma0_before_px"].get<double>(), 0.1, 0.03) << e["image"];
    EXPECT_NEAR(e["sigma0_after_px"].get<double>(), 0.1, 0.03) << e["image"];
  }
  EXPECT_TRUE(j["mapping_interior_correlations"].is_array());
  // The written camera: refined interior and affine mappings, base sub-images as in the file.
  const calib::Camera written = calib::ReadCamera(File("joint_camera.yaml"));
  EXPECT_NEAR(written.interior[0], cam["estimated"]["c"].get<double>(), 1e-9);
  for (const auto& s : j["subimages"]) {
    const auto& w = written.subimages[written.SubimageIndex(s["id"].get<std::string>())];
    EXPECT_EQ(std::string(calib::MappingModelName(w.model)), s["model"].get<std::string>())
        << s["id"];
    EXPECT_EQ(w.params, s["params"].get<std::vector<double>>()) << s["id"];
  }
}

TEST_F(ShearedFlight, AdjustJointWithoutStitchingStartsFromTheCameraFileMappings) {
  // The same block without its stitching measurements: --joint-model auto has nothing to choose
  // from (exit 2, nothing written); affine given, the translation mappings of the camera file are
  // the start and the image observations alone determine the affine mappings.
  std::string project = ReadTextFile(File("data/project_subimage.yaml"));
  project.erase(project.find("stitching: stitch_obs.csv\n"),
                std::string("stitching: stitch_obs.csv\n").size());
  WriteFileAtomically(File("data/project_nostitch.yaml"), project);
  const auto refused =
      RunAerocal("adjust --project " + File("data/project_nostitch.yaml") +
                 " --joint-stitching per-flight --base III,IV --out " + File("nostitch.json"));
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("--joint-model auto needs the project's stitching measurements"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(std::filesystem::exists(File("nostitch.json")));

  const auto j = AdjustJoint(
      "--joint-stitching per-flight --joint-model affine --base III,IV --self-calibration all",
      "nostitch.json",
      "data/project_nostitch.yaml");
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["mapping_model"], "affine");
  EXPECT_NE(j["mapping_model_reason"].get<std::string>().find("camera file's mappings"),
            std::string::npos);
  EXPECT_TRUE(j["stitching_per_exposure"].empty());
  for (const auto& s : j["subimages"]) {
    if (s["base"].get<bool>()) continue;
    // Start: the camera file's translation as an affine mapping (exact conversion).
    const auto initial = s["initial"].get<std::vector<double>>();
    ASSERT_EQ(initial.size(), 6u);
    EXPECT_EQ(initial[0], 1.0);
    EXPECT_EQ(initial[1], 0.0);
    EXPECT_EQ(initial[3], 0.0);
    EXPECT_EQ(initial[4], 1.0);
  }
  ExpectWithinThreeSigma(MappingErrors(j, Truth()));
}

TEST_F(ShearedFlight, AdjustJointTakesThePlatformOptions) {
  // The joint adjustment is a sensor kind of the one block adjustment: the command line's
  // platform options reach it as they reach the plain run. The simulated lever arm is zero.
  const auto j = AdjustJoint(
      "--joint-stitching per-flight --base III,IV --self-calibration all "
      "--lever-arm-m 0,0,0 --lever-arm free",
      "joint_platform.json");
  ASSERT_TRUE(j.contains("platform")) << j.dump().substr(0, 400);
  const auto& lever = j["platform"]["lever_arm_m"];
  EXPECT_EQ(lever["mode"], "free");
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(lever["sigma"][i].is_number()) << i;
    EXPECT_LE(std::abs(lever["value"][i].get<double>()), 3.0 * lever["sigma"][i].get<double>())
        << i;
  }
}

TEST_F(StronglyShearedFlight, AModelThatDoesNotFitWarnsByResidualGroup) {
  // Translation mappings cannot follow the shears: the stitching ties (and the image rays) do not
  // fit, and the result says so by group name.
  const auto run = RunAerocal(
      "adjust --project " + File("data/project_subimage.yaml") +
      " --joint-stitching per-flight --joint-model translation --base III,IV --no-snooping "
      "--out " +
      File("translation.json"));
  ASSERT_NE(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("warning: residual group stitch_tie: RMS"), std::string::npos)
      << run.output;
  const auto j = ReadJson(File("translation.json"));
  bool tie_warning = false;
  for (const auto& w : j["warnings"]) {
    EXPECT_EQ(w["name"], "group_rms");
    EXPECT_GT(w["value"].get<double>(), 3.0);
    EXPECT_EQ(w["limit"].get<double>(), 3.0);
    tie_warning |= w["subject"] == "stitch_tie";
  }
  EXPECT_TRUE(tie_warning) << j["warnings"].dump();
  // The same block with the model the stitching chooses (affine): no warning.
  const auto f = AdjustJoint("--joint-stitching per-flight --base III,IV", "fit.json");
  ASSERT_FALSE(f.empty());
  EXPECT_EQ(f["mapping_model"], "affine");
  EXPECT_TRUE(f["warnings"].empty()) << f["warnings"].dump();
  EXPECT_NEAR(f["sigma0"].get<double>(), 1.0, 0.15);
}

TEST_F(StronglyShearedFlight, AdjustJointPerExposureEstimatesOneMappingPerExposure) {
  // Self-calibrating: with the nominal interior held, every exposure's mappings absorb the
  // camera's affinity (B1, B2) and came out 3-6 sigma off in b2.
  const auto j = AdjustJoint(
      "--joint-stitching per-exposure --joint-model affine --base III,IV --self-calibration all",
      "per_exposure.json");
  ASSERT_FALSE(j.empty());
  EXPECT_EQ(j["mapping_scope"], "per-exposure");
  EXPECT_NE(j["mapping_model_reason"].get<std::string>().find("given by the user"),
            std::string::npos);
  const calib::Camera truth = Truth();
  int free = 0;
  double worst = 0.0;
  for (const auto& s : j["subimages"]) {
    EXPECT_TRUE(s.contains("exposure"));
    if (s["base"].get<bool>()) continue;
    ++free;
    const auto& t = truth.subimages[truth.SubimageIndex(s["id"].get<std::string>())];
    for (size_t i = 0; i < t.params.size(); ++i)
      worst = std::max(
          worst,
          std::abs(s["params"][i].get<double>() - t.params[i]) / s["sigma"][i].get<double>());
  }
  EXPECT_EQ(free, 9 * 4);
  // 216 parameters: one beyond 3 sigma may be expected (0.27 % each; seed 4: largest 2.6), none
  // beyond 4.
  EXPECT_LT(worst, 4.0);
  EXPECT_NEAR(j["sigma0"].get<double>(), 1.0, 0.15);
  EXPECT_TRUE(j["warnings"].empty()) << j["warnings"].dump();
  EXPECT_EQ(j["stitching_per_exposure"].size(), 9u);
}

TEST_F(StronglyShearedFlight, BadOptionsExitWithTwoAndWriteNothing) {
  const std::string out = " --out " + File("r.json");
  struct Case {
    std::string arguments, message;
  };
  const std::string subimage = "adjust --project " + File("data/project_subimage.yaml");
  const Case cases[] = {
      // Virtual-image observations: nothing for the joint adjustment to map.
      {"adjust --project " + File("data/project.yaml") +
           " --joint-stitching per-flight --base III,IV",
       "raw sub-image pixels"},
      {subimage + " --joint-stitching sideways", "per-flight"},
      {subimage + " --joint-stitching per-flight --joint-model shear", "--joint-model"},
      {subimage + " --joint-stitching per-flight --base IX", "IX"},
      {subimage + " --joint-model affine", "--joint-stitching"},
      {subimage + " --base III,IV", "--joint-stitching"},
      {subimage + " --joint-stitching per-flight --compare", "--compare"},
      {subimage + " --joint-stitching per-flight --robust-start", "--robust-start"},
      {"flight --camera " + File("data/camera_nominal.yaml") + " --data " + File("data") +
           " --joint-model shear",
       "--joint-model"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.arguments);
    const auto r = RunAerocal(c.arguments + out);
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(File("r.json")));
  }
}

}  // namespace
}  // namespace aerocal
