// The camera-model registry reaches every residual family with a camera (issue 30 item 4; the claim
// of docs/architecture.md "A camera model": its struct plus one list entry):
// - every registered model (ForEachCameraModel) gets from each family's factory (frame camera,
//   raw sub-image through its mapping, rig head) a residual whose interior block is the model's
//   size, that is zero at the true geometry and whose Jacobians match numeric differentiation;
// - a rig whose heads are in OpenCV's and COLMAP's models, noise-free, gives back the true mount,
//   lever arm and distortion of head B in the rig bundle, and its rig file round-trips;
// - every registered model is a rig's virtual camera: its rig file round-trips, the conversion
//   between heads and the virtual image goes through its own projection;
// - a multi-CCD camera in OpenCV's model, noise-free, gives back a sub-image's mapping half a
//   pixel off (joint adjustment) and the distortion (default sub-image kind) to 1e-8.
#include "calib/camera/camera_io.h"
#include "calib/camera/convert_camera.h"
#include "calib/camera/rig_io.h"
#include "calib/residuals/collinearity.h"
#include "stitch/rig/rig_conversion.h"
#include "tests/support/rig_flight_project.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block_io.h"
#include "triangulation/joint/joint_adjustment.h"
#include "triangulation/sensor/rig_head_camera.h"
#include "triangulation/simulation/flight_simulator.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace aerocal::triangulation {
namespace {

using calib::CameraModelId;

// Noise-free data: the solver's end point lies within this relative distance of the truth (the
// rig bundle's noise-free test reaches 1e-9; 1e-8 leaves room for the models' Newton inversions).
constexpr double kRelative = 1e-8;

// |estimate - truth| <= kRelative * max(|truth|, floor): relative, with an absolute floor for
// entries near zero (in the entry's own unit).
void ExpectNear(double estimate, double truth, double floor, const std::string& what) {
  EXPECT_LE(std::abs(estimate - truth), kRelative * std::max(std::abs(truth), floor))
      << what << ": " << estimate << " vs " << truth;
}

// `source` (distortion-free) in model `id`: the closed-form or fitted conversion, then a radial
// term of the model's own (its first radial parameter) so that its distortion takes part.
calib::Camera CameraInModel(const calib::Camera& source, CameraModelId id, double radial = -0.02) {
  calib::Camera camera =
      source.WithModelCamera(calib::ConvertCamera(source.AsModelCamera(), id).camera);
  const std::vector<calib::ParamInfo> table = camera.Params();
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].group == calib::ParamGroup::kRadial) {
      // Unitless terms act on normalised coordinates; brown_fraser_10's K1 on mm (mm^-2):
      // about the same few pixels at the format's corner.
      camera.interior[static_cast<int>(i)] = table[i].unit == "1" ? radial : radial * 1e-4;
      break;
    }
  return camera;
}

// ---------------------------------------------------------------------------------------------
// Every model, every family.

// Autodiff against Ceres' numeric differentiation, entry by entry: relative 1e-6 with an absolute
// floor of 1e-9 (GradientChecker's own verdict is relative only and fails on entries that are 0 up
// to rounding, such as d/d fy of a residual's x).
void ExpectGradientsMatch(const ceres::CostFunction& cost, const std::vector<double*>& blocks) {
  ceres::NumericDiffOptions options;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  checker.Probe(blocks.data(), 1e-6, &results);
  ASSERT_TRUE(results.return_value);
  ASSERT_EQ(results.jacobians.size(), blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    const Eigen::MatrixXd& autodiff = results.jacobians[b];
    const Eigen::MatrixXd& numeric = results.numeric_jacobians[b];
    for (int i = 0; i < autodiff.rows(); ++i)
      for (int j = 0; j < autodiff.cols(); ++j) {
        const double a = autodiff(i, j), n = numeric(i, j);
        EXPECT_LE(std::abs(a - n), 1e-6 * std::max(std::abs(a), std::abs(n)) + 1e-9)
            << "block " << b << " entry (" << i << ", " << j << "): " << a << " vs " << n;
      }
  }
}

