// A camera adjusted and calibrated in its OWN model (issue 10: the residual per camera model;
// issue 14: `calibrate --model`; issue 15: "a camera adjusted in its own model"), through the
// command line:
// - `adjust` on the simulated flight whose camera file was converted into `model:
//   metashape_frame` runs in that model (--self-calibration by its names) and writes the camera
//   back in it; the same block in the 10-parameter model gives the same check RMSE and sigma0
//   (the converted camera is exact, the models differ only in where the residual is measured);
// - `calibrate` on the simulated test field with an OpenCV camera file calibrates the OpenCV
//   model; `--model opencv` on a 10-parameter camera file adds the OpenCV fit beside it;
// - bad input: a parameter the model does not have, another model where the 10-parameter model is
//   needed (`flight`, `batch`): exit 2, FILE:LINE naming the model, nothing written.
#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace aerocal {
namespace {

using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

class FlightInAnotherModel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("aerocal_camera_models_flight");
    ASSERT_EQ(RunAerocal("simulate --out " + dir_->File("f")).exit_code, 0);
    const auto c =
        RunAerocal("camera convert --from aerocal --to aerocal --model metashape_frame " +
                   dir_->File("f/camera_nominal.yaml") + " " + dir_->File("f/cam_ms.yaml"));
    ASSERT_EQ(c.exit_code, 0) << c.output;
    WriteText(dir_->File("f/project_ms.yaml"),
              "cameras: {cam1: cam_ms.yaml}\nexposures: exposures.csv\npoints: points.csv\n"
              "observations: observations.csv\nframe: {projected: \"simulated local frame\"}\n");
  }
  static void TearDownTestSuite() { delete dir_; }
  static TempDir* dir_;
};
TempDir* FlightInAnotherModel::dir_ = nullptr;

TEST_F(FlightInAnotherModel, AdjustRunsInTheCameraFilesModelAndWritesItBackInIt) {
  const auto ms = RunAerocal("adjust --project " + dir_->File("f/project_ms.yaml") +
                             " --self-calibration f,cx,cy,k1,k2 --out " + dir_->File("ms.json") +
                             " --write-camera " + dir_->File("ms_out.yaml"));
  ASSERT_EQ(ms.exit_code, 0) << ms.output;
  const auto ours = RunAerocal("adjust --project " + dir_->File("f/project.yaml") +
                               " --self-calibration c,x0,y0,K1,K2 --out " + dir_->File("bf.json"));
  ASSERT_EQ(ours.exit_code, 0) << ours.output;
  const auto j = ReadJson(dir_->File("ms.json"));
  const auto b = ReadJson(dir_->File("bf.json"));
  EXPECT_EQ(j["camera_model"]["name"], "metashape_frame");
  EXPECT_EQ(j["camera_model"]["parameters"].size(), 13u);
  const auto& cam = j["cameras"][0];
  EXPECT_EQ(cam["model"], "metashape_frame");
  EXPECT_EQ(cam["free"], nlohmann::json({"f", "cx", "cy", "k1", "k2"}));
  EXPECT_TRUE(cam["estimated"].contains("k4"));
  EXPECT_FALSE(cam["estimated"].contains("c"));
  // The same camera (converted exactly) and the same free terms (f ~ c, cx ~ x0, cy ~ y0, k1 ~ K1,
  // k2 ~ K2 up to the forward/correction forms): the check points agree to 1 % and sigma0 to 1 %
  // (the residual in measured pixels here, in corrected photo coordinates there).
  EXPECT_NEAR(j["sigma0"].get<double>() / b["sigma0"].get<double>(), 1.0, 0.01);
  for (int axis = 0; axis < 3; ++axis)
    EXPECT_NEAR(j["check"]["rmse_m"][axis].get<double>() / b["check"]["rmse_m"][axis].get<double>(),
                1.0,
                0.01);
  // c = f p: the two principal distances and their sigmas agree.
  const double p = 0.009;
  EXPECT_NEAR(cam["estimated"]["f"].get<double>() * p,
              b["cameras"][0]["estimated"]["c"].get<double>(),
              0.1 * b["cameras"][0]["sigma"]["c"].get<double>());
  EXPECT_NEAR(
      cam["sigma"]["f"].get<double>() * p / b["cameras"][0]["sigma"]["c"].get<double>(), 1.0, 0.01);
  // Written back in its own model, readable as the next run's camera.
  const calib::Camera back =
      calib::ReadCamera(dir_->File("ms_out.yaml"), calib::CameraModels::kAny);
  EXPECT_EQ(back.model, calib::MetashapeFrameModel::kId);
  EXPECT_DOUBLE_EQ(back.interior[calib::MetashapeFrameModel::kF],
                   cam["estimated"]["f"].get<double>());
  EXPECT_DOUBLE_EQ(back.interior[calib::MetashapeFrameModel::kK2],
                   cam["estimated"]["k2"].get<double>());
}

