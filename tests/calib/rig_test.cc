// The rig model (calib/camera/rig.h) and its camera file (rig_io.h): the head pose formula by
// hand, its autodiff Jacobian against numeric differentiation (ceres::GradientChecker), the
// one-head rig that is an ordinary camera, the FORMATS.md example, write/read round trip, a virtual
// camera in another model and FILE:LINE for bad files.
#include "calib/camera/rig.h"

#include "calib/camera/camera_io.h"
#include "calib/camera/rig_io.h"
#include "calib/core/error.h"
#include "calib/core/yaml_util.h"
#include "tests/support/test_support.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/gradient_checker.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

namespace aerocal::calib {
namespace {

constexpr double kDeg = M_PI / 180.0;

void WriteText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

// The FORMATS.md "Multi-head rig" example, completed with a second head.
const char* kFormatsExample = R"(name: UAV-4
rig:
  reference_head: A
  virtual: {orientation: level, c: 24.5, pixel_size_mm: 0.0082, format_px: [12154, 8998], x0: 0.0, y0: 0.0}
  heads:
    - id: A
      pixel_size_mm: 0.0082
      format_px: [4368, 2912]
      interior: {c: 24.47, x0: 0.01, y0: -0.02, K1: 1.2e-4}   # 10-parameter model, as above
      interior_sigma: {c: 0.005}                              # optional
      mount_deg: [24.0, 0.0, 0.0]                             # omega, phi, kappa: head -> rig
      lever_arm_m: [0.0, 0.06, 0.0]                           # head centre in the rig frame
      mount_sigma_deg: [0.01, 0.01, 0.01]                     # optional a-priori sigmas
      lever_arm_sigma_m: [0.001, 0.001, 0.001]                # optional
    - id: B
      pixel_size_mm: 0.0082
      format_px: [4368, 2912]
      interior: {c: 24.52, x0: -0.03, y0: 0.01, K1: 1.1e-4, P2: 2e-6}
      mount_deg: [-24.0, 0.0, 0.5]
      lever_arm_m: [0.0, -0.06, 0.002]
)";

TEST(RigFile, ReadsTheFormatsExample) {
  testing::TempDir dir;
  WriteText(dir.File("rig.yaml"), kFormatsExample);
  const Rig rig = ReadRig(dir.File("rig.yaml"));
  EXPECT_EQ(rig.name, "UAV-4");
  ASSERT_EQ(rig.heads.size(), 2u);
  EXPECT_EQ(rig.reference_head, "A");
  EXPECT_EQ(rig.ReferenceIndex(), 0);
  EXPECT_EQ(rig.virtual_camera.orientation, VirtualOrientation::kLevel);
  EXPECT_EQ(rig.virtual_camera.camera.width_px, 12154);
  EXPECT_EQ(rig.virtual_camera.camera.c_mm(), 24.5);
  EXPECT_FALSE(rig.virtual_camera.height_m.has_value());
  const RigHead& a = rig.heads[0];
  EXPECT_EQ(a.camera.width_px, 4368);
  EXPECT_EQ(a.camera.interior[BrownFraser10Model::kK1], 1.2e-4);
  EXPECT_EQ(*a.camera.interior_sigma[BrownFraser10Model::kC], 0.005);
  EXPECT_NEAR(a.mount_rad[0], 24.0 * kDeg, 1e-15);
  EXPECT_EQ(a.lever_arm_m, Eigen::Vector3d(0.0, 0.06, 0.0));
  ASSERT_TRUE(a.mount_sigma_rad.has_value());
  EXPECT_NEAR((*a.mount_sigma_rad)[2], 0.01 * kDeg, 1e-18);
  EXPECT_EQ(*a.lever_arm_sigma_m, Eigen::Vector3d::Constant(0.001));
  EXPECT_FALSE(rig.heads[1].mount_sigma_rad.has_value()) << "absent sigma = free, never 0";
  EXPECT_EQ(rig.heads[1].camera.interior[BrownFraser10Model::kP2], 2e-6);
}

TEST(RigFile, WriteThenReadGivesTheSameRigAndTheSameBytes) {
  testing::TempDir dir;
  WriteText(dir.File("rig.yaml"), kFormatsExample);
  Rig a = ReadRig(dir.File("rig.yaml"));
  a.virtual_camera.height_m = 1200.0;
  WriteRig(dir.File("out.yaml"), a);
  const Rig b = ReadRig(dir.File("out.yaml"));
  ASSERT_EQ(b.heads.size(), a.heads.size());
  EXPECT_EQ(b.name, a.name);
  EXPECT_EQ(b.reference_head, a.reference_head);
  EXPECT_EQ(b.virtual_camera.orientation, a.virtual_camera.orientation);
  EXPECT_EQ(b.virtual_camera.camera.model, a.virtual_camera.camera.model);
  EXPECT_EQ(b.virtual_camera.camera.interior, a.virtual_camera.camera.interior);
  EXPECT_EQ(*b.virtual_camera.height_m, 1200.0);
  for (size_t k = 0; k < a.heads.size(); ++k) {
    EXPECT_EQ(b.heads[k].id, a.heads[k].id);
    EXPECT_EQ(b.heads[k].camera.interior, a.heads[k].camera.interior);
    EXPECT_EQ(b.heads[k].camera.interior_sigma, a.heads[k].camera.interior_sigma);
    EXPECT_EQ(b.heads[k].camera.pixel_size_mm, a.heads[k].camera.pixel_size_mm);
    // degrees <-> radians: the last bit of the conversion at most.
    EXPECT_NEAR((b.heads[k].mount_rad - a.heads[k].mount_rad).norm(), 0.0, 1e-15);
    EXPECT_EQ(b.heads[k].lever_arm_m, a.heads[k].lever_arm_m);
    EXPECT_EQ(b.heads[k].mount_sigma_rad.has_value(), a.heads[k].mount_sigma_rad.has_value());
  }
  EXPECT_EQ(RigToYaml(ReadRig(dir.File("out.yaml"))), RigToYaml(b));
}

// The virtual camera is a camera in any registered model: `virtual` with `model` and `interior`
// (the camera reader's keys) reads as that camera and is written back in the same form; the
// distortion-free default keeps its short form (c, x0, y0), so existing rig files are written as
// before.
TEST(RigFile, AVirtualCameraInAnyModelRoundTrips) {
  // A one-head rig with this `virtual` section.
  const auto rig_with_virtual = [](const std::string& section) {
    return ParseRig(LoadYamlText("rig:\n  virtual: " + section +
                                     "\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n"
                                     "      format_px: [1000, 800]\n      interior: {c: 15}\n",
                                 "rig.yaml"),
                    "rig.yaml");
  };
  const Rig rig = rig_with_virtual(
      "{orientation: level, model: opencv, pixel_size_mm: 0.006, format_px: [1200, 900], "
      "interior: {fx: 2500, fy: 2501, cx: 600.5, cy: 449, k1: -0.03, p1: 1e-4}, height_m: 300}");
  const Camera& v = rig.virtual_camera.camera;
  EXPECT_EQ(v.model, CameraModelId::kOpenCv);
  EXPECT_EQ(v.width_px, 1200);
  EXPECT_EQ(v.interior[v.ParamIndex("k1")], -0.03);
  EXPECT_EQ(rig.virtual_camera.orientation, VirtualOrientation::kLevel);
  EXPECT_EQ(*rig.virtual_camera.height_m, 300.0);
  EXPECT_NEAR(v.c_mm(), 2501 * 0.006, 1e-12);  // OpenCV's principal distance: fy p
  // A ray through a pixel and back through the model.
  const Eigen::Vector2d pixel(10.0, 880.0);
  const std::optional<Eigen::Vector3d> ray = rig.virtual_camera.RayFromPixel(pixel);
  ASSERT_TRUE(ray.has_value());
  EXPECT_EQ(ray->z(), -v.c_mm());
  Eigen::Vector2d back;
  ASSERT_TRUE(rig.virtual_camera.PixelFromRay(*ray * 3.0, &back));
  EXPECT_LT((back - pixel).norm(), 1e-9);
  EXPECT_FALSE(rig.virtual_camera.PixelFromRay(-*ray, &back));  // behind the camera
  const std::string text = RigToYaml(rig);
  EXPECT_NE(text.find("model: opencv"), std::string::npos) << text;
  const Rig again = ParseRig(LoadYamlText(text, "back.yaml"), "back.yaml");
  EXPECT_EQ(again.virtual_camera.camera.model, v.model);
  EXPECT_EQ(again.virtual_camera.camera.interior, v.interior);
  EXPECT_EQ(RigToYaml(again), text);
  // The default: the short form, c / x0 / y0 of the 10-parameter model's pinhole.
  const Rig pinhole = rig_with_virtual(
      "{c: 150, pixel_size_mm: 0.006, format_px: [1200, 900], x0: 0.25, y0: -0.5}");
  const Camera& p = pinhole.virtual_camera.camera;
  EXPECT_EQ(p.model, BrownFraser10Model::kId);
  EXPECT_EQ(p.interior, PinholeCamera(150, 0.25, -0.5, p.frame()).interior);
  EXPECT_EQ(p.PrincipalPointMm(), Eigen::Vector2d(0.25, -0.5));
  const YAML::Node written = LoadYamlText(RigToYaml(pinhole), "out.yaml")["rig"]["virtual"];
  EXPECT_EQ(written["c"].as<double>(), 150.0);
  EXPECT_EQ(written["x0"].as<double>(), 0.25);
  EXPECT_FALSE(written["interior"]);
  EXPECT_FALSE(written["model"]);
}

TEST(RigFile, TheDualLensExampleLoads) {
  const Rig rig = ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml");
  ASSERT_EQ(rig.heads.size(), 2u);
  EXPECT_EQ(rig.reference_head, "A");
  EXPECT_EQ(*rig.virtual_camera.height_m, 1200.0);
  EXPECT_NEAR(rig.heads[1].mount_rad[1], 1.0 * kDeg, 1e-16);
  EXPECT_EQ(rig.heads[1].lever_arm_m, Eigen::Vector3d(0.15, 0.01, 0.01));
  for (const RigHead& head : rig.heads) {
    EXPECT_EQ(head.camera.width_px, 10000);
    EXPECT_EQ(head.camera.pixel_size_mm, 0.006);
    EXPECT_EQ(head.camera.c_mm(), 150.0);
    EXPECT_EQ(head.camera.interior[BrownFraser10Model::kX0], 3.0);
    EXPECT_EQ(head.camera.interior[BrownFraser10Model::kY0], 3.0);
  }
}

// A rig of one head with identity mount and zero lever arm is the ordinary camera: the same
// camera back, and the head projection gives Camera::ProjectToPixel's pixel.
TEST(RigFile, AOneHeadRigIsAnOrdinaryCamera) {
  testing::TempDir dir;
  Camera camera;
  camera.name = "frame";
  camera.pixel_size_mm = 0.009;
  camera.width_px = 14000;
  camera.height_px = 12000;
  camera.interior = {170.038, -0.0024, 0.0015, 3e-8, -2e-12, 1e-16, 2e-7, -1.5e-7, 1e-5, -8e-6};
  WriteCamera(dir.File("camera.yaml"), camera);
  // A plain camera file is read as a rig of one head ...
  const Rig from_camera_file = ReadRig(dir.File("camera.yaml"));
  ASSERT_EQ(from_camera_file.heads.size(), 1u);
  // ... and a one-head rig file without reference_head or virtual section is allowed.
  WriteText(
      dir.File("rig.yaml"),
      "name: frame\nrig:\n  heads:\n    - id: H\n      pixel_size_mm: 0.009\n"
      "      format_px: [14000, 12000]\n      interior: {c: 170.038, x0: -0.0024, y0: 0.0015, "
      "K1: 3e-8, K2: -2e-12, K3: 1e-16, P1: 2e-7, P2: -1.5e-7, B1: 1e-5, B2: -8e-6}\n");
  const Rig from_rig_file = ReadRig(dir.File("rig.yaml"));
  EXPECT_EQ(from_rig_file.reference_head, "H");
  EXPECT_EQ(from_rig_file.virtual_camera.camera.c_mm(), camera.c_mm());
  EXPECT_EQ(from_rig_file.virtual_camera.camera.PrincipalPointMm().x(),
            camera.interior[BrownFraser10Model::kX0]);
  for (const Rig* rig : {&from_camera_file, &from_rig_file}) {
    const auto back = CameraFromSingleHeadRig(*rig);
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->interior, camera.interior);
    EXPECT_EQ(back->width_px, camera.width_px);
    EXPECT_EQ(back->pixel_size_mm, camera.pixel_size_mm);
  }
  Rig moved = from_rig_file;
  moved.heads[0].lever_arm_m.x() = 0.1;
  EXPECT_FALSE(CameraFromSingleHeadRig(moved).has_value());

