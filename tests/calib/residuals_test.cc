// Every residual's autodiff Jacobian against Ceres' GradientChecker (numeric differentiation),
// plus values by hand: a perfect observation gives a zero residual, whitening divides by sigma.
#include "calib/camera/camera.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/frame_collinearity_cost_function.h"
#include "calib/residuals/gnss_prior.h"
#include "calib/residuals/prior.h"
#include "calib/residuals/rotation_prior.h"
#include "calib/residuals/stitching.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace aerocal::calib {
namespace {

void ExpectGradientsMatch(const ceres::CostFunction& cost,
                          const std::vector<const double*>& blocks) {
  ceres::NumericDiffOptions options;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results)) << results.error_log;
}

struct Scene {
  double interior[10] = {170.038, -0.0024, 0.0015, 3e-8, -2e-12, 1e-16, 2e-7, -1.5e-7, 1e-5, -8e-6};
  double opk[3] = {0.01, -0.008, 0.3};
  Eigen::Vector4d rotation = QuaternionFromOpk(Eigen::Vector3d(opk));  // the solver's block
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
  ASSERT_TRUE(camera.ProjectToPixel(
      Eigen::Vector3d(s.opk), Eigen::Vector3d(s.center), Eigen::Vector3d(s.point), &pixel));
  auto cost = CollinearityResidual::Create(s.frame, pixel, 0.2);
  double r[2];
  const double* blocks[] = {s.interior, s.rotation.data(), s.center, s.point};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 0.0, 1e-6);  // 1e-6 sigma = 2e-7 px
  EXPECT_NEAR(r[1], 0.0, 1e-6);
  // One pixel off in col -> residual of 1 px / 0.2 px = 5 (to first order) in x.
  auto shifted = CollinearityResidual::Create(s.frame, pixel + Eigen::Vector2d(1, 0), 0.2);
  ASSERT_TRUE(shifted->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], 5.0, 0.01);
  ExpectGradientsMatch(*cost, {s.interior, s.rotation.data(), s.center, s.point});
}

TEST(CollinearityResidual, PointBehindTheCameraIsRejected) {
  Scene s;
  s.point[2] = 9000.0;
  auto cost = CollinearityResidual::Create(s.frame, Eigen::Vector2d(7000, 6000), 0.2);
  double r[2];
  const double* blocks[] = {s.interior, s.rotation.data(), s.center, s.point};
  EXPECT_FALSE(cost->Evaluate(blocks, r, nullptr));
}

