// Every residual's autodiff Jacobian against Ceres' GradientChecker (numeric differentiation),
// plus values by hand: a perfect observation gives a zero residual, whitening divides by sigma.
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include "calib/camera/camera.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/prior.h"
#include "calib/residuals/stitching.h"

namespace aerocal::calib {
namespace {

void ExpectGradientsMatch(const ceres::CostFunction& cost, const std::vector<double*>& blocks) {
  ceres::NumericDiffOptions options;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results)) << results.error_log;
}

struct Scene {
  double interior[10] = {170.038, -0.0024, 0.0015, 3e-8, -2e-12, 1e-16, 2e-7, -1.5e-7, 1e-5, -8e-6};
  double opk[3] = {0.01, -0.008, 0.3};
  double center[3] = {100.0, -50.0, 4700.0};
  double point[3] = {600.0, 300.0, 250.0};
  PixelFrame frame{0.009, 14000, 12000};
};

TEST(CollinearityResidual, ZeroForAPerfectObservationAndGradientsMatch) {
  Scene s;
  Camera camera;
  camera.pixel_size_mm = 0.009;
  camera.width_px = 14000;
  camera.height_px = 12000;
  std::copy(s.interior, s.interior + 10, camera.interior.begin());
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera.ProjectToPixel(Eigen::Vector3d(s.opk), Eigen::Vector3d(s.center),
                                    Eigen::Vector3d(s.point), &pixel));
  auto cost = CollinearityResidual::Create(s.frame, pixel, 0.2);
  double r[2];
  const double* blocks[] = {s.interior, s.opk, s.center, s.point};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-6);  // 1e-6 sigma = 2e-7 px
  EXPECT_NEAR(r[1], 0.0, 1e-6);
  // One pixel off in col -> residual of 1 px / 0.2 px = 5 (to first order) in x.
  auto shifted = CollinearityResidual::Create(s.frame, pixel + Eigen::Vector2d(1, 0), 0.2);
  ASSERT_TRUE(shifted->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 5.0, 0.01);
  ExpectGradientsMatch(*cost, {s.interior, s.opk, s.center, s.point});
}

TEST(CollinearityResidual, PointBehindTheCameraIsRejected) {
  Scene s;
  s.point[2] = 9000.0;
  auto cost = CollinearityResidual::Create(s.frame, Eigen::Vector2d(7000, 6000), 0.2);
  double r[2];
  const double* blocks[] = {s.interior, s.opk, s.center, s.point};
  EXPECT_FALSE(cost->Evaluate(blocks, r, nullptr));
}

template <typename Mapping>
std::vector<double> ConditionedTestParams(const MappingConditioning& cond) {
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  h << 1.0002, 1e-4, 6900.3, -1e-4, 0.9998, 7933.1, 1e-9, -2e-9, 1;
  if (Mapping::kModel != MappingModel::kProjective) h(2, 0) = h(2, 1) = 0;
  return ConditionedFromPlain(Mapping::kModel, cond, ParamsFromHomography(Mapping::kModel, h));
}

template <typename Mapping>
void CheckStitchingResiduals() {
  const MappingConditioning cond = MappingConditioning::ForSubimage(Mapping::kModel, 7100, 4134);
  std::vector<double> p = ConditionedTestParams<Mapping>(cond);
  double point[2] = {10000.0, 9000.0};
  auto ref = StitchReferenceResidual<Mapping>::Create(cond, Eigen::Vector2d(100, 200),
                                                      Eigen::Vector2d(7000, 8100), 0.05);
  ExpectGradientsMatch(*ref, {p.data()});
  auto tie = StitchTieResidual<Mapping>::Create(cond, Eigen::Vector2d(3000, 1200), 0.1);
  ExpectGradientsMatch(*tie, {p.data(), point});
  // Value: the mapped point minus the target, in sigmas.
  SubimageMapping plain{"x", 7100, 4134, Mapping::kModel, PlainFromConditioned(Mapping::kModel, cond, p)};
  const Eigen::Vector2d mapped = plain.VirtualFromSub({3000, 1200});
  double r[2];
  const double* blocks[] = {p.data(), point};
  ASSERT_TRUE(tie->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], (mapped.x() - point[0]) / 0.1, 1e-6);
  EXPECT_NEAR(r[1], (mapped.y() - point[1]) / 0.1, 1e-6);
  Scene s;
  auto sub = SubimageCollinearityResidual<Mapping>::Create(s.frame, cond, Eigen::Vector2d(3000, 1200), 0.2);
  ExpectGradientsMatch(*sub, {p.data(), s.interior, s.opk, s.center, s.point});
}

TEST(StitchingResiduals, GradientsMatchForEveryMappingModel) {
  CheckStitchingResiduals<TranslationMapping>();
  CheckStitchingResiduals<ConformalMapping>();
  CheckStitchingResiduals<AffineMapping>();
  CheckStitchingResiduals<ProjectiveMapping>();
}

TEST(PriorCostFunction, WhitenedDifferenceOnSelectedEntries) {
  PriorCostFunction prior(3, {0, 2}, {1.0, 5.0}, {0.5, 2.0});
  double x[3] = {2.0, 100.0, 1.0};
  const double* blocks[] = {x};
  double r[2];
  ASSERT_TRUE(prior.Evaluate(blocks, r, nullptr));
  EXPECT_DOUBLE_EQ(r[0], 2.0);   // (2 - 1) / 0.5
  EXPECT_DOUBLE_EQ(r[1], -2.0);  // (1 - 5) / 2
  ExpectGradientsMatch(prior, {x});
}

}  // namespace
}  // namespace aerocal::calib
