// Rendered head images of the four-head rig (`simulate --rig uav4 --render-images`, issue 16) and
// the horizontal stitched image of an exposure (stitch/rig/stitched_image.h, issue 16 item 6):
// - every rendered pixel shows the ground point its TRUE head ray meets (ground calibration,
//   increments and shutter offsets with the velocity), checked against the stitch module's own
//   converter on flat terrain (point sampling), and the default renderer integrates the texture
//   over each pixel's footprint;
// - the stitched image from the raw heads with the increments and offsets of the self-calibration
//   on the simulated ties agrees head against head (overlaps, before blending) at the level of
//   the true parameters, clearly better than with the ground calibration alone;
// - a gain and offset planted in one head are recovered by the radiometric balance;
// - ties matched on the rendered heads (rig_tie_matching.h) against the simulator's truth, and
//   the increments self-calibrated from them within their sigmas.
// The scene: the uav4 line at 0.2 x its formats (same geometry, 582 x 874 px heads), textured
// with a real photograph (../shared/data/odm_boruszyn_kap_frames).
#include "stitch/resample/raster.h"
#include "stitch/rig/feather_weights.h"
#include "stitch/rig/head_window.h"
#include "stitch/rig/rig_conversion.h"
#include "stitch/rig/rig_convert.h"
#include "stitch/rig/rig_tie_matching.h"
#include "stitch/rig/self_calibration.h"
#include "stitch/rig/stitched_image.h"
#include "tests/stitch/rig_stitch_line.h"
#include "tests/support/test_support.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <tuple>
#include <utility>

namespace aerocal::stitch {
namespace {

constexpr double kScale = 0.2;
using triangulation::RigFlightSimulationOptions;
using triangulation::SimulatedRigFlight;

std::string Photo() {
  const std::string data = aerocal::testing::SharedDataDir("odm_boruszyn_kap_frames");
  return data.empty() ? "" : data + "/images/img_4880.jpg";
}

RigFlightSimulationOptions SmallLine(double relief_m) {
  RigFlightSimulationOptions o = RigFlightSimulationOptions::DefaultUav4();
  o.format_scale = kScale;
  o.flight.seed = 3;
  o.flight.exposures = 2;
  o.flight.terrain_relief_m = relief_m;
  const calib::Rig rig = triangulation::ScaleRigFormats(
      triangulation::MakeNominalRig(triangulation::RigPreset::kUav4), kScale);
  for (const auto& s : DesignRig(rig, o.flight.flying_height_m, 200).standard_positions)
    o.stitch_ties.standard_positions.push_back({s.name, s.virtual_px});
  o.stitch_ties.jitter_px *= kScale;
  return o;
}

// The exposure's pose with the given increments and offsets per head (empty: none).
RigExposure Pose(const SimulatedRigFlight& f, int exposure, bool with_truth) {
  const triangulation::Exposure& e = f.exposures_file[exposure];
  RigExposure pose;
  pose.rig_opk_rad = e.opk_rad;
  pose.rig_center_m = e.center_m;
  pose.velocity_mps = e.velocity_mps.value_or(Eigen::Vector3d::Zero());
  if (with_truth)
    for (size_t k = 0; k < f.truth.heads.size(); ++k) {
      pose.increment_rad.push_back(
          f.rig_exposures[exposure * f.truth.heads.size() + k].increment_rad);
      pose.dt_s.push_back(f.rig_exposures[exposure * f.truth.heads.size() + k].dt_s);
    }
  return pose;
}

MemoryRaster AsRaster(const GrayImage& image, double gain = 1.0, double offset = 0.0) {
  MemoryRaster raster({static_cast<int>(image.cols()), static_cast<int>(image.rows()), 1, 8});
  for (int r = 0; r < image.rows(); ++r)
    for (int c = 0; c < image.cols(); ++c) raster.Set(c, r, 0, gain * image(r, c) + offset);
  return raster;
}

StitchedImageReport Stitch(const SimulatedRigFlight& f,
                           const RigExposure& pose,
                           double z_ref_m,
                           std::vector<MemoryRaster>& heads,
                           MemoryRaster* image = nullptr) {
  const RigConverter converter(f.truth, pose, {Eigen::Vector3d::UnitZ(), z_ref_m});
  std::vector<RasterSource*> sources;
  for (auto& h : heads) sources.push_back(&h);
  const calib::Camera& v = f.truth.virtual_camera.camera;
  MemoryRaster out({v.width_px, v.height_px, 1, 8}), mask({v.width_px, v.height_px, 1, 8});
  const StitchedImageReport report = MakeStitchedImage(converter, sources, {}, &out, &mask);
  long valid = 0;
  for (int r = 0; r < v.height_px; ++r)
    for (int c = 0; c < v.width_px; ++c) valid += mask.At(c, r) == 255 ? 1 : 0;
  EXPECT_EQ(valid, report.valid_pixels);
  if (image) *image = std::move(out);
  return report;
}

TEST(RigHeadImages, EveryPixelShowsTheGroundItsTrueRayMeets) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));  // flat: Z = base
  triangulation::RigImageOptions options;
  options.texture_path = Photo();
  options.grey_noise_dn = 0.0;
  options.point_sampling = true;  // the geometry: one sample at each pixel centre
  const triangulation::TexturedGround ground = triangulation::MakeRigGroundTexture(f, options);
  const double base_m = f.options.flight.terrain_base_m;
  const RectificationPlane terrain{Eigen::Vector3d::UnitZ(), base_m};
  // The truth pose (exposures_truth) through the stitch module's converter, and the ground
  // calibration alone: the rendering must follow the first.
  RigExposure truth = Pose(f, 1, true), ground_only = Pose(f, 1, false);
  truth.rig_opk_rad = ground_only.rig_opk_rad = f.exposures_truth[1].opk_rad;
  truth.rig_center_m = ground_only.rig_center_m = f.exposures_truth[1].center_m;
  const RigConverter with_truth(f.truth, truth, terrain), without(f.truth, ground_only, terrain);
  for (int k = 0; k < 4; ++k) {
    const GrayImage image = triangulation::RenderRigHeadImage(f, ground, options, 1, k);
    ASSERT_EQ(image.cols(), f.truth.heads[k].camera.width_px);
    ASSERT_EQ(image.rows(), f.truth.heads[k].camera.height_px);
    double worst = 0.0, worst_ground_only = 0.0;
    for (int r = 0; r < image.rows(); r += 7)
      for (int c = 0; c < image.cols(); c += 7) {
        const auto g = with_truth.PlanePointOfHeadPixel(k, Eigen::Vector2d(c, r));
        const auto g0 = without.PlanePointOfHeadPixel(k, Eigen::Vector2d(c, r));
        ASSERT_TRUE(g && g0);
        worst = std::max(worst, double(std::abs(image(r, c) - ground.At(g->x(), g->y()))));
        worst_ground_only = std::max(worst_ground_only,
                                     double(std::abs(image(r, c) - ground.At(g0->x(), g0->y()))));
      }
    // float grey values; the two ray intersections agree to ~1e-9 m
    EXPECT_LT(worst, 1e-3) << f.truth.heads[k].id;
    if (k != f.truth.ReferenceIndex()) {  // the increments move the head's ground by ~0.1 m
      EXPECT_GT(worst_ground_only, 1.0) << f.truth.heads[k].id;
    }
  }
}