// The hand-written Jacobian against its autodiff twin: the same residual to rounding, every
// Jacobian entry within 1e-12 of the block's largest entry (both are exact up to rounding; the
// blocks span 15 orders of magnitude: K3 in mm^-6), at the scene and at a non-unit quaternion with
// every distortion term tripled; a constant block (nullptr) is skipped; behind the camera both
// refuse.
TEST(FrameCollinearityCostFunction, EqualsTheAutodiffResidualToRounding) {
  Scene s;
  const Eigen::Vector2d pixel(3100.25, 9050.75);
  const FrameCollinearityCostFunction analytic(s.frame, pixel, 0.2);
  const auto autodiff = CollinearityResidual::Create(s.frame, pixel, 0.2);
  const int sizes[] = {10, 4, 3, 3};
  for (int variant = 0; variant < 2; ++variant) {
    if (variant == 1) {
      for (int k = 3; k < 10; ++k) s.interior[k] *= 3.0;
      s.rotation *= 1.7;  // R(q) = R(q / |q|): the normalisation's derivative counts
    }
    const double* blocks[] = {s.interior, s.rotation.data(), s.center, s.point};
    double r_a[2], r_b[2], j_a[4][20], j_b[4][20];
    double* jac_a[] = {j_a[0], j_a[1], j_a[2], j_a[3]};
    double* jac_b[] = {j_b[0], j_b[1], j_b[2], j_b[3]};
    ASSERT_TRUE(analytic.Evaluate(blocks, r_a, jac_a));
    ASSERT_TRUE(autodiff->Evaluate(blocks, r_b, jac_b));
    // Jets divide by multiplying with the reciprocal: the values agree to rounding, not bits.
    EXPECT_NEAR(r_a[0], r_b[0], 1e-12 * std::max(1.0, std::abs(r_b[0])));
    EXPECT_NEAR(r_a[1], r_b[1], 1e-12 * std::max(1.0, std::abs(r_b[1])));
    for (int b = 0; b < 4; ++b) {
      double largest = 0;
      for (int k = 0; k < 2 * sizes[b]; ++k) largest = std::max(largest, std::abs(j_b[b][k]));
      for (int k = 0; k < 2 * sizes[b]; ++k)
        EXPECT_LE(std::abs(j_a[b][k] - j_b[b][k]), 1e-12 * largest)
            << "variant " << variant << " block " << b << " entry " << k << ": " << j_a[b][k]
            << " against " << j_b[b][k];
    }
    jac_a[0] = nullptr;  // a fixed interior: the other blocks unchanged
    const double point_entry = j_a[3][4];
    ASSERT_TRUE(analytic.Evaluate(blocks, r_a, jac_a));
    EXPECT_EQ(j_a[3][4], point_entry);
  }
  ExpectGradientsMatch(analytic, {s.interior, s.rotation.data(), s.center, s.point});
  s.point[2] = 9000.0;  // behind the camera
  const double* behind[] = {s.interior, s.rotation.data(), s.center, s.point};
  double r[2];
  EXPECT_FALSE(analytic.Evaluate(behind, r, nullptr));
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
  auto ref = StitchReferenceResidual<Mapping>::Create(
      cond, Eigen::Vector2d(100, 200), Eigen::Vector2d(7000, 8100), 0.05);
  ExpectGradientsMatch(*ref, {p.data()});
  auto tie = StitchTieResidual<Mapping>::Create(cond, Eigen::Vector2d(3000, 1200), 0.1);
  ExpectGradientsMatch(*tie, {p.data(), point});
  // Value: the mapped point minus the target, in sigmas.
  SubimageMapping plain{
      "x", 7100, 4134, Mapping::kModel, PlainFromConditioned(Mapping::kModel, cond, p)};
  const Eigen::Vector2d mapped = plain.VirtualFromSub({3000, 1200});
  double r[2];
  const double* blocks[] = {p.data(), point};
  ASSERT_TRUE(tie->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], (mapped.x() - point[0]) / 0.1, 1e-6);
  EXPECT_NEAR(r[1], (mapped.y() - point[1]) / 0.1, 1e-6);
  Scene s;
  auto sub = SubimageCollinearityResidual<Mapping>::Create(
      s.frame, cond, Eigen::Vector2d(3000, 1200), 0.2);
  ExpectGradientsMatch(*sub, {p.data(), s.interior, s.rotation.data(), s.center, s.point});
}

// The rig head residual (a head of a two-head rig with mount, lever arm, increment, time offset
// and velocity): its value against an independent Eigen oracle of the head pose, its gradients
// against GradientChecker, and its one-head identity case against CollinearityResidual.
struct RigScene {
  double interior[10] = {150.02, 0.003, -0.002, 2e-8, -1e-12, 0, 1e-7, -2e-7, 5e-6, -3e-6};
  double rig_opk[3] = {0.012, -0.007, 0.4};
  Eigen::Vector4d rig_rotation = QuaternionFromOpk(Eigen::Vector3d(rig_opk));
  double rig_center[3] = {100.0, -50.0, 1400.0};
  double mount[3] = {0.002, 0.0175, -0.001};  // about 1 deg convergence in phi
  double lever[3] = {0.15, 0.01, 0.01};
  double increment[3] = {1e-5, -2e-5, 3e-5};
  double dt[1] = {0.002};
  double point[3] = {220.0, 90.0, 250.0};
  Eigen::Vector3d velocity{60.0, 5.0, -1.0};
  PixelFrame frame{0.006, 10000, 10000};
};

// The rig residual's blocks of a scene in the functor's order.
std::vector<const double*> BlocksOf(const RigScene& s) {
  return {s.interior,
          s.rig_rotation.data(),
          s.rig_center,
          s.mount,
          s.lever,
          s.increment,
          s.dt,
          s.point};
}