// Zero at the true geometry; the Jacobians compared one pixel off it (at a zero residual the
// checker's relative comparison of the residuals themselves is meaningless).
void ExpectZeroAndGradientsMatch(
    const std::function<std::unique_ptr<ceres::CostFunction>(const Eigen::Vector2d& offset_px)>&
        make,
    const std::vector<double*>& blocks) {
  double r[2];
  ASSERT_TRUE(make(Eigen::Vector2d::Zero())->Evaluate(blocks.data(), r, nullptr));
  EXPECT_LT(std::hypot(r[0], r[1]), 1e-6);  // sigmas: 2e-7 px at sigma 0.2 px
  ExpectGradientsMatch(*make(Eigen::Vector2d(0.7, -0.4)), blocks);
}

// A 100 mm camera of 4000 x 3000 pixels of 10 um, distortion-free, in brown_fraser_10.
calib::Camera BaseCamera() {
  calib::Camera camera;
  camera.pixel_size_mm = 0.01;
  camera.width_px = 4000;
  camera.height_px = 3000;
  camera.interior[calib::BrownFraser10Model::kC] = 100.0;
  camera.interior[calib::BrownFraser10Model::kX0] = 0.12;
  camera.interior[calib::BrownFraser10Model::kY0] = -0.08;
  return camera;
}

struct Scene {
  Eigen::Vector3d opk{0.01, -0.008, 0.3};
  Eigen::Vector4d rotation = calib::QuaternionFromOpk(opk);
  Eigen::Vector3d center{100.0, -50.0, 1500.0};
  Eigen::Vector3d point{420.0, 260.0, 250.0};
  // A head: mount, lever arm, increment, time offset, platform velocity.
  Eigen::Vector3d mount{0.002, 0.0175, -0.001}, lever{0.15, 0.01, 0.01};
  Eigen::Vector3d increment{1e-5, -2e-5, 3e-5}, velocity{60.0, 5.0, -1.0};
  double dt = 0.002;
};

template <typename Model>
void CheckEveryFamily() {
  SCOPED_TRACE(std::string(Model::kName));
  const calib::Camera camera = CameraInModel(BaseCamera(), Model::kId);
  ASSERT_EQ(camera.interior.size(), Model::kNumParams);
  std::vector<double> interior = camera.interior.values();
  Scene s;
  const std::vector<int> interior_block = {Model::kNumParams};

  // Frame camera.
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera.ProjectToPixel(s.opk, s.center, s.point, &pixel));
  const auto frame = [&](const Eigen::Vector2d& offset) {
    return calib::MakeCollinearityResidual(Model::kId, camera.frame(), pixel + offset, 0.2);
  };
  EXPECT_EQ(frame({0, 0})->parameter_block_sizes(), std::vector<int>({Model::kNumParams, 4, 3, 3}));
  ExpectZeroAndGradientsMatch(
      frame, {interior.data(), s.rotation.data(), s.center.data(), s.point.data()});

  // Raw sub-image: an affine mapping takes (u, v) to the virtual pixel, then the same camera.
  const calib::MappingModel affine = calib::MappingModel::kAffine;
  Eigen::Matrix3d h = Eigen::Matrix3d::Identity();
  h << 1.0002, 1e-4, 1900.3, -1e-4, 0.9998, 1433.1, 0, 0, 1;
  const calib::SubimageMapping mapping{
      "I", 2000, 1500, affine, calib::ParamsFromHomography(affine, h)};
  const calib::MappingConditioning cond =
      calib::MappingConditioning::ForSubimage(affine, mapping.width_px, mapping.height_px);
  std::vector<double> conditioned = calib::ConditionedFromPlain(affine, cond, mapping.params);
  const auto sub = [&](const Eigen::Vector2d& offset) {
    return calib::MakeSubimageCollinearityResidual(
        Model::kId, affine, camera.frame(), cond, mapping.SubFromVirtual(pixel) + offset, 0.2);
  };
  EXPECT_EQ(sub({0, 0})->parameter_block_sizes(),
            std::vector<int>({calib::MappingParamCount(affine), Model::kNumParams, 4, 3, 3}));
  ExpectZeroAndGradientsMatch(
      sub,
      {conditioned.data(), interior.data(), s.rotation.data(), s.center.data(), s.point.data()});

  // Rig head: R_k = R M_k E_k, O_k = O + R t_k + v dT_k (calib/camera/rig.h), Eigen oracle.
  const Eigen::Matrix3d r = calib::RotationFromOpk(s.opk);
  const Eigen::Matrix3d rk =
      r * calib::RotationFromOpk(s.mount) * calib::RotationFromOpk(s.increment);
  const Eigen::Vector3d ok = s.center + r * s.lever + s.velocity * s.dt;
  Eigen::Vector2d head_pixel;
  ASSERT_TRUE(camera.ProjectToPixel(calib::OpkFromRotation(rk), ok, s.point, &head_pixel));
  const auto head = [&](const Eigen::Vector2d& offset) {
    return calib::MakeRigHeadCollinearityResidual(
        Model::kId, camera.frame(), head_pixel + offset, 0.25, s.velocity);
  };
  EXPECT_EQ(head({0, 0})->parameter_block_sizes(),
            std::vector<int>({Model::kNumParams, 4, 3, 3, 3, 3, 1, 3}));
  ExpectZeroAndGradientsMatch(head,
                              {interior.data(),
                               s.rotation.data(),
                               s.center.data(),
                               s.mount.data(),
                               s.lever.data(),
                               s.increment.data(),
                               &s.dt,
                               s.point.data()});
}