// The default renderer integrates the texture over each pixel's footprint (a box over the pixel
// area): against a fine reference (12 x 12 exact ray intersections per pixel through the stitch
// module's converter, the texture's mean over them) on pixels spread over every head, the
// rendered value agrees far better than the pixel centre's sample (point sampling) does.
TEST(RigHeadImages, EveryPixelIntegratesTheGroundOverItsFootprint) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  triangulation::RigImageOptions options;
  options.texture_path = Photo();
  options.grey_noise_dn = 0.0;
  const triangulation::TexturedGround ground = triangulation::MakeRigGroundTexture(f, options);
  triangulation::RigImageOptions point = options;
  point.point_sampling = true;
  RigExposure truth = Pose(f, 1, true);
  truth.rig_opk_rad = f.exposures_truth[1].opk_rad;
  truth.rig_center_m = f.exposures_truth[1].center_m;
  const RigConverter converter(
      f.truth, truth, {Eigen::Vector3d::UnitZ(), f.options.flight.terrain_base_m});
  constexpr int kReference = 12;
  for (int k = 0; k < 4; ++k) {
    const GrayImage area = triangulation::RenderRigHeadImage(f, ground, options, 1, k);
    const GrayImage centre = triangulation::RenderRigHeadImage(f, ground, point, 1, k);
    double area2 = 0, centre2 = 0;
    int n = 0;
    for (int r = 3; r < area.rows(); r += 53)
      for (int c = 5; c < area.cols(); c += 57) {
        double sum = 0;
        for (int j = 0; j < kReference; ++j)
          for (int i = 0; i < kReference; ++i) {
            const auto g =
                converter.PlanePointOfHeadPixel(k,
                                                Eigen::Vector2d(c - 0.5 + (i + 0.5) / kReference,
                                                                r - 0.5 + (j + 0.5) / kReference));
            ASSERT_TRUE(g);
            sum += ground.At(g->x(), g->y());
          }
        const double reference = sum / (kReference * kReference);
        area2 += std::pow(area(r, c) - reference, 2);
        centre2 += std::pow(centre(r, c) - reference, 2);
        ++n;
      }
    const double area_rms = std::sqrt(area2 / n), centre_rms = std::sqrt(centre2 / n);
    std::printf(
        "head %s: %d pixels, against the 12 x 12 footprint mean: area integration RMS %.3f DN, "
        "point sampling RMS %.3f DN\n",
        f.truth.heads[k].id.c_str(),
        n,
        area_rms,
        centre_rms);
    EXPECT_GT(n, 120);
    EXPECT_LT(area_rms, 0.25 * centre_rms) << f.truth.heads[k].id;
  }
}