TEST_F(FlightInAnotherModel, BadModelUseIsExitTwoWithNothingWritten) {
  // A name of the 10-parameter model for a metashape_frame camera.
  auto r = RunAerocal("adjust --project " + dir_->File("f/project_ms.yaml") +
                      " --self-calibration c,x0 --out " + dir_->File("bad1.json"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("--self-calibration: unknown parameter 'c'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad1.json")));
  // (Sub-image mappings and rig heads take any model since issue 30 item 4:
  // tests/triangulation/model_families_test.cc; stitch, match and resample read no interior term
  // and take any model: tests/stitch/stitch_cli_test.cc, match_stitch_test.cc.)
  // The flight commands read the 10-parameter model only (their self-calibration candidates name
  // its terms): "convert it first", naming the model.
  const std::string flight = " --camera " + dir_->File("f/cam_ms.yaml") + " --data " +
                             dir_->File("f") + " --base III,IV --no-report --out ";
  const std::string message =
      "cam_ms.yaml:2: camera model 'metashape_frame': this command needs brown_fraser_10 (convert "
      "it first";
  r = RunAerocal("flight" + flight + dir_->File("bad3"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad3")));
  r = RunAerocal("batch plan --work " + dir_->File("bad4_work") + flight + dir_->File("bad4"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad4_work")));
}

class TestFieldInOpenCv : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir("aerocal_camera_models_field");
    ASSERT_EQ(RunAerocal("simulate --test-field --groups 1 --images-per-group 16 --out " +
                         dir_->File("tf"))
                  .exit_code,
              0);
    const auto c =
        RunAerocal("camera convert --from aerocal --to aerocal --model opencv " +
                   dir_->File("tf/camera_nominal.yaml") + " " + dir_->File("tf/cam_cv.yaml"));
    ASSERT_EQ(c.exit_code, 0) << c.output;
  }
  static void TearDownTestSuite() { delete dir_; }
  std::string Field() const {
    return " --observations " + dir_->File("tf/observations.csv") + " --points " +
           dir_->File("tf/points.csv") + " --no-snooping";
  }
  static TempDir* dir_;
};
TempDir* TestFieldInOpenCv::dir_ = nullptr;

TEST_F(TestFieldInOpenCv, AnOpenCvCameraFileIsCalibratedInTheOpenCvModel) {
  const auto r =
      RunAerocal("calibrate --camera " + dir_->File("tf/cam_cv.yaml") + Field() + " --out " +
                 dir_->File("cv.json") + " --write-camera " + dir_->File("cv_out.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto j = ReadJson(dir_->File("cv.json"));
  const auto& cam = j["cameras"][0];
  EXPECT_EQ(cam["model"], "opencv");
  EXPECT_EQ(j["calibration"]["model"], "opencv");
  EXPECT_EQ(cam["free"], nlohmann::json({"fx", "fy", "cx", "cy", "k1", "k2", "p1", "p2", "k3"}));
  // The truth is the 10-parameter camera_truth.yaml (c 24.052 mm, x0 0.021, y0 -0.014 mm): the
  // OpenCV pinhole part within 3 sigma of it (fy p = c, cx = x0 / p + (W - 1) / 2, ...; the
  // distortion models differ by ~1e-3 px, far below these sigmas).
  const calib::Camera truth = calib::ReadCamera(dir_->File("tf/camera_truth.yaml"));
  const double p = truth.pixel_size_mm;
  const auto& est = cam["estimated"];
  const auto& sigma = cam["sigma"];
  EXPECT_NEAR(est["fy"].get<double>(), truth.c_mm() / p, 3 * sigma["fy"].get<double>());
  EXPECT_NEAR(est["cx"].get<double>(),
              truth.PrincipalPointMm().x() / p + 0.5 * (truth.width_px - 1),
              3 * sigma["cx"].get<double>());
  EXPECT_NEAR(est["cy"].get<double>(),
              -truth.PrincipalPointMm().y() / p + 0.5 * (truth.height_px - 1),
              3 * sigma["cy"].get<double>());
  // Simulated 0.1 px noise with sigma 0.1 px.
  EXPECT_NEAR(j["sigma0"].get<double>(), 1.0, 0.1);
  // The certified values are the model's parameters.
  bool stated = false;
  for (const auto& q : j["calibration"]["uncertainty"]) stated = stated || q["quantity"] == "fx";
  EXPECT_TRUE(stated);
  const calib::Camera back =
      calib::ReadCamera(dir_->File("cv_out.yaml"), calib::CameraModels::kAny);
  EXPECT_EQ(back.model, calib::OpenCvModel::kId);
  EXPECT_DOUBLE_EQ(back.interior[calib::OpenCvModel::kFx], est["fx"].get<double>());
}

TEST_F(TestFieldInOpenCv, ModelOpenCvCalibratesTheOpenCvModelBesideTheTenParameterOne) {
  const auto r = RunAerocal("calibrate --camera " + dir_->File("tf/camera_nominal.yaml") + Field() +
                            " --model opencv --out " + dir_->File("both.json"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("beside, in model opencv"), std::string::npos) << r.output;
  const auto j = ReadJson(dir_->File("both.json"));
  EXPECT_EQ(j["cameras"][0]["model"], "brown_fraser_10");
  const auto& beside = j["calibration"]["beside"];
  EXPECT_EQ(beside["model"], "opencv");
  EXPECT_TRUE(beside["valid"].get<bool>());
  // The same marks, two models that both hold this lens to ~1e-3 px: the same RMS to 1 %, and
  // c = fy p within the 10-parameter result's sigma.
  EXPECT_NEAR(beside["rms_px"].get<double>() / j["calibration"]["rms_px"].get<double>(), 1.0, 0.01);
  EXPECT_NEAR(beside["estimated"]["fy"].get<double>() * 0.006,
              j["cameras"][0]["estimated"]["c"].get<double>(),
              j["cameras"][0]["sigma"]["c"].get<double>());
  // --model names a registered model.
  const auto bad = RunAerocal("calibrate --camera " + dir_->File("tf/camera_nominal.yaml") +
                              Field() + " --model opencv9 --out " + dir_->File("bad.json"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.output.find("--model: unknown camera model 'opencv9'"), std::string::npos)
      << bad.output;
  EXPECT_FALSE(std::filesystem::exists(dir_->File("bad.json")));
}

}  // namespace
}  // namespace aerocal