TEST(ModelFamilies, EveryRegisteredModelReachesEveryCameraResidualFamily) {
  int models = 0;
  calib::ForEachCameraModel([&](auto model) {
    CheckEveryFamily<decltype(model)>();
    ++models;
  });
  std::printf("%d registered models x 3 families (frame, sub-image, rig head)\n", models);
  EXPECT_GE(models, 11);
}

// ---------------------------------------------------------------------------------------------
// The virtual camera of a rig in every model.

// The dual-lens rig's virtual camera in `Model` (with its radial term): the rig file keeps it; a
// virtual pixel's point on the rectification plane is seen at that pixel by the virtual camera as
// a frame camera at the virtual pose (its own projection, Camera::ProjectToPixel), and every head
// that sees the point carries it back to the same virtual pixel.
template <typename Model>
void CheckVirtualCamera() {
  SCOPED_TRACE(std::string(Model::kName));
  calib::Rig rig = MakeNominalRig(RigPreset::kDualLens);
  calib::Camera& v = rig.virtual_camera.camera;
  v = CameraInModel(v, Model::kId);
  const calib::Rig back = calib::ParseRig(YAML::Load(calib::RigToYaml(rig)), "rig.yaml");
  EXPECT_EQ(back.virtual_camera.camera.model, Model::kId);
  EXPECT_EQ(back.virtual_camera.camera.interior, v.interior);
  stitch::RigExposure exposure;
  exposure.rig_opk_rad = Eigen::Vector3d(0.01, -0.02, 0.3);
  exposure.rig_center_m = Eigen::Vector3d(10.0, -20.0, 1250.0);
  const stitch::RigConverter converter(
      rig, exposure, stitch::MakeRectificationPlane(rig, exposure, 1200.0));
  const Eigen::Vector3d virtual_opk = calib::OpkFromRotation(converter.ObjectFromVirtual());
  int seen_by_heads = 0;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) {
      const Eigen::Vector2d pixel(i * (v.width_px - 1) / 4.0, j * (v.height_px - 1) / 4.0);
      const auto ground = converter.PlanePointOfVirtualPixel(pixel);
      ASSERT_TRUE(ground.has_value()) << pixel.transpose();
      Eigen::Vector2d seen;
      ASSERT_TRUE(v.ProjectToPixel(virtual_opk, converter.VirtualCenter(), *ground, &seen));
      EXPECT_LT((seen - pixel).norm(), 1e-6) << pixel.transpose();
      for (int k = 0; k < static_cast<int>(rig.heads.size()); ++k) {
        const auto head_px = converter.HeadFromVirtual(k, pixel);
        if (!head_px || !converter.InHeadFormat(k, *head_px)) continue;
        const auto again = converter.VirtualFromHead(k, *head_px);
        ASSERT_TRUE(again.has_value());
        EXPECT_LT((*again - pixel).norm(), 1e-6) << rig.heads[k].id << " " << pixel.transpose();
        ++seen_by_heads;
      }
    }
  EXPECT_GE(seen_by_heads, 10);
}

TEST(ModelFamilies, EveryRegisteredModelIsARigsVirtualCamera) {
  calib::ForEachCameraModel([&](auto model) { CheckVirtualCamera<decltype(model)>(); });
}

// ---------------------------------------------------------------------------------------------
// A rig with heads in OpenCV's and COLMAP's models.