TEST(RigStitchedImage, SeamlessWithTheRefinedIncrementsAndBalancesAPlantedGain) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(30.0));
  // The self-calibration on the simulated ties (observations.csv), line mode.
  testing::RigStitchInputs in = testing::InputsFromFlight(f);
  in.positions = DesignRig(f.nominal, f.options.flight.flying_height_m, 200).standard_positions;
  RigStitchOptions options;
  options.standard_radius_px *= kScale;
  const RigStitchResult result = SelfCalibrateRigStitching(
      f.truth, in.exposures, in.ties, in.observations, in.positions, options);
  ASSERT_TRUE(result.failures.empty()) << result.failures.front();

  triangulation::RigImageOptions render;
  render.texture_path = Photo();
  render.grey_noise_dn = 1.0;
  const triangulation::TexturedGround ground = triangulation::MakeRigGroundTexture(f, render);
  std::vector<GrayImage> raw;
  std::vector<MemoryRaster> heads;
  for (int k = 0; k < 4; ++k) {
    raw.push_back(triangulation::RenderRigHeadImage(f, ground, render, 0, k));
    heads.push_back(AsRaster(raw.back()));
  }
  const double z_ref = in.exposures[0].z_ref_m;
  RigExposure refined = Pose(f, 0, false);
  refined.increment_rad.assign(4, Eigen::Vector3d::Zero());
  refined.dt_s.assign(4, 0.0);
  for (const auto& h : result.exposures[0].heads) {
    refined.increment_rad[f.truth.HeadIndex(h.head)] = h.increment_rad;
    refined.dt_s[f.truth.HeadIndex(h.head)] = h.dt_fitted_s;
  }
  const StitchedImageReport with_truth = Stitch(f, Pose(f, 0, true), z_ref, heads);
  const StitchedImageReport with_refined = Stitch(f, refined, z_ref, heads);
  const StitchedImageReport ground_only = Stitch(f, Pose(f, 0, false), z_ref, heads);
  ASSERT_EQ(with_refined.zones.size(), 5u);  // AB, AC, AD, BC, CD
  for (const auto& z : with_refined.zones) EXPECT_GT(z.pixels, 1000) << z.zone;
  const double floor = with_truth.overall.rms_dn, after = with_refined.overall.rms_dn,
               before = ground_only.overall.rms_dn;
  std::printf(
      "overlap disagreement (RMS DN, head against head before blending): true parameters "
      "%.3f, refined %.3f, ground calibration alone %.3f\n",
      floor,
      after,
      before);
  for (size_t z = 0; z < with_refined.zones.size(); ++z)
    std::printf("  %s: %ld px, truth %.3f, refined %.3f, ground %.3f DN\n",
                with_refined.zones[z].zone.c_str(),
                with_refined.zones[z].pixels,
                with_truth.zones[z].rms_dn,
                with_refined.zones[z].rms_dn,
                ground_only.zones[z].rms_dn);
  // The floor: 1 DN noise of two interpolated heads, 8-bit rounding and the interpolation of a
  // texture finer than the oblique heads' pixels. A misregistration adds its part in quadrature:
  // sqrt(d^2 - floor^2). The refined geometry's part at most a quarter of the ground
  // calibration's (measured 0.92 of 4.65 DN; 0.97 of 4.90 DN when the renderer took one sample per
  // pixel and the floor was 1.94 DN: the part is the geometry's, the floor the renderer's).
  const double refined_part = std::sqrt(std::max(0.0, after * after - floor * floor));
  const double ground_part = std::sqrt(std::max(0.0, before * before - floor * floor));
  std::printf("misregistration's part in quadrature: refined %.3f DN, ground calibration %.3f DN\n",
              refined_part,
              ground_part);
  EXPECT_LT(refined_part, 0.25 * ground_part);
  EXPECT_GT(before, 1.5 * after);
  for (const auto& h : with_refined.heads) {  // equal radiometry: gain 1, offset 0
    EXPECT_NEAR(h.gain, 1.0, 0.01) << h.head;
    EXPECT_NEAR(h.offset_dn, 0.0, 1.0) << h.head;
  }

  // A gain and offset planted in head B (I_B' = 0.8 I_B + 12): the balance brings B back,
  // g_B = 1 / 0.8, o_B = -12 / 0.8, and the disagreement back to the unplanted one within 2 %.
  heads[1] = AsRaster(raw[1], 0.8, 12.0);
  const StitchedImageReport planted = Stitch(f, refined, z_ref, heads);
  EXPECT_NEAR(planted.heads[1].gain, 1.25, 0.01);
  EXPECT_NEAR(planted.heads[1].offset_dn, -15.0, 1.0);
  EXPECT_NEAR(planted.overall.rms_dn, after, 0.02 * after);
}

// Errors of matched ties against the truth (issue 16 item 2 diagnosis): per matched observation
// of a non-first head, the position LSM found minus the true position of the ground point the
// first head's pixel sees (flat terrain: the first head's raw pixel through its TRUE pose onto
// the terrain, projected into the other head through its true pose), both taken to the virtual
// image through the ground calibration (virtual px, the LSM's frame), and its z-score against
// the tie's LSM sigma (larger axis, per coordinate).
struct MatchedTieErrors {
  RigTieMatches matches;
  std::vector<Eigen::Vector2d> error_px;  // per observation; NaN for the first head's rows
  double rms_error_px = 0, rms_lsm_sigma_px = 0, rms_z = 0;
};