  // The head projection of the one-head rig = the camera's collinearity.
  const double opk[3] = {0.01, -0.008, 0.3}, center[3] = {100.0, -50.0, 4700.0};
  const double point[3] = {600.0, 300.0, 250.0};
  const double zero[3] = {0, 0, 0}, dt = 0.0;
  const RigHead& head = from_rig_file.heads[0];
  double ideal[2];
  ASSERT_TRUE(ProjectHeadIdeal(head.camera.interior.data(),
                               opk,
                               center,
                               head.mount_rad.data(),
                               head.lever_arm_m.data(),
                               zero,
                               &dt,
                               zero,
                               point,
                               ideal));
  Eigen::Vector2d measured;
  ASSERT_TRUE(BrownFraser10Model::MeasuredFromIdeal(
      head.camera.interior.data(), Eigen::Vector2d(ideal[0], ideal[1]), &measured, 1e-12));
  Eigen::Vector2d expected;
  ASSERT_TRUE(camera.ProjectToPixel(
      Eigen::Vector3d(opk), Eigen::Vector3d(center), Eigen::Vector3d(point), &expected));
  EXPECT_NEAR((head.camera.PixelFromPhoto(measured) - expected).norm(), 0.0, 1e-9);
}

// R_k = R M_k E_k and O_k = O + R t_k + v dT_k, against Eigen products written out here.
TEST(HeadPose, IsTheConventionsFormula) {
  const Eigen::Vector3d rig_opk(0.02, -0.03, 1.2), rig_center(500.0, -200.0, 1500.0);
  const Eigen::Vector3d mount(0.4, -0.1, 0.05), lever(0.1, -0.06, 0.02);
  const Eigen::Vector3d increment(1e-4, -2e-4, 3e-4), velocity(60.0, -5.0, 0.3);
  const double dt = 0.002;
  double rotation[9];
  Eigen::Vector3d center;
  HeadPose(rig_opk.data(),
           rig_center.data(),
           mount.data(),
           lever.data(),
           increment.data(),
           &dt,
           velocity.data(),
           rotation,
           center.data());
  const Eigen::Matrix3d expected =
      RotationFromOpk(rig_opk) * RotationFromOpk(mount) * RotationFromOpk(increment);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(rotation[3 * i + j], expected(i, j), 1e-15);
  const Eigen::Vector3d expected_center =
      rig_center + RotationFromOpk(rig_opk) * lever + velocity * dt;
  EXPECT_NEAR((center - expected_center).norm(), 0.0, 1e-12);
  // By hand: on a nadir rig, a head mounted at omega = 90 deg has its viewing axis -z turned to
  // Rx(90) (0, 0, -1) = (0, 1, 0): it looks forward along the rig's +y.
  const double nadir[3] = {0, 0, 0}, origin[3] = {0, 0, 0}, quarter[3] = {M_PI / 2, 0, 0};
  const double no_dt = 0.0;
  HeadPose(nadir, origin, quarter, lever.data(), origin, &no_dt, origin, rotation, center.data());
  EXPECT_NEAR(-rotation[2], 0.0, 1e-15);
  EXPECT_NEAR(-rotation[5], 1.0, 1e-15);
  EXPECT_NEAR(-rotation[8], 0.0, 1e-15);
  EXPECT_EQ(center, lever);
}

