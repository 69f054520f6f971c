// A camera calibrated in its OWN model (issue 10: the residual factory per camera model; issue 14:
// `calibrate --model opencv`; issue 15: "a camera adjusted in its own model"): the simulated test
// field (test_field_simulator.h) imaged by a camera whose truth is an OpenCV camera, calibrated by
// the same bundle adjustment in the OpenCV model (fx, fy, cx, cy, k1, k2, p1, p2, k3):
// - noise-free: the truth to 1e-6 relative (the adjustment's own convergence, nothing else);
// - 0.1 px noise: every parameter within 3 of its sigmas, sigma0 within 1 +- 3 / sqrt(2 r);
// - the same images calibrated in the 10-parameter model and converted to OpenCV with
//   calib::ConvertCamera agree with the direct fit within the conversions' stated residuals.
#include "calib/camera/convert_camera.h"
#include "triangulation/calibration/calibration.h"
#include "triangulation/simulation/test_field_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

namespace aerocal::triangulation {
namespace {

using CvModel = calib::OpenCvModel;

struct OpenCvField {
  SimulatedTestField field;           // the geometry (targets, stations, groups)
  calib::Camera truth;                // the OpenCV camera that took the images
  calib::ConversionResult from_ours;  // the simulator's 10-parameter truth as OpenCV (a fit)
  Project project;                    // nominal OpenCV camera, points, the OpenCV truth's pixels
};

calib::ConvertOptions WithoutRationalTerms() {
  calib::ConvertOptions o;
  o.zero = {"k4", "k5", "k6"};  // cv::calibrateCamera's default flags hold them at 0
  return o;
}

// The test field's stations and targets imaged by an OpenCV camera: the simulator's 10-parameter
// truth (typical 24 mm lens distortion) converted to OpenCV, its pixels plus `noise_px`.
OpenCvField MakeOpenCvField(double noise_px, std::uint64_t seed) {
  OpenCvField out;
  TestFieldOptions o;
  o.seed = seed;
  o.groups = 1;
  o.image_noise_px = 0.0;
  out.field = SimulateTestField(o);
  const SimulatedTestField& f = out.field;
  out.from_ours =
      calib::ConvertCamera(f.truth.AsModelCamera(), CvModel::kId, WithoutRationalTerms());
  out.truth = f.truth.WithModelCamera(out.from_ours.camera);
  const calib::ConversionResult nominal =
      calib::ConvertCamera(f.nominal.AsModelCamera(), CvModel::kId, WithoutRationalTerms());
  EXPECT_TRUE(nominal.exact);  // no distortion: the pinhole part is exact
  out.project = TestFieldProject(f);
  out.project.cameras["cam1"] = f.nominal.WithModelCamera(nominal.camera);
  if (noise_px == 0.0) out.project.points = f.points_truth;  // noise-free: exact control too
  for (size_t i = 0; i < out.project.points.size(); ++i)
    out.project.points[i].sigma_m = f.points_file[i].sigma_m;
  std::map<std::string, const Exposure*> exposure;
  for (const auto& e : f.exposures_truth) exposure[e.image] = &e;
  std::map<std::string, Eigen::Vector3d> point;
  for (const auto& p : f.points_truth) point[p.id] = *p.xyz_m;
  std::mt19937_64 rng(seed + 1000);
  std::normal_distribution<double> noise(0.0, 1.0);
  out.project.observations.clear();
  for (ImageObservation obs : f.observations) {
    const Exposure& e = *exposure.at(obs.image);
    Eigen::Vector2d pixel;
    if (!out.truth.ProjectToPixel(e.opk_rad, e.center_m, point.at(obs.point), &pixel)) continue;
    obs.pixel = pixel + noise_px * Eigen::Vector2d(noise(rng), noise(rng));
    out.project.observations.push_back(obs);
  }
  return out;
}

CalibrationRun CalibrateIn(const Project& project,
                           calib::CameraModelId model,
                           const std::string& free) {
  CalibrateOptions o;
  o.adjust.free_interior = ParseSelfCalibration(free, model);
  o.adjust.data_snooping = false;
  o.control_propagation = false;
  Project p = project;
  if (p.cameras.at("cam1").model != model) {
    calib::ConvertOptions c;
    if (model == CvModel::kId) c = WithoutRationalTerms();
    p.cameras["cam1"] = p.cameras.at("cam1").WithModelCamera(
        calib::ConvertCamera(p.cameras.at("cam1").AsModelCamera(), model, c).camera);
  }
  return Calibrate(p, o, {});
}

constexpr const char* kOpenCvFree = "fx,fy,cx,cy,k1,k2,p1,p2,k3";
const std::vector<int> kOpenCvCalibrated = {CvModel::kFx,
                                            CvModel::kFy,
                                            CvModel::kCx,
                                            CvModel::kCy,
                                            CvModel::kK1,
                                            CvModel::kK2,
                                            CvModel::kP1,
                                            CvModel::kP2,
                                            CvModel::kK3};

TEST(OpenCvModelCalibration, NoiseFreeTestFieldRecoversTheOpenCvTruth) {
  const OpenCvField f = MakeOpenCvField(0.0, 21);
  const CalibrationRun run = CalibrateIn(f.project, CvModel::kId, kOpenCvFree);
  const AdjustmentResult& r = run.all.result;
  ASSERT_TRUE(r.converged());
  const CameraEstimate& c = r.cameras[0];
  EXPECT_EQ(c.model, CvModel::kId);
  ASSERT_EQ(c.estimated.size(), CvModel::kNumParams);
  for (int k : kOpenCvCalibrated) {
    SCOPED_TRACE(std::string(CvModel::kParams[k].name));
    // Noise-free images and control: only the solver's convergence separates estimate and truth.
    EXPECT_NEAR(c.estimated[k], f.truth.interior[k], 1e-6 * std::abs(f.truth.interior[k]));
  }
  for (int k : {CvModel::kK4, CvModel::kK5, CvModel::kK6}) EXPECT_EQ(c.estimated[k], 0.0);
  EXPECT_LT(r.sigma0, 1e-3);
  std::printf("noise-free OpenCV truth: fx %.6f (truth %.6f) k1 %.8f (truth %.8f), sigma0 %.2e\n",
              c.estimated[CvModel::kFx],
              f.truth.interior[CvModel::kFx],
              c.estimated[CvModel::kK1],
              f.truth.interior[CvModel::kK1],
              r.sigma0);
}

class NoisyOpenCvField : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    field_ = new OpenCvField(MakeOpenCvField(0.1, 23));
    direct_ = new CalibrationRun(CalibrateIn(field_->project, CvModel::kId, kOpenCvFree));
  }
  static void TearDownTestSuite() {
    delete field_;
    delete direct_;
  }
  static OpenCvField* field_;
  static CalibrationRun* direct_;
};
OpenCvField* NoisyOpenCvField::field_ = nullptr;
CalibrationRun* NoisyOpenCvField::direct_ = nullptr;