MatchedTieErrors MatchAndMeasure(const SimulatedRigFlight& f,
                                 const testing::RigStitchInputs& in,
                                 const triangulation::RigImageOptions& render,
                                 const RigTieMatchOptions& match_options = {}) {
  MatchedTieErrors out;
  const triangulation::TexturedGround ground = triangulation::MakeRigGroundTexture(f, render);
  for (int i = 0; i < static_cast<int>(in.exposures.size()); ++i) {
    std::vector<GrayImage> heads;
    for (int k = 0; k < 4; ++k)
      heads.push_back(triangulation::RenderRigHeadImage(f, ground, render, i, k));
    MatchRigExposureTies(f.truth, in.exposures[i], i, heads, match_options, &out.matches);
  }
  const RectificationPlane terrain{Eigen::Vector3d::UnitZ(), f.options.flight.terrain_base_m};
  std::vector<RigConverter> truth, ground_calibration;
  for (int i = 0; i < static_cast<int>(in.exposures.size()); ++i) {
    RigExposure t = Pose(f, i, true);
    t.rig_opk_rad = f.exposures_truth[i].opk_rad;
    t.rig_center_m = f.exposures_truth[i].center_m;
    truth.emplace_back(f.truth, t, terrain);
    ground_calibration.emplace_back(
        f.truth,
        Pose(f, i, false),
        RectificationPlane{Eigen::Vector3d::UnitZ(), in.exposures[i].z_ref_m});
  }
  const auto& obs = out.matches.observations;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  out.error_px.assign(obs.size(), Eigen::Vector2d(nan, nan));
  double e2 = 0, s2 = 0, z2 = 0;
  int n = 0;
  for (size_t o = 0; o < obs.size(); ++o) {
    if (o == 0 || obs[o - 1].tie != obs[o].tie) continue;  // the tie's first head
    size_t first = o;
    while (first > 0 && obs[first - 1].tie == obs[o].tie) --first;
    const RigConverter& t = truth[obs[o].exposure];
    const RigConverter& g = ground_calibration[obs[o].exposure];
    const auto point = t.PlanePointOfHeadPixel(obs[first].head, obs[first].pixel);
    const auto true_pixel = point ? t.HeadPixelOfPoint(obs[o].head, *point) : std::nullopt;
    const auto v_true = true_pixel ? g.VirtualFromHead(obs[o].head, *true_pixel) : std::nullopt;
    const auto v_matched = g.VirtualFromHead(obs[o].head, obs[o].pixel);
    if (!v_true || !v_matched) continue;
    out.error_px[o] = *v_matched - *v_true;
    const double sigma = out.matches.lsm_sigma_px[obs[o].tie];
    e2 += out.error_px[o].squaredNorm() / 2;
    s2 += sigma * sigma;
    z2 += out.error_px[o].squaredNorm() / 2 / (sigma * sigma);
    ++n;
  }
  out.rms_error_px = std::sqrt(e2 / n);
  out.rms_lsm_sigma_px = std::sqrt(s2 / n);
  out.rms_z = std::sqrt(z2 / n);
  return out;
}

// Per zone and head (both exposures): count, mean error (the systematic part) and spread per
// coordinate, the RMS LSM sigma; and the whole set.
void PrintTieErrors(const char* title, const MatchedTieErrors& m, const calib::Rig& rig) {
  struct Sums {
    int n = 0;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero(), sum2 = Eigen::Vector2d::Zero();
    double s2 = 0;
  };
  std::map<std::string, Sums> per;
  const auto& obs = m.matches.observations;
  for (size_t o = 0; o < obs.size(); ++o) {
    if (!std::isfinite(m.error_px[o].x())) continue;
    const std::string& id = m.matches.ties[obs[o].tie].id;
    const std::string zone = id.substr(id.find('/') + 1, id.find('-') - id.find('/') - 1);
    Sums& s = per[zone + " " + rig.heads[obs[o].head].id];
    ++s.n;
    s.sum += m.error_px[o];
    s.sum2 += m.error_px[o].cwiseAbs2();
    s.s2 += std::pow(m.matches.lsm_sigma_px[obs[o].tie], 2);
  }
  std::printf(
      "%s: %zu ties; matched minus true position (virtual px): RMS per coordinate %.4f, "
      "RMS LSM sigma %.4f, RMS z %.2f\n",
      title,
      m.matches.ties.size(),
      m.rms_error_px,
      m.rms_lsm_sigma_px,
      m.rms_z);
  for (const auto& [key, s] : per) {
    const Eigen::Vector2d mean = s.sum / s.n;
    const Eigen::Vector2d spread = (s.sum2 / s.n - mean.cwiseAbs2()).cwiseMax(0).cwiseSqrt();
    std::printf("  %-6s n %3d  mean (%+.4f, %+.4f)  spread (%.4f, %.4f)  LSM sigma %.4f px\n",
                key.c_str(),
                s.n,
                mean.x(),
                mean.y(),
                spread.x(),
                spread.y(),
                std::sqrt(s.s2 / s.n));
  }
}

// The increments of the line-mode self-calibration on matched ties against the truth: z-scores
// (estimate - truth) / sigma of the 18 angles of the two exposures.
struct IncrementCheck {
  RigStitchResult result;
  std::vector<double> z;
  double rms_error_rad = 0, rms_truth_rad = 0, sum_z2 = 0, max_abs_z = 0;
  int beyond_3_sigma = 0;
};