// The projection as a rig residual would use it, differentiated by Ceres (Jets) and checked
// against numeric differentiation in every block.
struct HeadProjection {
  template <typename T>
  bool operator()(const T* interior,
                  const T* rig_opk,
                  const T* rig_center,
                  const T* mount,
                  const T* lever,
                  const T* increment,
                  const T* dt,
                  const T* velocity,
                  const T* point,
                  T* ideal) const {
    return ProjectHeadIdeal(
        interior, rig_opk, rig_center, mount, lever, increment, dt, velocity, point, ideal);
  }
};

TEST(HeadPose, AutodiffMatchesNumericDerivatives) {
  double interior[10] = {150.2, 3.001, 2.998, 2e-6, -1e-10, 0, 1e-7, -2e-7, 1e-5, 0};
  double rig_opk[3] = {0.01, -0.02, 0.4}, rig_center[3] = {100.0, 200.0, 1250.0};
  double mount[3] = {0.002, 0.0175, -0.001}, lever[3] = {0.15, 0.01, 0.01};
  double increment[3] = {1e-5, -2e-5, 3e-5}, dt[1] = {0.001}, velocity[3] = {70.0, 3.0, -0.5};
  double point[3] = {130.0, 260.0, 20.0};
  ceres::AutoDiffCostFunction<HeadProjection, 2, 10, 3, 3, 3, 3, 3, 1, 3, 3> cost(
      new HeadProjection);
  std::vector<double*> blocks = {
      interior, rig_opk, rig_center, mount, lever, increment, dt, velocity, point};
  ceres::NumericDiffOptions options;
  const std::vector<const ceres::Manifold*>* no_manifolds = nullptr;
  ceres::GradientChecker checker(&cost, no_manifolds, options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(blocks.data(), 1e-6, &results)) << results.error_log;
  // Behind the head: no projection.
  point[2] = 2000.0;
  double residual[2];
  EXPECT_FALSE(cost.Evaluate(blocks.data(), residual, nullptr));
}

