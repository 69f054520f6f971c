// The rig bundle (triangulation/sensor/rig_head_camera.h) on the dual-lens simulation
// (rig_flight_simulator.h): noise-free data give back head B's mount, lever arm and time offset
// to 1e-9 relative; with noise every rig parameter lies within 3 reported sigmas of the truth,
// sigma0 agrees with the injected noise and the check points are as good as with the true rig;
// free increments with a free mount are a rank defect (not valid); the reader takes a rig camera
// file and rejects head observations it cannot place, with FILE:LINE.
#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "tests/support/rig_flight_project.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block_io.h"
#include "triangulation/sensor/rig_head_camera.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

namespace aerocal::triangulation {
namespace {

// The in-memory project of a simulated flight with `rig` as its camera (no file rounding).
Project ProjectOf(const SimulatedRigFlight& f, const calib::Rig& rig) {
  return testing::RigFlightProject(f, rig);
}

RigFlightSimulationOptions KnownInteriors() {
  RigFlightSimulationOptions o;
  o.interior_correction = {calib::InteriorParams{}};  // heads' interiors as the nominal rig
  return o;
}

const RigHeadEstimate& HeadB(const RigAdjustmentResult& r) { return r.heads[1]; }

TEST(RigBundle, NoiseFreeRecoversMountLeverArmAndTimeOffset) {
  RigFlightSimulationOptions o = KnownInteriors();
  o.flight.image_noise_px = 0.0;
  o.speed_mps = 55.0;
  o.time_offset_s = 0.004;
  const SimulatedRigFlight f = SimulateRigFlight(o);
  Project project = ProjectOf(f, f.nominal);
  for (auto& p : project.points)  // control without survey noise
    for (const auto& t : f.points_truth)
      if (p.id == t.id && p.xyz_m) p.xyz_m = t.xyz_m;
  AdjustOptions options;
  options.data_snooping = false;
  options.auto_robust_start = false;
  RigAdjustOptions rig;
  rig.time_offsets = calib::BlockMode::kFree;
  const RigAdjustmentResult r = AdjustRig(project, options, rig);
  ASSERT_TRUE(r.adjustment.solve.converged) << r.adjustment.solve.message;
  const calib::RigHead& truth = f.truth.heads[1];
  // 1e-9 relative: of the mount's 1 deg and the lever arm's 0.15 m (the oracle).
  constexpr double kRelative = 1e-9;
  EXPECT_LT((HeadB(r).mount_rad - truth.mount_rad).norm(), kRelative * truth.mount_rad.norm());
  EXPECT_LT((HeadB(r).lever_arm_m - truth.lever_arm_m).norm(),
            kRelative * truth.lever_arm_m.norm());
  EXPECT_LT(std::abs(HeadB(r).time_offset_s - o.time_offset_s), kRelative * o.time_offset_s);
  std::printf("noise-free: |mount error| %.3g rad, |lever-arm error| %.3g m, |dT error| %.3g s\n",
              (HeadB(r).mount_rad - truth.mount_rad).norm(),
              (HeadB(r).lever_arm_m - truth.lever_arm_m).norm(),
              std::abs(HeadB(r).time_offset_s - o.time_offset_s));
  // The reference head is the rig's datum: untouched.
  EXPECT_TRUE(r.heads[0].mount_rad.isZero(0.0));
  EXPECT_TRUE(r.heads[0].lever_arm_m.isZero(0.0));
}

// Every free rig parameter of head B within `k` reported sigmas of the truth; the largest
// |error| / sigma.
double WorstRigError(const RigAdjustmentResult& r, const calib::RigHead& truth) {
  const RigHeadEstimate& b = HeadB(r);
  EXPECT_TRUE(b.mount_sigma_rad && b.lever_arm_sigma_m);
  if (!b.mount_sigma_rad || !b.lever_arm_sigma_m) return INFINITY;
  double worst = 0.0;
  for (int i = 0; i < 3; ++i) {
    worst =
        std::max(worst, std::abs(b.mount_rad(i) - truth.mount_rad(i)) / (*b.mount_sigma_rad)(i));
    worst = std::max(worst,
                     std::abs(b.lever_arm_m(i) - truth.lever_arm_m(i)) / (*b.lever_arm_sigma_m)(i));
  }
  return worst;
}

TEST(RigBundle, NoisyFlightWithinThreeSigmaAndCheckPointsAsWithTheTrueRig) {
  const RigFlightSimulationOptions o = KnownInteriors();
  const SimulatedRigFlight f = SimulateRigFlight(o);
  const Project project = ProjectOf(f, f.nominal);
  AdjustOptions options;
  const RigAdjustmentResult r = AdjustRig(project, options, {});
  ASSERT_TRUE(r.adjustment.valid) << r.adjustment.invalid_reasons.front();
  const double worst = WorstRigError(r, f.truth.heads[1]);
  EXPECT_LT(worst, 3.0);
  // sigma0 / injected sigma within 1 +- 3 / sqrt(2 r).
  const double redundancy = r.adjustment.solve.redundancy;
  EXPECT_NEAR(r.adjustment.sigma0, 1.0, 3.0 / std::sqrt(2.0 * redundancy));
  // The lever arm seen from 1200 m is barely separable from the mount: said by name.
  bool named = false;
  for (const auto& h : r.determinability.high_correlations)
    named |= h.a.find("head B mount.phi") != std::string::npos &&
             h.b.find("head B lever arm.tx") != std::string::npos;
  EXPECT_TRUE(named);
  // Check points at the noise floor: as good as a bundle that knows the true rig (within 10 %:
  // the six estimated rig parameters cost a little redundancy, nothing more).
  RigAdjustOptions known;
  known.mounts = calib::BlockMode::kFixed;
  known.lever_arms = calib::BlockMode::kFixed;
  const RigAdjustmentResult t = AdjustRig(ProjectOf(f, f.truth), options, known);
  ASSERT_TRUE(t.adjustment.valid);
  const Eigen::Vector3d estimated = r.adjustment.check.rmse_m,
                        reference = t.adjustment.check.rmse_m;
  EXPECT_LT(estimated.norm(), 1.10 * reference.norm())
      << estimated.transpose() << " vs " << reference.transpose();
  std::printf(
      "noisy: worst |error| / sigma %.2f, sigma0 %.4f (r = %.0f), check RMSE %.4f m vs "
      "%.4f m with the true rig\n",
      worst,
      r.adjustment.sigma0,
      redundancy,
      estimated.norm(),
      reference.norm());
}

TEST(RigBundle, SelfCalibratingHeadsWithinThreeSigma) {
  RigFlightSimulationOptions o;  // the default interior errors of both heads
  o.flight.gnss_sigma_m = 0.05;  // GNSS centres: c and the flying height separate
  const SimulatedRigFlight f = SimulateRigFlight(o);
  AdjustOptions options;
  options.free_interior = {"c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};
  const RigAdjustmentResult r = AdjustRig(ProjectOf(f, f.nominal), options, {});
  ASSERT_TRUE(r.adjustment.valid) << r.adjustment.invalid_reasons.front();
  EXPECT_LT(WorstRigError(r, f.truth.heads[1]), 3.0);
  for (int k = 0; k < 2; ++k)
    for (int i : {calib::BrownFraser10Model::kC,
                  calib::BrownFraser10Model::kX0,
                  calib::BrownFraser10Model::kY0}) {
      ASSERT_TRUE(r.heads[k].interior_sigma[i].has_value());
      EXPECT_LT(std::abs(r.heads[k].interior[i] - f.truth.heads[k].camera.interior[i]),
                3.0 * *r.heads[k].interior_sigma[i])
          << "head " << r.heads[k].id << " " << calib::BrownFraser10Model::kParams[i].name;
    }
}

TEST(RigBundle, FreeIncrementsWithAFreeMountAreNotDeterminable) {
  RigFlightSimulationOptions o = KnownInteriors();
  o.flight.exposures = 12;
  o.flight.tie_points = 120;
  const SimulatedRigFlight f = SimulateRigFlight(o);
  const Project project = ProjectOf(f, f.nominal);
  AdjustOptions options;
  options.data_snooping = false;
  RigAdjustOptions rig;
  rig.increments = calib::BlockMode::kFree;
  const RigAdjustmentResult free = AdjustRig(project, options, rig);
  EXPECT_FALSE(free.adjustment.valid);
  EXPECT_FALSE(free.determinability.undetermined.empty());
  // Weighted increments (a-priori 5") make the same block determinable.
  rig.increments = calib::BlockMode::kWeighted;
  rig.increment_sigma_rad = 5.0 / 206264.806;
  const RigAdjustmentResult weighted = AdjustRig(project, options, rig);
  EXPECT_TRUE(weighted.adjustment.valid) << (weighted.adjustment.invalid_reasons.empty()
                                                 ? ""
                                                 : weighted.adjustment.invalid_reasons.front());
  EXPECT_EQ(weighted.exposures.size(), f.exposures_file.size());
}

TEST(RigBundle, OptionsAndRigFileRulesAreEnforced) {
  RigAdjustOptions weighted_without_sigma;
  weighted_without_sigma.time_offsets = calib::BlockMode::kWeighted;
  EXPECT_THROW(weighted_without_sigma.Validate(), ConfigError);
  EXPECT_EQ(calib::ParseBlockMode("weighted"), calib::BlockMode::kWeighted);
  EXPECT_FALSE(calib::ParseBlockMode("Free").has_value());

  RigFlightSimulationOptions o = KnownInteriors();
  o.flight.exposures = 6;
  o.flight.tie_points = 40;
  const SimulatedRigFlight f = SimulateRigFlight(o);  // no velocity columns
  const Project project = ProjectOf(f, f.nominal);
  RigAdjustOptions rig;
  rig.time_offsets = calib::BlockMode::kFree;
  EXPECT_THROW(AdjustRig(project, AdjustOptions{}, rig), InputError);
  rig = {};
  rig.mounts = calib::BlockMode::kWeighted;  // the nominal rig file has no mount sigmas
  EXPECT_THROW(AdjustRig(project, AdjustOptions{}, rig), ConfigError);
  // The frame camera never takes a head pixel for a virtual-image pixel.
  try {
    Adjust(project, AdjustOptions{});
    ADD_FAILURE() << "a rig project adjusted without the rig bundle";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rig bundle"), std::string::npos) << e.what();
  }
}

TEST(RigBundle, ProjectReaderTakesARigFileAndRejectsMisplacedHeads) {
  testing::TempDir dir("aerocal_rig_bundle");
  RigFlightSimulationOptions o = KnownInteriors();
  o.flight.exposures = 6;
  o.flight.tie_points = 40;
  WriteSimulatedRigFlight(SimulateRigFlight(o), dir.File("flight"));
  const Project project = ReadProject(dir.File("flight"));
  ASSERT_EQ(project.rigs.size(), 1u);
  EXPECT_EQ(project.rigs.at("rig1").heads.size(), 2u);
  EXPECT_EQ(project.cameras.at("rig1").interior, project.rigs.at("rig1").heads[0].camera.interior);

  const auto expect_error =
      [&](const std::string& observations, const std::string& where, const std::string& what) {
        WriteFileAtomically(dir.File("flight/observations.csv"), observations);
        try {
          ReadProject(dir.File("flight"));
          ADD_FAILURE() << "no error for " << what;
        } catch (const InputError& e) {
          const std::string message = e.what();
          EXPECT_NE(message.find(where), std::string::npos) << message;
          EXPECT_NE(message.find(what), std::string::npos) << message;
        }
      };
  const std::string image = project.exposures.front().image;
  expect_error("image,head,point,col,row,sigma_px\n" + image + ",A,C1,10,10,0.2\n" + image +
                   ",Q,C1,10,10,0.2\n",
               "observations.csv:3",
               "no head 'Q'");
  expect_error("image,point,col,row,sigma_px\n" + image + ",C1,10,10,0.2\n",
               "observations.csv:2",
               "need a head");
}

}  // namespace
}  // namespace aerocal::triangulation