TEST(RigHeadCollinearityResidual, ZeroAtTheOraclePoseAndGradientsMatch) {
  RigScene s;
  // Oracle: R_k = R M_k E_k, O_k = O + R t_k + v dT_k with Eigen matrices (CONVENTIONS.md).
  const Eigen::Matrix3d r = RotationFromOpk(Eigen::Vector3d(s.rig_opk));
  const Eigen::Matrix3d rk =
      r * RotationFromOpk(Eigen::Vector3d(s.mount)) * RotationFromOpk(Eigen::Vector3d(s.increment));
  const Eigen::Vector3d ok =
      Eigen::Vector3d(s.rig_center) + r * Eigen::Vector3d(s.lever) + s.velocity * s.dt[0];
  Camera head;
  head.pixel_size_mm = s.frame.pixel_size_mm;
  head.width_px = s.frame.width_px;
  head.height_px = s.frame.height_px;
  std::copy(s.interior, s.interior + 10, head.interior.begin());
  Eigen::Vector2d pixel;
  ASSERT_TRUE(head.ProjectToPixel(OpkFromRotation(rk), ok, Eigen::Vector3d(s.point), &pixel));
  auto cost = RigHeadCollinearityResidual::Create(s.frame, pixel, 0.25, s.velocity);
  double res[2];
  ASSERT_TRUE(cost->Evaluate(BlocksOf(s).data(), res, nullptr));
  EXPECT_NEAR(res[0], 0.0, 1e-6);  // 1e-6 sigma = 2.5e-7 px (the distortion inverse's tolerance)
  EXPECT_NEAR(res[1], 0.0, 1e-6);
  // A lever-arm error of 1 mm along the rig's x moves the head centre by R [1e-3 0 0]^T: the
  // residual is that projection shift in units of sigma (first order; distortion changes it by
  // < 1e-3 relative).
  double lever_moved[3] = {s.lever[0] + 1e-3, s.lever[1], s.lever[2]};
  std::vector<const double*> moved = BlocksOf(s);
  moved[4] = lever_moved;
  ASSERT_TRUE(cost->Evaluate(moved.data(), res, nullptr));
  Eigen::Vector2d pixel_moved;
  ASSERT_TRUE(head.ProjectToPixel(OpkFromRotation(rk),
                                  ok + r * Eigen::Vector3d(1e-3, 0, 0),
                                  Eigen::Vector3d(s.point),
                                  &pixel_moved));
  const double expected = (pixel_moved - pixel).norm() / 0.25;
  ASSERT_GT(expected, 0.05);  // the shift is seen (0.13 um at 1150 m = 0.02 px)
  EXPECT_NEAR(std::hypot(res[0], res[1]), expected, 0.02 * expected);
  ExpectGradientsMatch(*cost, BlocksOf(s));
}

// The factory's cost function (rig_head_cost_function.h) differentiates over increment, dt and
// point only (7-wide Jets) when the held blocks' Jacobians are not asked for: residuals and those
// Jacobians equal the 30-wide autodiff's to 1e-10 relative on random states; asked for every
// Jacobian it gives the autodiff's own.
TEST(RigHeadCollinearityResidual, ReducedJetsEqualTheFullAutodiff) {
  std::mt19937 rng(35);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    RigScene s;
    for (double& a : s.increment) a = 0.01 * u(rng);
    for (double& a : s.mount) a += 0.02 * u(rng);
    for (double& a : s.lever) a += 0.05 * u(rng);
    for (int a = 0; a < 3; ++a) s.point[a] += 200.0 * u(rng);
    s.dt[0] = 0.01 * u(rng);
    s.interior[0] += u(rng);
    const Eigen::Vector2d pixel(5000.0 + 4000.0 * u(rng), 5000.0 + 4000.0 * u(rng));
    auto full = RigHeadCollinearityResidual::Create(s.frame, pixel, 0.25, s.velocity);
    auto reduced = MakeRigHeadCollinearityResidual(
        CameraModelId::kBrownFraser10, s.frame, pixel, 0.25, s.velocity);
    const std::vector<const double*> blocks = BlocksOf(s);
    const int sizes[] = {10, 4, 3, 3, 3, 3, 1, 3};
    for (bool all : {false, true}) {
      std::vector<std::vector<double>> j_full(8), j_reduced(8);
      double* jf[8];
      double* jr[8];
      for (int b = 0; b < 8; ++b) {
        j_full[b].assign(2 * sizes[b], 0.0);
        j_reduced[b].assign(2 * sizes[b], NAN);
        jf[b] = j_full[b].data();
        jr[b] = (all || b >= 5) ? j_reduced[b].data() : nullptr;
      }
      double r_full[2], r_reduced[2];
      ASSERT_TRUE(full->Evaluate(blocks.data(), r_full, jf));
      ASSERT_TRUE(reduced->Evaluate(blocks.data(), r_reduced, jr));
      for (int row = 0; row < 2; ++row)
        EXPECT_NEAR(r_reduced[row], r_full[row], 1e-10 * std::abs(r_full[row]) + 1e-300);
      for (int b = all ? 0 : 5; b < 8; ++b)
        for (int i = 0; i < 2 * sizes[b]; ++i)
          EXPECT_NEAR(j_reduced[b][i], j_full[b][i], 1e-10 * std::abs(j_full[b][i]) + 1e-300)
              << "trial " << trial << " block " << b << " entry " << i;
    }
  }
}

