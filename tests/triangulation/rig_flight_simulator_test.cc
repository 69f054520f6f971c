// The rig flight simulator (triangulation/simulation/rig_flight_simulator.h): the dual-lens preset
// is the example rig file, every head observation is the projection an independent Eigen oracle of
// the head pose gives, both heads of one exposure see common points, the files read back, and the
// time offset moves a head by v dT.
#include "triangulation/simulation/rig_flight_simulator.h"

#include "calib/camera/rig_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/rig/rig_design.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

TEST(RigFlightSimulator, DualLensPresetIsTheExampleRigFile) {
  const calib::Rig file = calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml");
  const calib::Rig preset = MakeNominalRig(RigPreset::kDualLens);
  EXPECT_EQ(calib::RigToYaml(preset), calib::RigToYaml(file));
  const calib::Rig uav4 = calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_uav4.yaml");
  EXPECT_EQ(calib::RigToYaml(MakeNominalRig(RigPreset::kUav4)), calib::RigToYaml(uav4));
  EXPECT_EQ(ParseRigPreset("uav4"), RigPreset::kUav4);
  EXPECT_EQ(ParseRigPreset("dual-lens"), RigPreset::kDualLens);
  EXPECT_FALSE(ParseRigPreset("dual_lens").has_value());
}

TEST(RigFlightSimulator, NoiseFreeObservationsAreTheOracleProjections) {
  RigFlightSimulationOptions o;
  o.flight.exposures = 12;
  o.flight.ground_points = 20;
  o.flight.tie_points = 60;
  o.flight.image_noise_px = 0.0;
  o.speed_mps = 55.0;
  o.time_offset_s = 0.003;
  o.increment_sigma_rad = 2e-5;
  const SimulatedRigFlight f = SimulateRigFlight(o);
  ASSERT_EQ(f.truth.heads.size(), 2u);
  ASSERT_EQ(f.rig_exposures.size(), 2 * f.exposures_truth.size());
  // The truth differs from the nominal rig by the stated errors of head B only.
  EXPECT_NEAR(
      (f.truth.heads[1].lever_arm_m - f.nominal.heads[1].lever_arm_m - o.lever_arm_error_m).norm(),
      0,
      1e-15);
  EXPECT_TRUE(f.truth.heads[0].lever_arm_m.isZero(0.0));
  EXPECT_TRUE(f.truth.heads[0].mount_rad.isZero(0.0));
  std::map<std::string, const GroundPoint*> points;
  for (const auto& p : f.points_truth) points[p.id] = &p;
  std::map<std::string, int> exposure_index;
  for (size_t i = 0; i < f.exposures_truth.size(); ++i)
    exposure_index[f.exposures_truth[i].image] = i;
  std::set<std::pair<std::string, std::string>> seen_a, seen_b;
  double worst_px = 0.0;
  for (const auto& obs : f.observations) {
    const int i = exposure_index.at(obs.image);
    const int k = f.truth.HeadIndex(obs.head);
    ASSERT_GE(k, 0) << obs.head;
    const Exposure& e = f.exposures_truth[i];
    const RigExposureTruth& t = f.rig_exposures[2 * i + k];
    ASSERT_EQ(t.head, obs.head);
    // Oracle: R_k = R M_k E_k, O_k = O + R t_k + v dT_k with Eigen (CONVENTIONS.md).
    const calib::RigHead& head = f.truth.heads[k];
    const Eigen::Matrix3d r = calib::RotationFromOpk(e.opk_rad);
    const Eigen::Matrix3d rk = r * head.RigFromHead() * calib::RotationFromOpk(t.increment_rad);
    const Eigen::Vector3d ok = e.center_m + r * head.lever_arm_m + *e.velocity_mps * t.dt_s;
    Eigen::Vector2d px;
    ASSERT_TRUE(head.camera.ProjectToPixel(
        calib::OpkFromRotation(rk), ok, *points.at(obs.point)->xyz_m, &px));
    worst_px = std::max(worst_px, (px - obs.pixel).cwiseAbs().maxCoeff());
    (k == 0 ? seen_a : seen_b).insert({obs.image, obs.point});
  }
  EXPECT_LT(worst_px, 1e-9);  // the same projection, to rounding
  // The heads overlap: most points head B sees in an exposure head A sees there as well.
  int common = 0;
  for (const auto& s : seen_b) common += seen_a.count(s);
  EXPECT_GT(common, 0.5 * seen_b.size()) << common << " of " << seen_b.size();
  EXPECT_GT(seen_b.size(), 100u);
  // Velocity along the strip: kappa 0 flies +x.
  EXPECT_NEAR(f.exposures_truth[0].velocity_mps->x(),
              55.0 * std::cos(f.exposures_truth[0].opk_rad.z()),
              1e-12);
}