TEST(ModelFamilies, RigWithHeadsInOpenCvAndColmapRecoversTheTruthNoiseFree) {
  RigFlightSimulationOptions o;
  o.interior_correction = {calib::InteriorParams{}};  // heads' interiors as the nominal rig
  o.flight.image_noise_px = 0.0;
  SimulatedRigFlight f = SimulateRigFlight(o);
  // Truth: head A (reference) in OpenCV's model, head B in COLMAP's OPENCV, each with its own
  // radial distortion; the nominal rig knows them but not head B's k1, mount and lever arm.
  const CameraModelId models[] = {CameraModelId::kOpenCv, CameraModelId::kColmapOpenCv};
  ASSERT_EQ(f.truth.heads.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    f.truth.heads[k].camera = CameraInModel(f.truth.heads[k].camera, models[k], -0.02 - 0.01 * k);
    f.nominal.heads[k].camera = f.truth.heads[k].camera;
  }
  calib::Camera& nominal_b = f.nominal.heads[1].camera;
  nominal_b.interior[nominal_b.ParamIndex("k1")] = 0.0;

  // The head pixels through the true heads in their models.
  std::map<std::string, const Exposure*> exposure_of;
  for (const Exposure& e : f.exposures_truth) exposure_of[e.image] = &e;
  std::map<std::string, Eigen::Vector3d> point_of;
  for (const GroundPoint& p : f.points_truth) point_of[p.id] = *p.xyz_m;
  std::map<std::pair<std::string, std::string>, const RigExposureTruth*> increment_of;
  for (const RigExposureTruth& t : f.rig_exposures) increment_of[{t.image, t.head}] = &t;
  for (ImageObservation& ob : f.observations)
    ASSERT_TRUE(ProjectRigHead(f.truth.heads[f.truth.HeadIndex(ob.head)],
                               *exposure_of.at(ob.image),
                               *increment_of.at({ob.image, ob.head}),
                               point_of.at(ob.point),
                               &ob.pixel));

  // The rig file keeps each head's model and interior.
  const calib::Rig back = calib::ParseRig(YAML::Load(calib::RigToYaml(f.nominal)), "rig.yaml");
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(back.heads[k].camera.model, models[k]);
    EXPECT_EQ(back.heads[k].camera.interior, f.nominal.heads[k].camera.interior);
  }

  Project project = testing::RigFlightProject(f, f.nominal);
  for (GroundPoint& p : project.points)  // control without survey noise
    if (p.xyz_m) p.xyz_m = point_of.at(p.id);
  AdjustOptions options;
  options.data_snooping = false;
  options.auto_robust_start = false;
  options.free_interior = {"k1"};  // a name both models have
  const RigAdjustmentResult r = AdjustRig(project, options, {});
  ASSERT_TRUE(r.adjustment.solve.converged) << r.adjustment.solve.message;
  const calib::RigHead& truth = f.truth.heads[1];
  const RigHeadEstimate& b = r.heads[1];
  EXPECT_EQ(b.model, CameraModelId::kColmapOpenCv);
  for (int i = 0; i < 3; ++i) {
    ExpectNear(b.mount_rad(i), truth.mount_rad(i), truth.mount_rad.norm(), "mount");
    ExpectNear(b.lever_arm_m(i), truth.lever_arm_m(i), truth.lever_arm_m.norm(), "lever arm");
  }
  for (int k = 0; k < 2; ++k) {
    const calib::Camera& t = f.truth.heads[k].camera;
    ExpectNear(r.heads[k].interior[t.ParamIndex("k1")], t.interior[t.ParamIndex("k1")], 0.0, "k1");
  }
  std::printf("rig (opencv + colmap_opencv heads): |mount error| %.3g rad, |lever error| %.3g m\n",
              (b.mount_rad - truth.mount_rad).norm(),
              (b.lever_arm_m - truth.lever_arm_m).norm());
}

// ---------------------------------------------------------------------------------------------
// A multi-CCD camera in OpenCV's model.

struct SubimageFlight {
  SimulatedFlight sim;
  calib::Camera truth;  // the simulated camera in OpenCV's model, with the true mappings
  Project project;      // raw sub-image pixels through `truth`; control without survey noise
};

