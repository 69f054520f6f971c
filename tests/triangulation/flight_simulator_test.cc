// The simulated example flight (issue: "the embedded default data") has the geometry it promises:
// a 2x3-CCD camera of 14000 x 12000 px at 9 um with c ~ 170 mm and ~200 px overlaps between
// neighbouring CCDs, 37 exposures in 3 east-west strips 4500 m above the terrain with 60 % forward
// and 30 % side overlap, 300 m relief, 329 surveyed points of which 5 control points sit at the
// block's corners and centre, seen by at least three images; and a nominal camera that differs
// from the truth by the interior correction.
#include "triangulation/simulation/flight_simulator.h"

#include "stitch/quality/resampling_mtf.h"
#include "tests/support/rendered_targets.h"
#include "triangulation/simulation/flight_edge_targets.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <map>
#include <set>

namespace aerocal::triangulation {
namespace {

TEST(FlightSimulator, DefaultFlightHasThePromisedGeometry) {
  const SimulatedFlight f = SimulateFlight(FlightSimulationOptions{});
  const calib::Camera& cam = f.truth;
  EXPECT_EQ(cam.width_px, 14000);
  EXPECT_EQ(cam.height_px, 12000);
  EXPECT_DOUBLE_EQ(cam.pixel_size_mm, 0.009);
  EXPECT_NEAR(cam.interior[0], 170.0, 0.1);
  ASSERT_EQ(cam.subimages.size(), 6u);
  // Neighbouring CCDs overlap by about 200 px (virtual-image footprints of the sub-images).
  struct Box {
    double u0, u1, v0, v1;
  };
  std::vector<Box> boxes;
  for (const auto& s : cam.subimages) {
    const Eigen::Vector2d a = s.VirtualFromSub({0, 0}),
                          b = s.VirtualFromSub({s.width_px - 1.0, s.height_px - 1.0});
    boxes.push_back({std::min(a.x(), b.x()),
                     std::max(a.x(), b.x()),
                     std::min(a.y(), b.y()),
                     std::max(a.y(), b.y())});
  }
  int neighbours = 0;
  for (size_t i = 0; i < boxes.size(); ++i)
    for (size_t j = i + 1; j < boxes.size(); ++j) {
      const double du = std::min(boxes[i].u1, boxes[j].u1) - std::max(boxes[i].u0, boxes[j].u0);
      const double dv = std::min(boxes[i].v1, boxes[j].v1) - std::max(boxes[i].v0, boxes[j].v0);
      if (du <= 0 || dv <= 0) continue;
      const double overlap = std::min(du, dv);  // the strip's width
      if (std::max(du, dv) < 1000) continue;    // a corner where four CCDs meet
      ++neighbours;
      EXPECT_NEAR(overlap, 200.0, 20.0) << cam.subimages[i].id << "-" << cam.subimages[j].id;
    }
  EXPECT_EQ(neighbours, 7);  // 3 rows x 2 columns: 4 vertical + 3 horizontal neighbours

  // 37 exposures in 3 east-west strips, 4500 m above the mean terrain.
  ASSERT_EQ(f.exposures_truth.size(), 37u);
  std::map<long, std::vector<double>> strips;  // rounded Y -> X of its exposures
  double mean_z = 0;
  for (const auto& e : f.exposures_truth) {
    strips[std::lround(e.center_m.y() / 100.0)].push_back(e.center_m.x());
    mean_z += e.center_m.z() / 37.0;
  }
  EXPECT_EQ(strips.size(), 3u);
  const double terrain_mean = f.options.terrain_base_m + 0.5 * f.options.terrain_relief_m;
  EXPECT_NEAR(mean_z - terrain_mean, 4500.0, 50.0);
  // Overlaps from the ground footprint: format / c * height.
  const double scale = (mean_z - terrain_mean) / cam.interior[0];  // m per mm
  const double footprint_x = 14000 * 0.009 * scale, footprint_y = 12000 * 0.009 * scale;
  std::vector<double> xs = strips.begin()->second;
  std::sort(xs.begin(), xs.end());
  const double base = (xs.back() - xs.front()) / (xs.size() - 1);
  EXPECT_NEAR(1.0 - base / footprint_x, 0.60, 0.03);
  const double spacing = (std::prev(strips.end())->first - strips.begin()->first) * 100.0 / 2.0;
  EXPECT_NEAR(1.0 - spacing / footprint_y, 0.30, 0.03);

  // 329 surveyed points, 5 of them control at the corners and the centre, seen by >= 3 images.
  int control = 0, check = 0;
  double z_min = 1e9, z_max = -1e9;
  std::map<std::string, std::set<std::string>> images_of;
  for (const auto& o : f.observations) images_of[o.point].insert(o.image);
  for (const auto& p : f.points_truth) {
    z_min = std::min(z_min, p.xyz_m->z());
    z_max = std::max(z_max, p.xyz_m->z());
    if (p.role == PointRole::kCheck) ++check;
    if (p.role != PointRole::kControl) continue;
    ++control;
    EXPECT_GE(images_of[p.id].size(), 3u) << p.id;
  }
  EXPECT_EQ(control, 5);
  EXPECT_EQ(control + check, 329);
  EXPECT_GT(z_max - z_min, 0.7 * f.options.terrain_relief_m);  // the points sample the relief
  EXPECT_LE(z_max - z_min, f.options.terrain_relief_m + 1.0);

  // The nominal camera differs from the truth by the interior correction; the file has noise-free
  // truth elsewhere.
  for (int k = 0; k < calib::BrownFraser10Model::kNumParams; ++k)
    EXPECT_NEAR(
        f.truth.interior[k] - f.nominal.interior[k], f.options.interior_correction[k], 1e-12);
  EXPECT_GT(std::abs(f.options.interior_correction[0]), 0.0);
  EXPECT_FALSE(f.subimage_observations.empty());
  EXPECT_FALSE(f.stitching.empty());
}

TEST(FlightSimulator, TheSameSeedGivesTheSameFlightAndAnotherSeedAnother) {
  FlightSimulationOptions o;
  const SimulatedFlight a = SimulateFlight(o), b = SimulateFlight(o);
  o.seed = 2;
  const SimulatedFlight c = SimulateFlight(o);
  ASSERT_EQ(a.observations.size(), b.observations.size());
  for (size_t i = 0; i < a.observations.size(); ++i)
    ASSERT_EQ(a.observations[i].pixel, b.observations[i].pixel);
  EXPECT_NE(a.observations.front().pixel, c.observations.front().pixel);
}

// The simulator asks only the exposures near a point whether they see it (a grid of ground discs,
// flight_simulator.cc): every (point, image) pair whose true projection falls inside the format
// (20 px margin) must still be observed, and no other, here with tilts of several degrees and a
// low flight over high relief, where the discs are widest relative to the block.
TEST(FlightSimulator, ObservesEveryPointInEveryImageThatSeesIt) {
  FlightSimulationOptions o;
  o.seed = 4;
  o.exposures = 24;
  o.strips = 3;
  o.attitude_sigma_deg = 6.0;
  o.flying_height_m = 1500.0;
  o.terrain_relief_m = 900.0;
  o.tie_points = 400;
  const SimulatedFlight f = SimulateFlight(o);
  std::set<std::pair<std::string, std::string>> observed;
  for (const auto& obs : f.observations) observed.insert({obs.point, obs.image});
  constexpr double kMarginPx = 20.0;
  size_t expected = 0;
  for (const auto& p : f.points_truth) {
    for (const auto& e : f.exposures_truth) {
      Eigen::Vector2d px;
      const bool inside = f.truth.ProjectToPixel(e.opk_rad, e.center_m, *p.xyz_m, &px) &&
                          px.x() >= kMarginPx && px.y() >= kMarginPx &&
                          px.x() <= f.truth.width_px - 1 - kMarginPx &&
                          px.y() <= f.truth.height_px - 1 - kMarginPx;
      expected += inside;
      EXPECT_EQ(observed.count({p.id, e.image}), inside ? 1u : 0u) << p.id << " in " << e.image;
    }
  }
  EXPECT_EQ(f.observations.size(), expected);
  EXPECT_GT(expected, 2000u);  // 2525 with seed 4
}

// The flight example of issue 36: edge targets laid out on the ground, raw sub-image patches
// rendered through the true camera and a Gaussian PSF (s = 1 raw px, 40 DN noise on a 32000 DN
// step), the virtual patches resampled from them (bilinear, the production resampler). The raw
// MTF50 is the analytic one of the PSF and the pixel, and the virtual MTF50 is the raw one times
// bilinear interpolation's transfer at the exact sub-pixel shifts of the true mapping
// (stitch/quality/resampling_mtf.h), both within their stated U (k = 2).
TEST(FlightEdgeTargets, VirtualImageLosesTheMtfBilinearResamplingPredicts) {
  FlightSimulationOptions o;
  o.ground_points = 40, o.tie_points = 100;  // the targets need only the exposures
  const SimulatedFlight flight = SimulateFlight(o);
  FlightEdgeTargetOptions t;
  const std::vector<EdgeTargetPatch> patches =
      RenderEdgeTargetPatches(flight, LayOutEdgeTargets(flight, t), t);
  std::map<stitch::MtfAxis, std::vector<stitch::SlantedEdgeResult>> raw_by_axis, virtual_by_axis;
  std::map<stitch::MtfAxis, double> predicted_sum;
  for (const EdgeTargetPatch& p : patches) {
    const stitch::SlantedEdgeResult raw = stitch::MeasureSlantedEdge(p.raw, p.raw_region);
    const stitch::SlantedEdgeResult virt =
        stitch::MeasureSlantedEdge(p.virtual_image, p.virtual_region);
    const double analytic = testing::FirstCrossing(
        [&](double f) {
          return testing::RenderedEdgeMtf(
              f, t.psf_sigma_px, std::atan2(p.raw_normal.y(), p.raw_normal.x()));
        },
        0.5);
    const double predicted = stitch::PredictResampledMtf50AtShifts(raw, p.shifts, p.normal);
    const double uniform = stitch::PredictResampledMtf50(
        raw, stitch::Interpolation::kBilinear, std::atan2(p.normal.y(), p.normal.x()));
    // The prediction carries the raw edge's U scaled to it; the two are counted as independent
    // (the virtual patch's noise is the raw one's, interpolated: a conservative sum).
    const double u_prediction = raw.mtf50_expanded_cy_px * predicted / raw.mtf50_cy_px;
    const double expanded = std::hypot(virt.mtf50_expanded_cy_px, u_prediction);
    std::printf(
        "%-5s %-4s %-4s raw %.4f (analytic %.4f, U %.4f) virtual %.4f (U %.4f), loss "
        "%5.2f %%, predicted %5.2f %% (uniform phases %5.2f %%), virtual / predicted "
        "%+.2f %%\n",
        p.target.c_str(),
        p.image.c_str(),
        p.subimage.c_str(),
        raw.mtf50_cy_px,
        analytic,
        raw.mtf50_expanded_cy_px,
        virt.mtf50_cy_px,
        virt.mtf50_expanded_cy_px,
        100.0 * (1.0 - virt.mtf50_cy_px / raw.mtf50_cy_px),
        100.0 * (1.0 - predicted / raw.mtf50_cy_px),
        100.0 * (1.0 - uniform / raw.mtf50_cy_px),
        100.0 * (virt.mtf50_cy_px / predicted - 1.0));
    EXPECT_EQ(raw.axis, p.axis) << p.target << " " << p.image;
    EXPECT_NEAR(raw.mtf50_cy_px, analytic, raw.mtf50_expanded_cy_px) << p.target << " " << p.image;
    EXPECT_NEAR(virt.mtf50_cy_px, predicted, expanded) << p.target << " " << p.image;
    raw_by_axis[p.axis].push_back(raw);
    virtual_by_axis[p.axis].push_back(virt);
    predicted_sum[p.axis] += predicted;
  }
  for (stitch::MtfAxis axis : {stitch::MtfAxis::kX, stitch::MtfAxis::kY}) {
    ASSERT_GE(raw_by_axis[axis].size(), 4u) << stitch::MtfAxisName(axis);
    const stitch::EdgeMtfCombination raw = stitch::CombineEdgeMeasurements(raw_by_axis[axis]);
    const stitch::EdgeMtfCombination virt = stitch::CombineEdgeMeasurements(virtual_by_axis[axis]);
    std::printf("axis %s: %d patches, raw MTF50 %.4f +- %.4f, virtual %.4f +- %.4f (k = 2)\n",
                std::string(stitch::MtfAxisName(axis)).c_str(),
                raw.count,
                raw.mtf50_cy_px,
                raw.mtf50_expanded_cy_px,
                virt.mtf50_cy_px,
                virt.mtf50_expanded_cy_px);
    EXPECT_LT(virt.mtf50_cy_px, raw.mtf50_cy_px) << stitch::MtfAxisName(axis);
    // The combined virtual MTF50 is the mean prediction within its U (type A from the patches'
    // scatter, which holds the spread of the shifts' losses too).
    EXPECT_NEAR(virt.mtf50_cy_px, predicted_sum[axis] / virt.count, virt.mtf50_expanded_cy_px)
        << stitch::MtfAxisName(axis);
  }
}

// Bilinear interpolation's transfer at given shifts (stitch/quality/resampling_mtf.h): at one
// shift d it is |(1 - d) + d e^{2 pi i f}| per axis; over shifts spread uniformly over the pixel it
// is sinc^2, the transfer of the triangle kernel.
TEST(FlightEdgeTargets, BilinearTransferAtShiftsHasItsClosedForms) {
  const Eigen::Vector2d along_x(1.0, 0.0), slanted(std::cos(0.3), std::sin(0.3));
  for (double d : {0.0, 0.25, 0.5, 0.8})
    for (double f : {0.1, 0.3, 0.5}) {
      const double expected = std::abs(std::complex<double>(1.0 - d, 0.0) +
                                       d * std::polar(1.0, 2.0 * testing::kRenderPi * f));
      EXPECT_NEAR(stitch::BilinearTransferAtShifts({{d, 0.7}}, along_x, f), expected, 1e-12);
    }
  EXPECT_NEAR(stitch::BilinearTransferAtShifts({{0.5, 0.5}}, along_x, 0.5), 0.0, 1e-12);
  std::vector<Eigen::Vector2d> spread;  // a 64 x 64 grid of shifts over the pixel (midpoints)
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) spread.push_back({(i + 0.5) / 64, (j + 0.5) / 64});
  for (double f : {0.1, 0.25, 0.4}) {
    const double expected =
        stitch::InterpolationTransfer(stitch::Interpolation::kBilinear, f * slanted.x()) *
        stitch::InterpolationTransfer(stitch::Interpolation::kBilinear, f * slanted.y());
    EXPECT_NEAR(stitch::BilinearTransferAtShifts(spread, slanted, f), expected, 1e-3) << f;
  }
}

}  // namespace
}  // namespace aerocal::triangulation