TEST(RigHeadCollinearityResidual, TimeOffsetActsAsVelocityTimesOffset) {
  RigScene s;
  const Eigen::Vector2d pixel(4200.0, 5300.0);
  auto cost = RigHeadCollinearityResidual::Create(s.frame, pixel, 0.25, s.velocity);
  auto still = RigHeadCollinearityResidual::Create(s.frame, pixel, 0.25, Eigen::Vector3d::Zero());
  double shifted_center[3];
  for (int i = 0; i < 3; ++i) shifted_center[i] = s.rig_center[i] + s.velocity[i] * s.dt[0];
  double zero_dt[1] = {0.0};
  double a[2], b[2];
  const std::vector<const double*> with_dt = BlocksOf(s);
  const double* shifted[] = {s.interior,
                             s.rig_rotation.data(),
                             shifted_center,
                             s.mount,
                             s.lever,
                             s.increment,
                             zero_dt,
                             s.point};
  ASSERT_TRUE(cost->Evaluate(with_dt.data(), a, nullptr));
  ASSERT_TRUE(still->Evaluate(shifted, b, nullptr));
  EXPECT_NEAR(a[0], b[0], 1e-9);  // the same head centre, to rounding
  EXPECT_NEAR(a[1], b[1], 1e-9);
}

TEST(RigHeadCollinearityResidual, OneHeadRigIsTheFrameCamera) {
  // Identity mount, zero lever arm, zero increment, dT = 0: the rig head residual and the frame
  // camera's CollinearityResidual agree in value and in their Jacobians of the shared blocks.
  Scene s;
  double zero3a[3] = {0, 0, 0}, zero3b[3] = {0, 0, 0}, zero3c[3] = {0, 0, 0}, dt[1] = {0};
  const Eigen::Vector2d pixel(6100.5, 5222.25);
  auto frame_cost = CollinearityResidual::Create(s.frame, pixel, 0.2);
  auto rig_cost =
      RigHeadCollinearityResidual::Create(s.frame, pixel, 0.2, Eigen::Vector3d(30, 0, 0));
  const double* frame_blocks[] = {s.interior, s.rotation.data(), s.center, s.point};
  const double* rig_blocks[] = {
      s.interior, s.rotation.data(), s.center, zero3a, zero3b, zero3c, dt, s.point};
  double rf[2], rr[2];
  std::vector<double> jf_int(20), jf_opk(8), jf_c(6), jf_p(6);
  std::vector<double> jr_int(20), jr_opk(8), jr_c(6), jr_m(6), jr_l(6), jr_e(6), jr_dt(2), jr_p(6);
  double* jf[] = {jf_int.data(), jf_opk.data(), jf_c.data(), jf_p.data()};
  double* jr[] = {jr_int.data(),
                  jr_opk.data(),
                  jr_c.data(),
                  jr_m.data(),
                  jr_l.data(),
                  jr_e.data(),
                  jr_dt.data(),
                  jr_p.data()};
  ASSERT_TRUE(frame_cost->Evaluate(frame_blocks, rf, jf));
  ASSERT_TRUE(rig_cost->Evaluate(rig_blocks, rr, jr));
  EXPECT_DOUBLE_EQ(rr[0], rf[0]);
  EXPECT_DOUBLE_EQ(rr[1], rf[1]);
  const std::vector<std::pair<const std::vector<double>*, const std::vector<double>*>> pairs = {
      {&jr_int, &jf_int}, {&jr_opk, &jf_opk}, {&jr_c, &jf_c}, {&jr_p, &jf_p}};
  for (const auto& [a, b] : pairs)
    for (size_t i = 0; i < a->size(); ++i)
      EXPECT_NEAR((*a)[i], (*b)[i], 1e-9 * (1.0 + std::abs((*b)[i])));
  // dr/d(dT) = dr/dO v with v = (30, 0, 0) m/s.
  EXPECT_NEAR(jr_dt[0], jr_c[0] * 30.0, 1e-9 * (1.0 + std::abs(jr_c[0] * 30.0)));
  EXPECT_NEAR(jr_dt[1], jr_c[3] * 30.0, 1e-9 * (1.0 + std::abs(jr_c[3] * 30.0)));
}