IncrementCheck SelfCalibrateOnMatches(const SimulatedRigFlight& f,
                                      const testing::RigStitchInputs& in,
                                      const RigTieMatches& matches) {
  IncrementCheck out;
  RigStitchOptions options;
  options.standard_radius_px *= kScale;
  out.result = SelfCalibrateRigStitching(
      f.truth, in.exposures, matches.ties, matches.observations, in.positions, options);
  double error2 = 0, truth2 = 0;
  for (int i = 0; i < static_cast<int>(in.exposures.size()); ++i)
    for (const auto& h : out.result.exposures[i].heads) {
      if (h.reference) continue;
      const int k = f.truth.HeadIndex(h.head);
      const Eigen::Vector3d truth = f.rig_exposures[i * f.truth.heads.size() + k].increment_rad;
      for (int a = 0; a < 3; ++a) {
        const double z = (h.increment_rad[a] - truth[a]) / h.increment_sigma_rad[a];
        out.z.push_back(z);
        out.sum_z2 += z * z;
        out.max_abs_z = std::max(out.max_abs_z, std::abs(z));
        out.beyond_3_sigma += std::abs(z) > 3.0;
        error2 += std::pow(h.increment_rad[a] - truth[a], 2);
        truth2 += truth[a] * truth[a];
      }
    }
  out.rms_error_rad = std::sqrt(error2 / out.z.size());
  out.rms_truth_rad = std::sqrt(truth2 / out.z.size());
  return out;
}

// Exposure 0 of `f` converted at the ground calibration (no increments, no time offsets) over
// its level plane.
RigConverter FirstExposureAtGroundCalibration(const SimulatedRigFlight& f) {
  const testing::RigStitchInputs in = testing::InputsFromFlight(f);
  RigExposure pose = in.exposures[0].pose;
  pose.increment_rad.clear();
  pose.dt_s.clear();
  return RigConverter(
      f.truth, pose, RectificationPlane{Eigen::Vector3d::UnitZ(), in.exposures[0].z_ref_m});
}

// The windows of the tie matching (issue 35) are the whole-format projection's pixels: on the
// uav4 heads at 0.2 x their formats (tilted, with their correction grids), a random 8-bit texture
// per head, every pixel of a 300 x 300 window around each head's centre has the coverage of
// ProjectHeadOntoVirtual and, where covered, its value to 1/256 DN (the whole-format path
// resamples 16-bit values x 256) plus float rounding.
TEST(RigHeadWindow, WindowsEqualTheWholeFormatProjection) {
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  const RigConverter converter = FirstExposureAtGroundCalibration(f);
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  std::mt19937 rng(5);
  for (int k = 0; k < static_cast<int>(f.truth.heads.size()); ++k) {
    const calib::Camera& head = f.truth.heads[k].camera;
    GrayImage image(head.height_px, head.width_px);
    MemoryRaster source({head.width_px, head.height_px, 1, 16});
    for (int r = 0; r < head.height_px; ++r)
      for (int c = 0; c < head.width_px; ++c) {
        image(r, c) = static_cast<float>(rng() % 256);
        source.Set(c, r, 0, image(r, c) * 256.0);
      }
    const HeadProjection whole = ProjectHeadOntoVirtual(converter, k, grids.grids[k], &source);
    const HeadWindowSampler sampler(converter, k, image, grids.grids[k]);
    const auto centre = converter.VirtualFromHead(
        k, Eigen::Vector2d(0.5 * (head.width_px - 1), 0.5 * (head.height_px - 1)));
    ASSERT_TRUE(centre);
    const int x0 = static_cast<int>(centre->x()) - 150, y0 = static_cast<int>(centre->y()) - 150;
    const VirtualWindow window = sampler.Project(x0, y0, 300, 300);
    const int width = f.truth.virtual_camera.camera.width_px;
    int covered = 0, differ = 0;
    double worst = 0.0;
    for (int r = 0; r < 300; ++r)
      for (int c = 0; c < 300; ++c) {
        const int x = x0 + c, y = y0 + r;
        if (x < 0 || y < 0 || x >= width || y >= f.truth.virtual_camera.camera.height_px) continue;
        const bool in_whole = whole.covered[static_cast<size_t>(y) * width + x] != 0;
        differ += in_whole != (window.weight(r, c) > 0);
        if (!in_whole || !(window.weight(r, c) > 0)) continue;
        ++covered;
        worst = std::max(worst, std::abs(window.values(r, c) - whole.values.At(x, y) / 256.0));
      }
    EXPECT_GT(covered, 20000) << f.truth.heads[k].id;
    EXPECT_EQ(differ, 0) << f.truth.heads[k].id;
    EXPECT_LT(worst, 1.0 / 256 + 1e-3) << f.truth.heads[k].id;  // 16-bit rounding + float
  }
}

// The stitched image projects each head over its footprint's box only (ProjectHeadFootprint):
// on the uav4 heads at 0.2 x (tilted, with correction grids) and a random 16-bit texture, the box
// is well under half the virtual format, holds every covered pixel of the whole-format
// projection, and each of its pixels (value and coverage) is the whole format's to the last bit.
TEST(RigStitchedImage, FootprintBoxHoldsTheWholeFormatsPixelsBitForBit) {
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  const RigConverter converter = FirstExposureAtGroundCalibration(f);
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  const int width = f.truth.virtual_camera.camera.width_px;
  const int height = f.truth.virtual_camera.camera.height_px;
  std::mt19937 rng(11);
  for (int k = 0; k < static_cast<int>(f.truth.heads.size()); ++k) {
    const calib::Camera& head = f.truth.heads[k].camera;
    MemoryRaster source({head.width_px, head.height_px, 1, 16});
    for (int r = 0; r < head.height_px; ++r)
      for (int c = 0; c < head.width_px; ++c) source.Set(c, r, 0, rng() % 65536);
    const HeadProjection whole = ProjectHeadOntoVirtual(converter, k, grids.grids[k], &source);
    const HeadProjection box = ProjectHeadFootprint(converter, k, grids.grids[k], &source);
    const VirtualRegion& b = box.region;
    EXPECT_LT(2.0 * b.width * b.height, 1.0 * width * height) << f.truth.heads[k].id;
    long covered_whole = 0, covered_box = 0, differ = 0;
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const bool covered = whole.covered[static_cast<size_t>(y) * width + x] != 0;
        covered_whole += covered;
        if (x < b.x0 || y < b.y0 || x >= b.x0 + b.width || y >= b.y0 + b.height) continue;
        const size_t at = static_cast<size_t>(y - b.y0) * b.width + (x - b.x0);
        covered_box += box.covered[at] != 0;
        differ += (box.covered[at] != 0) != covered ||
                  box.values.At(x - b.x0, y - b.y0) != whole.values.At(x, y);
      }
    EXPECT_GT(covered_whole, 100000) << f.truth.heads[k].id;
    EXPECT_EQ(covered_box, covered_whole) << f.truth.heads[k].id;
    EXPECT_EQ(differ, 0) << f.truth.heads[k].id;
  }
}