TEST(RigFlightSimulator, FilesReadBackWithHeadsAndVelocity) {
  RigFlightSimulationOptions o;
  o.flight.exposures = 9;
  o.flight.ground_points = 12;
  o.flight.tie_points = 30;
  o.flight.gnss_sigma_m = 0.05;
  o.flight.imu_sigma_deg = 0.005;
  o.speed_mps = 60.0;
  const SimulatedRigFlight f = SimulateRigFlight(o);
  testing::TempDir dir;
  WriteSimulatedRigFlight(f, dir.path());
  const auto observations = ReadObservations(dir.File("observations.csv"), 0.5);
  ASSERT_EQ(observations.size(), f.observations.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    EXPECT_EQ(observations[i].head, f.observations[i].head);
    EXPECT_NEAR((observations[i].pixel - f.observations[i].pixel).norm(), 0.0, 1e-4);  // 4 decimals
  }
  const auto exposures = ReadExposures(dir.File("exposures.csv"));
  ASSERT_EQ(exposures.size(), 9u);
  ASSERT_TRUE(exposures[0].velocity_mps && exposures[0].center_sigma_m &&
              exposures[0].opk_sigma_rad);
  EXPECT_NEAR((*exposures[0].velocity_mps - *f.exposures_file[0].velocity_mps).norm(), 0.0, 1e-4);
  const calib::Rig truth = calib::ReadRig(dir.File("rig_truth.yaml"));
  EXPECT_NEAR((truth.heads[1].mount_rad - f.truth.heads[1].mount_rad).norm(), 0.0, 1e-15);
  EXPECT_NE(ReadTextFile(dir.File("truth/rig_exposures.csv"))
                .find("image,head,domega,dphi,dkappa,dT_ms\n0001,A,"),
            std::string::npos);
  // The project reads as a rig project (the rig bundle: tests/triangulation/rig_bundle_test.cc).
  const Project project = ReadProject(dir.File("project.yaml"));
  ASSERT_EQ(project.rigs.count("rig1"), 1u);
  EXPECT_EQ(project.rigs.at("rig1").heads.size(), 2u);
}

TEST(RigBlockFiles, PartialVelocityAndMixedColumnsAreRefusedByLine) {
  testing::TempDir dir;
  WriteFileAtomically(dir.File("exposures.csv"),
                      "image,camera,X,Y,Z,omega,phi,kappa,vX,vY,vZ\n"
                      "1,rig1,0,0,1000,0,0,0,50,0,0\n"
                      "2,rig1,100,0,1000,0,0,0,50,,0\n");
  try {
    ReadExposures(dir.File("exposures.csv"));
    ADD_FAILURE() << "a partial velocity was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("exposures.csv:3: vX, vY, vZ must all be given"),
              std::string::npos)
        << e.what();
  }
  WriteFileAtomically(dir.File("observations.csv"), "image,head,subimage,point,u,v\n1,A,I,P,1,2\n");
  EXPECT_THROW(ReadObservations(dir.File("observations.csv"), 0.5), InputError);
  WriteFileAtomically(dir.File("observations.csv"), "image,head,point,col,row\n1,,P,1,2\n");
  try {
    ReadObservations(dir.File("observations.csv"), 0.5);
    ADD_FAILURE() << "an empty head was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("observations.csv:2: head must not be empty"),
              std::string::npos)
        << e.what();
  }
}