// Each bad file is refused with FILE:LINE and what is wrong.
TEST(RigFile, BadFilesNameFileAndLine) {
  testing::TempDir dir;
  const std::string head_a =
      "    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
      "      interior: {c: 150}\n";
  const std::string virt = "  virtual: {c: 150, pixel_size_mm: 0.006, format_px: [120, 100]}\n";
  struct Case {
    std::string text, expected;
  } cases[] = {
      {"rig:\n  reference_head: Z\n" + virt + "  heads:\n" + head_a, ":2: reference_head 'Z'"},
      {"rig:\n  reference_head: A\n" + virt + "  heads:\n" + head_a + head_a,
       ":9: duplicate head id 'A'"},
      {"rig:\n" + virt + "  heads:\n" + head_a +
           "    - id: B\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
           "      interior: {c: 150}\n",
       ":2: a rig of several heads needs reference_head"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: -5}\n",
       ":6: interior.c must be > 0"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: 150}\n      mount_deg: [1, 2]\n",
       ":7: mount_deg must be a list of 3 numbers"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: 150}\n      lever_arm_m: [0, nan, 0]\n",
       ":7: lever_arm_m must be a number"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: 150}\n      lever_arm_sigma_m: [0.001, 0, 0.001]\n",
       ":7: lever_arm_sigma_m must be > 0"},
      {"rig:\n  heads:\n    - id: A\n      format_px: [100, 100]\n      interior: {c: 150}\n",
       ":3: head A: missing pixel_size_mm"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: 150, K9: 1}\n",
       ":6: unknown key 'K9'"},
      {"rig:\n  heads:\n    - id: A\n      pixel_size_mm: 0.006\n      format_px: [100, 100]\n"
       "      interior: {c: 150}\n      mounts_deg: [0, 0, 0]\n",
       ":7: unknown key 'mounts_deg'"},
      {"rig:\n  reference_head: A\n  virtual: {orientation: tilted, c: 150, pixel_size_mm: 0.006, "
       "format_px: [120, 100]}\n  heads:\n" +
           head_a,
       ":3: virtual.orientation must be rig or level"},
      {"rig:\n  reference_head: A\n  virtual: {c: 150, pixel_size_mm: 0.006, format_px: [120, "
       "100], "
       "height_m: -3}\n  heads:\n" +
           head_a,
       ":3: virtual.height_m out of range (got -3, expected 1 .. 100000)"},
      {"rig:\n  reference_head: A\n  virtual: {c: 150, format_px: [120, 100]}\n  heads:\n" + head_a,
       ":3: virtual: missing pixel_size_mm"},
      {"rig:\n  reference_head: A\n  virtual: {c: 150, pixel_size_mm: 0.006, format_px: [120, "
       "100], interior: {c: 150}}\n  heads:\n" +
           head_a,
       ":3: virtual.c: give the pinhole's c, x0, y0 or a camera's interior, not both"},
      {"rig:\n  reference_head: A\n  virtual: {model: opencv, pixel_size_mm: 0.006, format_px: "
       "[120, 100], interior: {fx: 2500, fy: 2500}, interior_sigma: {fx: 1}}\n  heads:\n" +
           head_a,
       ":3: virtual.interior_sigma: the virtual camera has no interior_sigma"},
      {"rig:\n  reference_head: A\n  virtual: {model: pinhole9, pixel_size_mm: 0.006, format_px: "
       "[120, 100], interior: {c: 150}}\n  heads:\n" +
           head_a,
       ":3: unknown camera model 'pinhole9'"},
      {"rig:\n  heads: []\n", ":2: rig.heads must be a non-empty list"},
      {"name: x\nrig:\n  heads:\n" + head_a + "extra: 1\n", ":8: unknown key 'extra'"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    WriteText(dir.File("bad.yaml"), c.text);
    try {
      ReadRig(dir.File("bad.yaml"));
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("bad.yaml" + c.expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace aerocal::calib