// The banded feather weights (feather_weights.h) against OpenCV's distance transform over the
// whole raster, bit for bit: a tilted quadrilateral touching two raster edges, with holes of 1 to
// 40 px and isolated uncovered pixels, for ramps from 1 to 255 px (the band wider than the
// raster), and each head's real footprint coverage of the simulated line.
TEST(RigStitchedImage, BandedFeatherWeightsEqualTheWholeDistanceTransform) {
  const int width = 701, height = 523;
  std::vector<std::uint8_t> covered(static_cast<size_t>(width) * height, 0);
  const auto side = [](double ax, double ay, double bx, double by, double x, double y) {
    return (bx - ax) * (y - ay) - (by - ay) * (x - ax);
  };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      covered[static_cast<size_t>(y) * width + x] =
          side(-30, 60, 640, -20, x, y) >= 0 && side(640, -20, 760, 480, x, y) >= 0 &&
                  side(760, 480, 90, 560, x, y) >= 0 && side(90, 560, -30, 60, x, y) >= 0
              ? 255
              : 0;
  std::mt19937 rng(5);
  for (int hole = 0; hole < 30; ++hole) {
    const int cx = rng() % width, cy = rng() % height, r = hole < 20 ? 0 : 1 + rng() % 20;
    for (int y = std::max(0, cy - r); y <= std::min(height - 1, cy + r); ++y)
      for (int x = std::max(0, cx - r); x <= std::min(width - 1, cx + r); ++x)
        covered[static_cast<size_t>(y) * width + x] = 0;
  }
  for (const int feather : {1, 2, 7, 64, 200, 255})
    EXPECT_EQ(FeatherWeights(covered.data(), width, height, feather),
              FeatherWeightsWhole(covered.data(), width, height, feather))
        << "feather " << feather;
  const std::vector<std::uint8_t> all(static_cast<size_t>(width) * height, 255);
  EXPECT_EQ(FeatherWeights(all.data(), width, height, 64),
            FeatherWeightsWhole(all.data(), width, height, 64));

  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  const RigConverter converter = FirstExposureAtGroundCalibration(f);
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  for (int k = 0; k < static_cast<int>(f.truth.heads.size()); ++k) {
    const calib::Camera& head = f.truth.heads[k].camera;
    MemoryRaster source({head.width_px, head.height_px, 1, 16});
    const HeadProjection p = ProjectHeadFootprint(converter, k, grids.grids[k], &source);
    EXPECT_EQ(FeatherWeights(p.covered.data(), p.region.width, p.region.height, 64),
              FeatherWeightsWhole(p.covered.data(), p.region.width, p.region.height, 64))
        << f.truth.heads[k].id;
  }
}