TEST_F(NoisyOpenCvField, OpenCvParametersWithinThreeSigmaOfTheTruth) {
  const AdjustmentResult& r = direct_->all.result;
  ASSERT_TRUE(r.valid) << (r.invalid_reasons.empty() ? "" : r.invalid_reasons[0]);
  const CameraEstimate& c = r.cameras[0];
  for (int k : kOpenCvCalibrated) {
    SCOPED_TRACE(std::string(CvModel::kParams[k].name));
    ASSERT_GT(c.sigma[k], 0.0);
    EXPECT_LE(std::abs(c.estimated[k] - field_->truth.interior[k]), 3.0 * c.sigma[k])
        << c.estimated[k] << " truth " << field_->truth.interior[k] << " sigma " << c.sigma[k];
  }
  // Injected 0.1 px with sigma 0.1 px, the residual in measured pixels: sigma0 within
  // 1 +- 3 / sqrt(2 r).
  EXPECT_NEAR(r.sigma0, 1.0, 3.0 / std::sqrt(2.0 * r.solve.redundancy));
}

TEST(OpenCvModelCalibration, TenParameterFitConvertedToOpenCvAgreesWithTheDirectFit) {
  // Noise-free images: what separates the two results is the models, not the noise.
  const OpenCvField f = MakeOpenCvField(0.0, 25);
  const CalibrationRun direct = CalibrateIn(f.project, CvModel::kId, kOpenCvFree);
  const CalibrationRun ten =
      CalibrateIn(f.project, calib::BrownFraser10Model::kId, "c,x0,y0,K1,K2,K3,P1,P2,B1");
  const AdjustmentResult& r = ten.all.result;
  ASSERT_TRUE(direct.all.result.converged());
  ASSERT_TRUE(r.converged());
  ASSERT_EQ(r.cameras[0].model, calib::BrownFraser10Model::kId);
  calib::Camera ours = f.field.nominal;
  ours.interior = r.cameras[0].estimated;
  const calib::ConversionResult converted =
      calib::ConvertCamera(ours.AsModelCamera(), CvModel::kId, WithoutRationalTerms());
  calib::Camera opencv = f.truth;
  opencv.interior = direct.all.result.cameras[0].estimated;
  const calib::ConversionResidual difference =
      calib::CompareCameras(opencv.AsModelCamera(), converted.camera, 51);
  // Stated residuals: the OpenCV truth is the 10-parameter truth converted (from_ours), so the
  // 10-parameter model holds these images up to that residual; the conversion of its fit back to
  // OpenCV states its own. The two results agree within their sum over the whole format.
  const double stated_px = f.from_ours.residual.max_px + converted.residual.max_px;
  std::printf(
      "10-parameter fit as OpenCV vs direct OpenCV fit: max %.5f px (rms %.5f), stated "
      "residuals %.5f + %.5f px\n",
      difference.max_px,
      difference.rms_px,
      f.from_ours.residual.max_px,
      converted.residual.max_px);
  EXPECT_EQ(difference.failed_points, 0);
  EXPECT_LE(difference.max_px, stated_px);
}

}  // namespace
}  // namespace aerocal::triangulation