TEST(OpkPriorResidual, IsTheAngleDifferenceInSigmasAndGradientsMatch) {
  // The IMU prior on a quaternion block: (opk(q) - opk0) / sigma per angle, kappa wrapped.
  const Eigen::Vector3d opk(0.02, -0.01, M_PI - 0.001);  // kappa near 180 deg
  Eigen::Vector4d q = QuaternionFromOpk(opk);
  const Eigen::Vector3d imu(0.021, -0.0115, -M_PI + 0.0005);  // the same heading, wrapped
  const Eigen::Vector3d sigma(1e-3, 5e-4, 2e-3);
  auto cost = OpkPriorResidual::Create(imu, sigma);
  double r[3];
  double no_boresight[3] = {0, 0, 0};
  const double* blocks[] = {q.data(), no_boresight};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], -1.0, 1e-9);   // (0.020 - 0.021) / 1e-3
  EXPECT_NEAR(r[1], 3.0, 1e-9);    // (-0.0100 + 0.0115) / 5e-4
  EXPECT_NEAR(r[2], -0.75, 1e-9);  // (pi - 0.001 - (-pi + 0.0005) - 2 pi) / 2e-3
  ExpectGradientsMatch(*cost, {q.data(), no_boresight});
  // A boresight M: the IMU records R M^T; the prior of R M^T's own angles is zero.
  double boresight[3] = {0.003, -0.002, 0.01};
  const Eigen::Vector3d imu_angles = OpkFromRotation(
      RotationFromQuaternion(q) * RotationFromOpk(Eigen::Vector3d(boresight)).transpose());
  auto exact = OpkPriorResidual::Create(imu_angles, sigma);
  const double* with_boresight[] = {q.data(), boresight};
  ASSERT_TRUE(exact->Evaluate(with_boresight, r, nullptr));
  EXPECT_NEAR(std::hypot(r[0], std::hypot(r[1], r[2])), 0.0, 1e-9);
  ExpectGradientsMatch(*exact, {q.data(), boresight});
  // Undefined at phi = 90 deg (omega and kappa not separable): refused, not a silent number.
  Eigen::Vector4d wall = QuaternionFromOpk(Eigen::Vector3d(0.1, M_PI / 2, 0.0));
  const double* wall_blocks[] = {wall.data(), no_boresight};
  EXPECT_FALSE(cost->Evaluate(wall_blocks, r, nullptr));
}

TEST(GnssPriorResidual, AntennaIsCentrePlusLeverArmPlusVelocityTimesOffset) {
  Scene s;
  const Eigen::Vector3d lever(0.2, -0.1, 1.5), velocity(70.0, -3.0, 0.5);
  const double dt = 0.02;
  const Eigen::Vector3d antenna =
      Eigen::Vector3d(s.center) + RotationFromQuaternion(s.rotation) * lever + velocity * dt;
  const Eigen::Vector3d sigma(0.05, 0.05, 0.1);
  auto cost = GnssPriorResidual::Create(antenna + Eigen::Vector3d(0.05, 0, -0.2), sigma, velocity);
  double lever_arm[3] = {lever.x(), lever.y(), lever.z()}, offset[1] = {dt}, r[3];
  const double* blocks[] = {s.rotation.data(), s.center, lever_arm, offset};
  ASSERT_TRUE(cost->Evaluate(blocks, r, nullptr));
  EXPECT_NEAR(r[0], -1.0, 1e-9);  // (antenna - recorded) / sigma
  EXPECT_NEAR(r[1], 0.0, 1e-9);
  EXPECT_NEAR(r[2], 2.0, 1e-9);
  ExpectGradientsMatch(*cost, {s.rotation.data(), s.center, lever_arm, offset});
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

TEST(LinearConstraintCostFunction, WhitenedSumOverBlocks) {
  Eigen::MatrixXd w0(2, 3), w1(2, 2);
  w0 << 1, 2, 3, 0, -1, 0.5;
  w1 << 4, 0, 0, 1;
  const LinearConstraintCostFunction constraint(
      {w0, w1}, {Eigen::Vector3d(1, 0, 0), Eigen::Vector2d(0, 2)}, 0.5);
  double x0[3] = {2.0, 1.0, -1.0}, x1[2] = {1.0, 3.0};
  const double* blocks[] = {x0, x1};
  double r[2];
  ASSERT_TRUE(constraint.Evaluate(blocks, r, nullptr));
  EXPECT_DOUBLE_EQ(r[0], (1 + 2 - 3 + 4) / 0.5);  // w0 (1, 1, -1) + w1 (1, 1)
  EXPECT_DOUBLE_EQ(r[1], (0 - 1 - 0.5 + 1) / 0.5);
  ExpectGradientsMatch(constraint, {x0, x1});
}

}  // namespace
}  // namespace aerocal::calib