// Both paths of the tie matching on one exposure's rendered heads: about the same ties, and
// where both chose the same first-head pixel, nearly the same matched head pixels. Not equal:
// the former path resamples 16-bit values, x 256 only when no head pixel exceeds 255 DN; the
// noisy heads reach 257 DN, so it rounds to whole DN, which moves LSM by 0.022 px RMS (the
// windows interpolate the float pixels). Bound: 0.03 px RMS, below a third of the matching's
// error against the truth (0.08 px, MatchedTiesGiveIncrementsWithinTheirSigmas).
TEST(RigTieMatching, WindowsMatchAsTheWholeProjections) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  const testing::RigStitchInputs in = testing::InputsFromFlight(f);
  triangulation::RigImageOptions render;
  render.texture_path = Photo();
  render.grey_noise_dn = 1.0;
  render.texture_gsd_m = 1.0;
  const triangulation::TexturedGround ground = triangulation::MakeRigGroundTexture(f, render);
  std::vector<GrayImage> heads;
  for (int k = 0; k < 4; ++k)
    heads.push_back(triangulation::RenderRigHeadImage(f, ground, render, 0, k));
  RigTieMatches windows, whole;
  RigTieMatchOptions former;
  former.whole_projections = true;
  MatchRigExposureTies(f.truth, in.exposures[0], 0, heads, {}, &windows);
  MatchRigExposureTies(f.truth, in.exposures[0], 0, heads, former, &whole);
  float top = 0.0f;
  for (const GrayImage& h : heads) top = std::max(top, h.maxCoeff());
  std::printf("ties: windows %zu, whole projections %zu; brightest head pixel %.1f DN\n",
              windows.ties.size(),
              whole.ties.size(),
              top);
  EXPECT_NEAR(static_cast<double>(windows.ties.size()), whole.ties.size(), 0.1 * whole.ties.size());
  // observations keyed by (first head pixel, head)
  const auto key_of = [](const RigTieMatches& m, size_t o) {
    size_t first = o;
    while (first > 0 && m.observations[first - 1].tie == m.observations[o].tie) --first;
    const Eigen::Vector2d& p = m.observations[first].pixel;
    return std::make_tuple(
        std::lround(p.x() * 1e3), std::lround(p.y() * 1e3), m.observations[o].head);
  };
  std::map<std::tuple<long, long, int>, Eigen::Vector2d> former_pixel;
  for (size_t o = 0; o < whole.observations.size(); ++o)
    former_pixel[key_of(whole, o)] = whole.observations[o].pixel;
  int same = 0, beyond = 0;
  double worst = 0.0, sum2 = 0.0;
  for (size_t o = 0; o < windows.observations.size(); ++o) {
    const auto it = former_pixel.find(key_of(windows, o));
    if (it == former_pixel.end()) continue;
    ++same;
    const double d = (windows.observations[o].pixel - it->second).norm();
    worst = std::max(worst, d);
    sum2 += d * d;
    beyond += d > 0.01;
  }
  const double rms = std::sqrt(sum2 / std::max(1, same));
  std::printf(
      "%d observations at the same points: difference RMS %.5f px, largest %.5f px, %d beyond "
      "0.01 px\n",
      same,
      rms,
      worst,
      beyond);
  EXPECT_GT(same, static_cast<int>(windows.observations.size()) / 2);
  EXPECT_LT(rms, 0.03);

  // The tie cell: 40 px at this small format (the default target of 2000 cells is far above the
  // zones' area / 40^2); a target of a quarter of the ties grows it to the side of that many
  // square cells over the zones' pixels, rounded up to 8 px, in both paths, and the ties thin
  // by about the ratio of the cells' areas (cells at the zones' borders hold a tie too: at most
  // twice the target).
  double zone_pixels = 0;
  for (const RigZoneMatchReport& z : windows.zones) {
    EXPECT_EQ(z.cell_px, 40.0) << z.zone;
    zone_pixels += z.pixels;
  }
  RigTieMatchOptions thin;
  thin.target_ties = std::floor(windows.ties.size() / 4.0);
  const double cell = 8.0 * std::ceil(std::sqrt(zone_pixels / thin.target_ties) / 8.0);
  EXPECT_EQ(TieCellPx(thin, zone_pixels), cell);
  EXPECT_GT(cell, 40.0);
  RigTieMatches thinned, thinned_whole;
  MatchRigExposureTies(f.truth, in.exposures[0], 0, heads, thin, &thinned);
  thin.whole_projections = true;
  MatchRigExposureTies(f.truth, in.exposures[0], 0, heads, thin, &thinned_whole);
  for (const RigZoneMatchReport& z : thinned.zones) EXPECT_EQ(z.cell_px, cell) << z.zone;
  for (const RigZoneMatchReport& z : thinned_whole.zones) EXPECT_EQ(z.cell_px, cell) << z.zone;
  std::printf("target %.0f ties: cell %.0f px, %zu ties (whole projections %zu)\n",
              thin.target_ties,
              cell,
              thinned.ties.size(),
              thinned_whole.ties.size());
  EXPECT_GT(thinned.ties.size(), thin.target_ties / 2);
  EXPECT_LT(thinned.ties.size(), 2 * thin.target_ties);
}

// The diagnosis behind the prefilter and the area-integrating renderer (stitch/README.md "Ties
// matched on the head images"): point sampling against area integration, texels of 1 m and
// 0.25 m, no prefilter against 1.0 and 1.5 px. About 3 minutes: run it by hand,
// `test_stitch_rig_stitched_image --gtest_also_run_disabled_tests --gtest_filter=*Diagnosis*`.
TEST(RigTieMatching, DISABLED_DiagnosisMatchedTieErrors) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  testing::RigStitchInputs in = testing::InputsFromFlight(f);
  in.positions = DesignRig(f.nominal, f.options.flight.flying_height_m, 200).standard_positions;
  for (double gsd : {1.0, 0.25})
    for (const auto& [point, prefilter] :
         {std::pair<bool, double>{true, 0.0}, {false, 0.0}, {false, 1.0}, {false, 1.5}}) {
      triangulation::RigImageOptions render;
      render.texture_path = Photo();
      render.grey_noise_dn = 1.0;
      render.texture_gsd_m = gsd;
      render.point_sampling = point;
      RigTieMatchOptions match;
      match.prefilter_sigma_px = prefilter;
      char title[160];
      std::snprintf(title,
                    sizeof title,
                    "%s, texels %.2f m, 1 DN noise, prefilter %.1f px",
                    point ? "point sampling" : "area integration",
                    gsd,
                    prefilter);
      const MatchedTieErrors m = MatchAndMeasure(f, in, render, match);
      PrintTieErrors(title, m, f.truth);
      const IncrementCheck c = SelfCalibrateOnMatches(f, in, m.matches);
      std::printf(
          "  -> sigma0 %.3f, %zu rejected, fit RMS %.4f -> %.4f px; increments RMS error %.3g rad, "
          "sum z^2 %.1f (18 angles), max |z| %.2f, %d beyond 3 sigma\n",
          c.result.sigma0,
          c.result.rejected.size(),
          c.result.before.fit.per_coordinate,
          c.result.after.fit.per_coordinate,
          c.rms_error_rad,
          c.sum_z2,
          c.max_abs_z,
          c.beyond_3_sigma);
    }
}

