// Conversion error analysis of the dual-lens example (stitch/rig/error_analysis.h): the physics by
// hand (10" at c = 150 mm, the principal points of the two heads with opposite signs, lever arm
// and height parallaxes), exactness (zero limits give exactly zero), Monte-Carlo against linear
// propagation, the grouped worst cases and the grid.
#include "calib/camera/convert_camera.h"
#include "calib/camera/rig_io.h"
#include "stitch/rig/error_analysis.h"
#include "stitch/rig/error_analysis_json.h"
#include "stitch/rig/rig_conversion.h"

#include <gtest/gtest.h>

#include <cmath>

namespace aerocal::stitch {
namespace {

constexpr double kArcsec = M_PI / (180.0 * 3600.0);
constexpr double kC = 150.0, kPixel = 0.006, kHeight = 1200.0;

calib::Rig ExampleRig() {
  return calib::ReadRig(std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens.yaml");
}
ErrorLimits ExampleLimits() {
  return ReadErrorLimits(std::string(AEROCAL_CONFIGS_DIR) + "/rig_dual_lens_limits.yaml");
}

// Virtual pixel of a head-B pixel under the nominal rig.
Eigen::Vector2d VirtualOfB(const calib::Rig& rig, const Eigen::Vector2d& b) {
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, kHeight));
  return *converter.VirtualFromHead(1, b);
}

const SourceErrorRow& Row(const std::vector<SourceErrorRow>& rows, const std::string& name) {
  for (const auto& row : rows)
    if (row.source == name) return row;
  throw std::runtime_error("no row " + name);
}

TEST(RigErrorAnalysis, LimitsFileAndSources) {
  const ErrorLimits limits = ExampleLimits();
  EXPECT_EQ(limits.principal_point_px, 0.5);
  EXPECT_EQ(limits.principal_distance_px, 1.0);
  EXPECT_EQ(limits.angles_arcsec, 10.0);
  EXPECT_EQ(limits.lever_arm_mm, 1.0);
  EXPECT_EQ(limits.height_m, 150.0);
  EXPECT_EQ(limits.sigmas, 3.0);
  const auto sources = MakeErrorSources(ExampleRig(), limits);
  std::vector<std::string> names;
  for (const auto& s : sources) names.push_back(s.name);
  EXPECT_EQ(names,
            (std::vector<std::string>{"x0:A",
                                      "y0:A",
                                      "c:A",
                                      "x0:B",
                                      "y0:B",
                                      "c:B",
                                      "omega:B",
                                      "phi:B",
                                      "kappa:B",
                                      "tx:B",
                                      "ty:B",
                                      "tz:B",
                                      "height"}));
  EXPECT_DOUBLE_EQ(sources[0].limit, 0.5 * kPixel);  // mm
  EXPECT_DOUBLE_EQ(sources[2].limit, 1.0 * kPixel);  // mm
  EXPECT_DOUBLE_EQ(sources[6].limit, 10 * kArcsec);  // rad
  EXPECT_DOUBLE_EQ(sources[9].limit, 1e-3);          // m
  EXPECT_DOUBLE_EQ(sources[12].limit, 150.0);        // m
  EXPECT_NEAR(NormalBound99_75(), 3.0233, 1e-4);
}

// At head B's principal point (5499.5, 4499.5): a rotation of 10" moves the point by
// c tan(10") / p = 150 mm x 4.848e-5 / 6 um = 1.212 px, phi along x (+), omega along y (-),
// kappa not at all; the principal points of A and B act with opposite signs; 1 mm of lever arm
// moves it by 1 mm x c / H / p = 0.0208 px; the height by the parallax of the 0.15 m baseline,
// c 0.15 m (1/H - 1/(H + dH)) / p.
TEST(RigErrorAnalysis, ExampleCameraPhysicsByHand) {
  const calib::Rig rig = ExampleRig();
  const ConversionErrorModel model(
      rig, kHeight, MakeErrorSources(rig, ExampleLimits()), 1, VirtualOfB(rig, {5499.5, 4499.5}));
  EXPECT_LT((model.head_px() - Eigen::Vector2d(5499.5, 4499.5)).norm(), 1e-8);
  const auto rows = MaximumErrors(model);
  const double rotation_px = kC * std::tan(10 * kArcsec) / kPixel;
  EXPECT_NEAR(rotation_px, 1.212, 0.001);
  // 0.3 %: the 1 deg convergence and the 0.01 m offsets bend the first-order figure.
  EXPECT_NEAR(Row(rows, "phi:B").plus_px.x(), rotation_px, 0.003 * rotation_px);
  EXPECT_NEAR(Row(rows, "phi:B").minus_px.x(), -rotation_px, 0.003 * rotation_px);
  EXPECT_NEAR(Row(rows, "phi:B").plus_px.y(), 0.0, 0.001);
  EXPECT_NEAR(Row(rows, "omega:B").plus_px.y(), -rotation_px, 0.003 * rotation_px);
  EXPECT_NEAR(Row(rows, "omega:B").plus_px.x(), 0.0, 0.03);  // omega about the rig x: phi = 1 deg
  EXPECT_LT(Row(rows, "kappa:B").plus_px.norm(), 1e-3);      // at the principal point
  // Principal points: B's own error shifts its pixel by exactly the limit, A's turns the virtual
  // ray the other way.
  EXPECT_NEAR(Row(rows, "x0:B").plus_px.x(), 0.5, 1e-6);
  EXPECT_NEAR(Row(rows, "y0:B").plus_px.y(), 0.5, 1e-6);
  EXPECT_NEAR(Row(rows, "x0:A").plus_px.x(), -0.5, 0.005);
  EXPECT_NEAR(Row(rows, "y0:A").plus_px.y(), -0.5, 0.005);
  for (const char* axis : {"x0", "y0"}) {
    const int i = axis[0] == 'x' ? 0 : 1;
    EXPECT_LT(Row(rows, std::string(axis) + ":A").plus_px[i] *
                  Row(rows, std::string(axis) + ":B").plus_px[i],
              0)
        << axis << ": opposite signs";
  }
  // Principal distance: at the principal point a scale change moves nothing (B); A's changes the
  // ray of a point 433 px from A's principal point by 433 px x 1 px / 25000 px = 0.017 px.
  EXPECT_LT(Row(rows, "c:B").plus_px.norm(), 1e-4);
  EXPECT_NEAR(Row(rows, "c:A").plus_px.norm(), 433.3 / 25000.0, 0.002);
  // Lever arm: B moved by +1 mm sees the fixed point 1 mm x c / H back.
  const double lever_px = 1e-3 * kC / kHeight / kPixel;
  EXPECT_NEAR(Row(rows, "tx:B").plus_px.x(), -lever_px, 0.01 * lever_px);
  EXPECT_NEAR(Row(rows, "ty:B").plus_px.y(), -lever_px, 0.01 * lever_px);
  // Height: parallax of the 0.15 m baseline (and 0.01 m across it).
  const double plus_h = kC * 0.15 * (1 / kHeight - 1 / (kHeight + 150)) / kPixel;
  const double minus_h = kC * 0.15 * (1 / kHeight - 1 / (kHeight - 150)) / kPixel;
  EXPECT_NEAR(plus_h, 0.347, 0.001);
  EXPECT_NEAR(Row(rows, "height").plus_px.x(), plus_h, 0.01 * plus_h);
  EXPECT_NEAR(Row(rows, "height").minus_px.x(), minus_h, 0.01 * std::abs(minus_h));
  EXPECT_NEAR(Row(rows, "height").plus_px.y(), plus_h / 15.0, 0.01);
}

// Issue 30 item 2: the interior sources are the head model's own parameters (the registry's
// table). The example rig's heads have no distortion, so their opencv form is exact
// (fx = fy = c / p, cx, cy from x0, y0): the sources are cx, cy, fx, fy per head; head B's cx moves
// its pixel by exactly the limit in col (ex = +0.5 px), its cy in row (down, so ey = -0.5 px); the
// mount and the height act as on the brown_fraser_10 heads (the same rays, to 1e-9 px).
TEST(RigErrorAnalysis, SourcesAreTheHeadModelsOwnParameters) {
  const calib::Rig ours = ExampleRig();
  calib::Rig opencv = ours;
  for (calib::RigHead& head : opencv.heads) {
    const calib::ConversionResult r =
        calib::ConvertCamera(head.camera.AsModelCamera(), calib::CameraModelId::kOpenCv);
    ASSERT_TRUE(r.exact);
    head.camera = calib::Camera::OfModel(calib::CameraModelId::kOpenCv).WithModelCamera(r.camera);
  }
  const auto sources = MakeErrorSources(opencv, ExampleLimits());
  std::vector<std::string> names;
  for (size_t i = 0; i < 8; ++i) names.push_back(sources[i].name);
  EXPECT_EQ(
      names,
      (std::vector<std::string>{"cx:A", "cy:A", "fx:A", "fy:A", "cx:B", "cy:B", "fx:B", "fy:B"}));
  EXPECT_EQ(sources[0].unit, "px");
  EXPECT_DOUBLE_EQ(sources[0].limit, 0.5);  // px, as the limits file gives it
  EXPECT_DOUBLE_EQ(sources[2].limit, 1.0);
  const Eigen::Vector2d target = VirtualOfB(ours, {5499.5, 4499.5});
  const auto rows = MaximumErrors(ConversionErrorModel(opencv, kHeight, sources, 1, target));
  EXPECT_NEAR(Row(rows, "cx:B").plus_px.x(), 0.5, 1e-6);
  EXPECT_NEAR(Row(rows, "cx:B").plus_px.y(), 0.0, 1e-6);
  EXPECT_NEAR(Row(rows, "cy:B").plus_px.y(), -0.5, 1e-6);
  const auto theirs = MaximumErrors(
      ConversionErrorModel(ours, kHeight, MakeErrorSources(ours, ExampleLimits()), 1, target));
  for (const char* name : {"omega:B", "phi:B", "kappa:B", "tx:B", "height"})
    EXPECT_LT((Row(rows, name).plus_px - Row(theirs, name).plus_px).norm(), 1e-9) << name;
}

TEST(RigErrorAnalysis, ZeroLimitsGiveExactlyZero) {
  const calib::Rig rig = ExampleRig();
  ErrorLimits zero;
  zero.sigmas = 3;
  const TargetAnalysis analysis =
      AnalyseTarget(rig, kHeight, zero, 1, VirtualOfB(rig, {4999.5, 4999.5}), 1000, 5, true);
  for (const auto& row : analysis.per_source) {
    EXPECT_EQ(row.plus_px, Eigen::Vector2d::Zero()) << row.source;
    EXPECT_EQ(row.minus_px, Eigen::Vector2d::Zero()) << row.source;
  }
  for (const auto& w : analysis.worst_cases) EXPECT_EQ(w.max_radial_px, 0.0) << w.group;
  EXPECT_EQ(analysis.linear.sigma_px, Eigen::Vector2d::Zero());
  EXPECT_EQ(analysis.linear.bound_radial_px, 0.0);
  for (const auto& share : analysis.linear.share_x)
    EXPECT_FALSE(share.has_value()) << "null, never 0";
  ASSERT_TRUE(analysis.monte_carlo.has_value());
  EXPECT_EQ(analysis.monte_carlo->max_radial_px, 0.0);
  EXPECT_EQ(analysis.monte_carlo->sigma_px, Eigen::Vector2d::Zero());
  // A deviation of zero in a model with real limits is also exactly zero.
  const ConversionErrorModel model(
      rig, kHeight, MakeErrorSources(rig, ExampleLimits()), 1, VirtualOfB(rig, {100.0, 9000.0}));
  EXPECT_EQ(*model.Error(Eigen::VectorXd::Zero(13)), Eigen::Vector2d::Zero());
}

// The target B:4999.5,4999.5 with 1e5 samples: Monte-Carlo sigmas within 1 % of the
// linear propagation (sampling error of a sigma at n = 1e5: 0.22 %; the height's curvature adds
// < 0.2 %), the bounds within 3 % (a 99.75 % quantile from 1e5 samples rests on 250 of them).
TEST(RigErrorAnalysis, MonteCarloAgreesWithLinearPropagation) {
  const calib::Rig rig = ExampleRig();
  const ErrorLimits limits = ExampleLimits();
  const TargetAnalysis a =
      AnalyseTarget(rig, kHeight, limits, 1, VirtualOfB(rig, {4999.5, 4999.5}), 100000, 42, false);
  ASSERT_TRUE(a.monte_carlo.has_value());
  const MonteCarloResult& mc = *a.monte_carlo;
  EXPECT_EQ(mc.failed, 0);
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_NEAR(mc.sigma_px[axis] / a.linear.sigma_px[axis], 1.0, 0.01) << axis;
    EXPECT_NEAR(mc.bound_px[axis] / a.linear.bound_px[axis], 1.0, 0.03) << axis;
    EXPECT_NEAR(mc.mean_px[axis], 0.0, 0.02) << axis;
  }
  EXPECT_NEAR(mc.bound_radial_px / a.linear.bound_radial_px, 1.0, 0.03);
  // Hand figure: sigma_x^2 = 2 (0.5/3)^2 + (1.212/3)^2 + (~0.4/3)^2 -> ~0.49 px.
  EXPECT_NEAR(a.linear.sigma_px.x(), 0.49, 0.02);
  EXPECT_NEAR(a.linear.sigma_px.y(), 0.47, 0.02);
  // The relative angles are the main source: phi:B of x, omega:B of y.
  const auto sources = MakeErrorSources(rig, limits);
  int main_x = 0, main_y = 0;
  for (size_t i = 0; i < sources.size(); ++i) {
    if (*a.linear.share_x[i] > *a.linear.share_x[main_x]) main_x = static_cast<int>(i);
    if (*a.linear.share_y[i] > *a.linear.share_y[main_y]) main_y = static_cast<int>(i);
  }
  EXPECT_EQ(sources[main_x].name, "phi:B");
  EXPECT_EQ(sources[main_y].name, "omega:B");
  double sum_x = 0, sum_y = 0;
  for (size_t i = 0; i < sources.size(); ++i) {
    sum_x += *a.linear.share_x[i];
    sum_y += *a.linear.share_y[i];
  }
  EXPECT_NEAR(sum_x, 1.0, 1e-12);
  EXPECT_NEAR(sum_y, 1.0, 1e-12);
  // The paper's "total within 2 px": the 99.75 % radial bound is below 2 px.
  EXPECT_LT(mc.bound_radial_px, 2.0);
  EXPECT_GT(mc.bound_radial_px, 1.0);
  // Same seed, same numbers.
  const TargetAnalysis again =
      AnalyseTarget(rig, kHeight, limits, 1, VirtualOfB(rig, {4999.5, 4999.5}), 100000, 42, false);
  EXPECT_EQ(again.monte_carlo->sigma_px, mc.sigma_px);
  EXPECT_EQ(again.monte_carlo->bound_radial_px, mc.bound_radial_px);
}

