// The robust start on cameras in other registered models (issue 28 part 3): its re-admission step
// evaluates excluded observations at the clean solution. It once did so with the 10-parameter
// collinearity functor on any camera's parameter block, reading past a 4-parameter COLMAP
// SIMPLE_RADIAL block. Now the residual is built by the sensor kind through the model registry,
// as the solve builds it:
// - at a solution, BlockAdjustment::ResidualAtCurrentValues of every used observation equals the
//   residual the adjustment reports for it (the same term, to rounding);
// - a small simulated block imaged by a camera in each of three other models (COLMAP
//   SIMPLE_RADIAL, OpenCV, Metashape), 40-sigma blunders planted on well-observed tie rays,
//   adjusted with the robust start and the model's own self-calibration: every blunder is
//   rejected, no more good rays are lost than the blunders' correlated groups, and the camera
//   comes back within 3 sigma of the truth in that model.
// Labelled `unit`: it runs in the sanitizer job, where the old read past the block was visible.
#include "calib/camera/convert_camera.h"
#include "tests/support/simulated_block.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/simulation/flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>

namespace aerocal::triangulation {
namespace {

struct ModelBlock {
  Project project;      // nominal camera in the model, the truth's pixels plus noise, blunders
  calib::Camera truth;  // the flight's truth expressed in the model (a fit, then exact pixels)
  std::set<std::pair<std::string, std::string>> blunders;
};

// A small flight (2 strips, 16 exposures, GNSS centres) whose pixels are those of the flight's
// true camera expressed in `model`, so the model fits the data exactly but for the noise.
ModelBlock MakeBlock(calib::CameraModelId model, std::uint64_t seed) {
  FlightSimulationOptions options;
  options.seed = seed;
  options.exposures = 16;
  options.strips = 2;
  options.tie_points = 250;
  options.ground_points = 40;
  options.gnss_sigma_m = 0.05;
  const SimulatedFlight flight = SimulateFlight(options);
  ModelBlock out;
  out.project = testing::ProjectFromFlight(flight);
  out.truth = flight.truth.WithModelCamera(
      calib::ConvertCamera(flight.truth.AsModelCamera(), model).camera);
  out.project.cameras["cam1"] = flight.nominal.WithModelCamera(
      calib::ConvertCamera(flight.nominal.AsModelCamera(), model).camera);
  std::map<std::string, const Exposure*> exposure;
  for (const auto& e : flight.exposures_truth) exposure[e.image] = &e;
  std::map<std::string, Eigen::Vector3d> point;
  for (const auto& p : flight.points_truth) point[p.id] = *p.xyz_m;
  std::map<std::string, int> rays;
  for (const auto& o : flight.observations) ++rays[o.point];
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, options.image_noise_px);
  out.project.observations.clear();
  int tie_rays_seen = 0;
  for (ImageObservation o : flight.observations) {
    const Exposure& e = *exposure.at(o.image);
    Eigen::Vector2d pixel;
    if (!out.truth.ProjectToPixel(e.opk_rad, e.center_m, point.at(o.point), &pixel)) continue;
    o.pixel = pixel + Eigen::Vector2d(noise(rng), noise(rng));
    // Every 20th ray of a tie point seen in 4 or more images: 40 sigma, away from its neighbours.
    if (o.point[0] == 'T' && rays.at(o.point) >= 4 && ++tie_rays_seen % 20 == 0) {
      o.pixel += Eigen::Vector2d(40 * o.sigma_px, -12 * o.sigma_px);
      out.blunders.insert({o.image, o.point});
    }
    out.project.observations.push_back(o);
  }
  return out;
}

AdjustOptions SelfCalibrationIn(calib::CameraModelId model) {
  AdjustOptions o;
  o.free_interior = ParseSelfCalibration("all", model);
  if (model == calib::OpenCvModel::kId)  // k4-k6: cv::calibrateCamera's default holds them at 0
    o.free_interior = ParseSelfCalibration("fx,fy,cx,cy,k1,k2,p1,p2,k3", model);
  o.robust_start = true;
  return o;
}

TEST(ResidualAtCurrentValues, EqualsTheAdjustmentsOwnResidualOfEveryUsedObservation) {
  const ModelBlock block = MakeBlock(calib::ColmapSimpleRadialModel::kId, 5);
  AdjustOptions options = SelfCalibrationIn(calib::ColmapSimpleRadialModel::kId);
  options.robust_start = false;
  options.data_snooping = false;
  BlockAdjustment adjustment(block.project, options);
  const AdjustmentResult r = adjustment.Run();
  ASSERT_TRUE(r.converged());
  int compared = 0;
  std::map<std::pair<std::string, std::string>, const ObservationResidual*> reported;
  for (const auto& v : r.residuals) reported[{v.image, v.point}] = &v;
  for (const auto& o : block.project.observations) {
    const auto it = reported.find({o.image, o.point});
    if (it == reported.end() || !it->second->used) continue;
    const auto v = adjustment.ResidualAtCurrentValues(o);
    ASSERT_TRUE(v.has_value()) << o.image << " " << o.point;
    // The report's residual is the whitened (x, y up) residual times sigma in (col, row).
    const Eigen::Vector2d expected(it->second->residual_px.x() / o.sigma_px,
                                   -it->second->residual_px.y() / o.sigma_px);
    EXPECT_NEAR((*v - expected).norm(), 0.0, 1e-9) << o.image << " " << o.point;
    ++compared;
  }
  EXPECT_GT(compared, 500);
  ImageObservation unknown = block.project.observations.front();
  unknown.point = "not-a-point";
  EXPECT_FALSE(adjustment.ResidualAtCurrentValues(unknown).has_value());
}

class RobustStartInModel : public ::testing::TestWithParam<calib::CameraModelId> {};

TEST_P(RobustStartInModel, RejectsEveryBlunderAndRecoversTheCamera) {
  const calib::CameraModelId model = GetParam();
  const ModelBlock block = MakeBlock(model, 7);
  ASSERT_GE(block.blunders.size(), 6u);
  const AdjustmentResult r = Adjust(block.project, SelfCalibrationIn(model));
  ASSERT_TRUE(r.converged());
  EXPECT_TRUE(r.snooping.robust_start);
  EXPECT_GT(r.snooping.robust_excluded, 0);
  std::set<std::pair<std::string, std::string>> rejected;
  for (const auto& x : r.rejected)
    if (!x.point.empty()) rejected.insert({x.image, x.point});
  for (const auto& b : block.blunders)
    EXPECT_TRUE(rejected.count(b)) << "blunder " << b.first << " " << b.second << " kept";
  // A blunder's correlated group (its point's other rays) may go with it; nothing else may.
  std::set<std::string> blundered_points;
  for (const auto& b : block.blunders) blundered_points.insert(b.second);
  for (const auto& x : rejected)
    EXPECT_TRUE(block.blunders.count(x) || blundered_points.count(x.second))
        << "good ray " << x.first << " " << x.second << " rejected";
  // The camera in its own model: every free parameter within 3 of its sigmas of the truth.
  const CameraEstimate& camera = r.cameras.at(0);
  ASSERT_EQ(camera.model, model);
  ASSERT_EQ(camera.estimated.size(), block.truth.interior.size());
  const std::vector<calib::ParamInfo> params = calib::CameraModelParams(model);
  int judged = 0;
  for (size_t k = 0; k < params.size(); ++k) {
    if (!(camera.sigma[k] > 0)) continue;
    EXPECT_LE(std::abs(camera.estimated[k] - block.truth.interior[k]), 3 * camera.sigma[k])
        << params[k].name;
    ++judged;
  }
  EXPECT_GE(judged, 4);
  EXPECT_LT(r.sigma0, 1.3);
}

std::string ModelTestName(const ::testing::TestParamInfo<calib::CameraModelId>& info) {
  static const char* const kNames[] = {"ColmapSimpleRadial", "OpenCv", "Metashape"};
  return kNames[info.index];
}

INSTANTIATE_TEST_SUITE_P(ThreeOtherModels,
                         RobustStartInModel,
                         ::testing::Values(calib::ColmapSimpleRadialModel::kId,
                                           calib::OpenCvModel::kId,
                                           calib::MetashapeFrameModel::kId),
                         ModelTestName);

}  // namespace
}  // namespace aerocal::triangulation