// Tie matching on the rendered head images (issue 16 item 2; stitch/rig/rig_tie_matching.h): the
// heads projected onto the level plane with the ground calibration and the POS, Foerstner + LSM per
// zone (default options: LSM on the projections low-passed by 1.5 px), measured back in raw head
// pixels; the self-calibration on those ties alone (line mode, flat terrain, area-integrating
// renderer, 1 m texels, 1 DN noise). Asserted: ties in every zone and none between B and D; no
// systematic error per zone (matched minus true position, against the truth of the simulator);
// a valid run; the increments within 3 sigma of the truth as chi-square predicts for 18 angles
// (sum of z^2 below its 0.999 quantile, 42.3; at most one beyond 3 sigma: two or more have
// probability 0.001); the fitted stitching RMS at the matching noise (the LSM sigmas scaled by
// the sigma0 reached: at most 1.5 x that).
TEST(RigTieMatching, MatchedTiesGiveIncrementsWithinTheirSigmas) {
  if (Photo().empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const SimulatedRigFlight f = triangulation::SimulateRigFlight(SmallLine(0.0));
  testing::RigStitchInputs in = testing::InputsFromFlight(f);
  in.positions = DesignRig(f.nominal, f.options.flight.flying_height_m, 200).standard_positions;
  triangulation::RigImageOptions render;
  render.texture_path = Photo();
  render.grey_noise_dn = 1.0;
  render.texture_gsd_m = 1.0;
  const MatchedTieErrors m = MatchAndMeasure(f, in, render);
  std::map<std::string, int> ties_per_zone;
  for (const auto& z : m.matches.zones) {
    std::printf("  %s %s: %ld px, %d cells, LSM %d tried %d failed, %d ties\n",
                z.image.c_str(),
                z.zone.c_str(),
                z.pixels,
                z.cells,
                z.lsm_tried,
                z.lsm_failed,
                z.ties);
    ties_per_zone[z.zone] += z.ties;
  }
  // AC is small (the corners between A and C beyond B and D's footprints)
  for (const char* zone : {"AB", "AC", "AD", "BC", "CD"}) EXPECT_GE(ties_per_zone[zone], 4) << zone;
  EXPECT_EQ(ties_per_zone.count("BD"), 0u);  // B and D see no common ground
  PrintTieErrors("matched ties", m, f.truth);
  // No systematic error per zone and head: the mean of 200-odd ties within 0.015 px (3 x its
  // standard error at a spread of 0.07 px; without the prefilter they reached 0.04 px).
  std::map<std::string, std::pair<int, Eigen::Vector2d>> mean;
  for (size_t o = 0; o < m.matches.observations.size(); ++o) {
    if (!std::isfinite(m.error_px[o].x())) continue;
    const RigStitchObservation& obs = m.matches.observations[o];
    const std::string& id = m.matches.ties[obs.tie].id;
    auto& [n, sum] = mean[id.substr(id.find('/') + 1, id.find('-') - id.find('/') - 1) +
                          f.truth.heads[obs.head].id];
    if (n == 0) sum.setZero();
    ++n;
    sum += m.error_px[o];
  }
  for (const auto& [key, v] : mean) {
    if (v.first >= 100) {
      EXPECT_LT((v.second / v.first).cwiseAbs().maxCoeff(), 0.015) << key;
    }
  }

  const IncrementCheck c = SelfCalibrateOnMatches(f, in, m.matches);
  ASSERT_TRUE(c.result.failures.empty()) << c.result.failures.front();
  std::printf(
      "matched: %zu ties, %zu observations, LSM sigma RMS %.4f px; sigma0 %.3f, fit "
      "stitching RMS per coordinate %.4f -> %.4f px, %zu rejected\n",
      m.matches.ties.size(),
      m.matches.observations.size(),
      m.rms_lsm_sigma_px,
      c.result.sigma0,
      c.result.before.fit.per_coordinate,
      c.result.after.fit.per_coordinate,
      c.result.rejected.size());
  std::printf("increments: RMS(estimate - truth) %.3g rad, RMS(truth) %.3g rad; z-scores:",
              c.rms_error_rad,
              c.rms_truth_rad);
  for (double z : c.z) std::printf(" %.2f", z);
  std::printf("; sum z^2 %.1f\n", c.sum_z2);
  ASSERT_EQ(c.z.size(), 18u);
  EXPECT_LT(c.sum_z2, 42.3);  // chi-square, 18 degrees of freedom, 0.999 quantile
  EXPECT_LE(c.beyond_3_sigma, 1);
  EXPECT_LT(c.rms_error_rad, 0.15 * c.rms_truth_rad);  // the ground calibration alone: 1 x
  // At the matching noise: the LSM sigmas scaled by the sigma0 the fit reaches; the pair
  // differences of the fitted ties at most that noise x 1.5.
  EXPECT_LT(c.result.after.fit.per_coordinate, 1.5 * c.result.sigma0 * m.rms_lsm_sigma_px);
  EXPECT_GT(c.result.before.fit.per_coordinate, 3.0 * c.result.after.fit.per_coordinate);
}

}  // namespace
}  // namespace aerocal::stitch