SubimageFlight MakeSubimageFlight() {
  FlightSimulationOptions o;
  o.seed = 12;
  o.image_noise_px = 0.0;
  o.stitching.ties_per_frame = 0;
  SubimageFlight f;
  f.sim = SimulateFlight(o);
  f.truth = CameraInModel(f.sim.truth, CameraModelId::kOpenCv);
  EXPECT_EQ(f.truth.subimages.size(), f.sim.truth.subimages.size());
  std::map<std::string, const Exposure*> exposure_of;
  for (const Exposure& e : f.sim.exposures_truth) exposure_of[e.image] = &e;
  std::map<std::string, Eigen::Vector3d> point_of;
  for (const GroundPoint& p : f.sim.points_truth) point_of[p.id] = *p.xyz_m;
  Project& p = f.project;
  p.path = "simulated/project_subimage.yaml";
  const std::string camera_id = f.sim.exposures_file.front().camera;
  p.cameras[camera_id] = f.truth;
  p.camera_files[camera_id] = "simulated/camera.yaml";
  p.exposures = f.sim.exposures_file;
  p.points = f.sim.points_file;
  for (GroundPoint& g : p.points)
    if (g.xyz_m) g.xyz_m = point_of.at(g.id);
  for (ImageObservation ob : f.sim.subimage_observations) {
    const Exposure& e = *exposure_of.at(ob.image);
    Eigen::Vector2d virtual_px;
    EXPECT_TRUE(f.truth.ProjectToPixel(e.opk_rad, e.center_m, point_of.at(ob.point), &virtual_px));
    ob.pixel = f.truth.subimages[f.truth.SubimageIndex(ob.subimage)].SubFromVirtual(virtual_px);
    p.observations.push_back(ob);
  }
  ValidateProject(p);
  return f;
}

TEST(ModelFamilies, SubimageCameraInOpenCvRecoversTheTruthNoiseFree) {
  SubimageFlight f = MakeSubimageFlight();
  const std::string camera_id = f.project.cameras.begin()->first;
  const calib::Camera& truth = f.truth;
  const int k1 = truth.ParamIndex("k1");
  AdjustOptions options;
  options.data_snooping = false;
  options.auto_robust_start = false;
  options.free_interior = {"k1", "k2"};

  // Default sub-image kind (the camera file's mappings): k1 from 0.
  Project start = f.project;
  start.cameras[camera_id].interior[k1] = 0.0;
  const AdjustmentResult mapped = Adjust(start, options);
  ASSERT_TRUE(mapped.converged()) << mapped.solve.message;
  ExpectNear(mapped.cameras.at(0).estimated[k1], truth.interior[k1], 0.0, "k1 (mapped)");

  // Joint adjustment: sub-image I's mapping half a pixel off, k1 from 0, III and IV the datum.
  calib::SubimageMapping& sub = start.cameras[camera_id].subimages[truth.SubimageIndex("I")];
  Eigen::Matrix3d h = calib::HomographyFromParams(sub.model, sub.params.data());
  h(0, 2) += 0.5;
  h(1, 2) += 0.5;
  sub.params = calib::ParamsFromHomography(sub.model, h);
  JointOptions joint_options;
  joint_options.adjust = options;
  joint_options.base_ids = {"III", "IV"};
  joint_options.use_stitching = false;
  const JointResult joint = AdjustJoint(start, joint_options);
  ASSERT_TRUE(joint.adjustment.converged()) << joint.adjustment.solve.message;
  ExpectNear(joint.adjustment.cameras.at(0).estimated[k1], truth.interior[k1], 0.0, "k1 (joint)");
  int checked = 0;
  for (const MappingEstimate& m : joint.mappings) {
    const calib::SubimageMapping& t = truth.subimages[truth.SubimageIndex(m.subimage)];
    for (size_t i = 0; i < m.params.size(); ++i)
      ExpectNear(m.params[i], t.params[i], 1.0, "mapping " + m.subimage + " p" + std::to_string(i));
    checked += m.subimage == "I";
  }
  EXPECT_EQ(checked, 1);
  std::printf("sub-image camera in opencv: k1 %.12g (truth %.12g), joint k1 %.12g\n",
              mapped.cameras.at(0).estimated[k1],
              truth.interior[k1],
              joint.adjustment.cameras.at(0).estimated[k1]);
}

}  // namespace
}  // namespace aerocal::triangulation