TEST(RigFlightSimulator, TheSameSeedGivesTheSameFlight) {
  RigFlightSimulationOptions o;
  o.flight.exposures = 6;
  o.flight.ground_points = 10;
  o.flight.tie_points = 20;
  const SimulatedRigFlight a = SimulateRigFlight(o), b = SimulateRigFlight(o);
  ASSERT_EQ(a.observations.size(), b.observations.size());
  for (size_t i = 0; i < a.observations.size(); ++i)
    EXPECT_EQ(a.observations[i].pixel, b.observations[i].pixel);
  o.flight.seed = 2;
  EXPECT_NE(SimulateRigFlight(o).observations.front().pixel, a.observations.front().pixel);
}

TEST(RigFlightSimulator, Uav4StitchingTiesAreMeasuredInOneExposureAndReadBack) {
  RigFlightSimulationOptions o = RigFlightSimulationOptions::DefaultUav4();
  o.flight.exposures = 3;
  o.flight.image_noise_px = 0.0;
  for (const auto& s :
       stitch::DesignRig(MakeNominalRig(RigPreset::kUav4), 300.0, 200).standard_positions)
    if (s.name == "AB-1" || s.name == "ACD")
      o.stitch_ties.standard_positions.push_back({s.name, s.virtual_px});
  const SimulatedRigFlight f = SimulateRigFlight(o);
  ASSERT_EQ(f.exposures_truth.size(), 3u);
  // Shutter offsets per head, the reference head's zero.
  for (size_t i = 0; i < f.rig_exposures.size(); ++i)
    EXPECT_EQ(f.rig_exposures[i].dt_s, o.head_time_offsets_s[i % 4]) << i;
  std::map<std::string, std::set<std::string>> images, heads;
  for (const auto& obs : f.observations) {
    images[obs.point].insert(obs.image);
    heads[obs.point].insert(obs.head);
  }
  int check = 0, standard = 0;
  for (const auto& p : f.points_file) {
    EXPECT_FALSE(p.xyz_m.has_value()) << p.id;
    EXPECT_EQ(images[p.id].size(), 1u) << p.id << ": a stitching tie belongs to one exposure";
    EXPECT_GE(heads[p.id].size(), 2u) << p.id;
    check += p.role == PointRole::kCheck;
    standard += f.tie_position.count(p.id) > 0;
  }
  EXPECT_EQ(check, 3 * o.stitch_ties.check);
  EXPECT_EQ(standard, 3 * 2 * o.stitch_ties.per_standard_position);
  EXPECT_EQ(f.points_file.size(), static_cast<size_t>(3 * (6 + 40 + 10)));
  // Around ACD: seen by A, C and D.
  for (const auto& [id, position] : f.tie_position)
    if (position == "ACD") {
      EXPECT_EQ(heads[id], (std::set<std::string>{"A", "C", "D"})) << id;
    }
  // z_ref: the terrain under the image, within the relief.
  for (const auto& e : f.exposures_file) {
    ASSERT_TRUE(e.z_ref_m.has_value());
    EXPECT_GE(*e.z_ref_m, o.flight.terrain_base_m);
    EXPECT_LE(*e.z_ref_m, o.flight.terrain_base_m + o.flight.terrain_relief_m);
  }
  // The files read back: check ties keep their role without coordinates, z_ref its value.
  aerocal::testing::TempDir tmp;
  WriteSimulatedRigFlight(f, tmp.path());
  const auto points = ReadPoints(tmp.File("points.csv"));
  ASSERT_EQ(points.size(), f.points_file.size());
  for (size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].role, f.points_file[i].role);
    EXPECT_FALSE(points[i].xyz_m.has_value());
  }
  const auto exposures = ReadExposures(tmp.File("exposures.csv"));
  ASSERT_EQ(exposures.size(), 3u);
  EXPECT_NEAR(*exposures[1].z_ref_m, *f.exposures_file[1].z_ref_m, 1e-6);
}

}  // namespace
}  // namespace aerocal::triangulation