TEST(RigErrorAnalysis, GroupedWorstCases) {
  const calib::Rig rig = ExampleRig();
  const TargetAnalysis a = AnalyseTarget(
      rig, kHeight, ExampleLimits(), 1, VirtualOfB(rig, {5499.5, 4499.5}), 0, 1, false);
  EXPECT_FALSE(a.monte_carlo.has_value());
  std::map<std::string, const WorstCase*> by_group;
  for (const auto& w : a.worst_cases) by_group[w.group] = &w;
  for (const char* g : {"interior:A",
                        "interior:B",
                        "angles:B",
                        "lever_arm:B",
                        "relative_orientation:B",
                        "height",
                        "all"})
    ASSERT_TRUE(by_group.count(g)) << g;
  // omega and phi at their limits together: sqrt(2) x 1.212 px.
  const double rotation_px = kC * std::tan(10 * kArcsec) / kPixel;
  EXPECT_NEAR(by_group["angles:B"]->max_radial_px, std::sqrt(2.0) * rotation_px, 0.01);
  // Nearly linear: the worst corner of all sources is the sum of the single-source errors.
  const WorstCase& all = *by_group["all"];
  EXPECT_TRUE(all.exhaustive);
  EXPECT_EQ(all.sources.size(), 13u);
  for (int axis = 0; axis < 2; ++axis) {
    EXPECT_LE(all.max_abs_px[axis], 1.01 * all.sum_abs_px[axis]);  // interactions: +0.1 %
    EXPECT_GT(all.max_abs_px[axis], 0.95 * all.sum_abs_px[axis]);
  }
  // x: 0.5 + 0.5 + 1.212 + 0.446 (height at -150 m) + small terms.
  EXPECT_NEAR(all.sum_abs_px.x(), 0.5 + 0.5 + 1.212 + 0.446, 0.1);
}

TEST(RigErrorAnalysis, GridCoversTheVirtualImage) {
  const calib::Rig rig = ExampleRig();
  const GridAnalysis grid = AnalyseGrid(rig, kHeight, ExampleLimits(), 3, 200, 11);
  EXPECT_EQ(grid.points.size(), 9u);  // B sees all nine cell centres
  EXPECT_TRUE(grid.unseen.empty());
  ASSERT_GE(grid.worst, 0);
  for (const auto& p : grid.points) {
    EXPECT_LE(p.linear.bound_radial_px, grid.points[grid.worst].linear.bound_radial_px);
    // Everywhere about the same: the angles dominate, their effect varies as 1 + r^2 / c^2.
    EXPECT_NEAR(p.linear.bound_radial_px, grid.points[grid.worst].linear.bound_radial_px, 0.1);
    EXPECT_EQ(p.monte_carlo->n, 200);
  }
  const std::string csv = BoundMapCsv(rig, grid);
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 10);
}

}  // namespace
}  // namespace aerocal::stitch
