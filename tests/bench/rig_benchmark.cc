// Rig conversion speed (issue 13): the dual-lens camera's 10000 x 10000 px head pair (8 bit, a
// random texture) converted into its 10460 x 10044 px virtual image by ConvertRigExposure, against
// cv::remap on the same maps (the plane homography plus, for distorted heads, the same correction
// grids; maps built per strip, their building timed apart in the counter `map_s`), in one run;
// the end prints the time ratios. Plus the Monte-Carlo of the conversion error analysis with 1e5
// samples (configs/rig_dual_lens_limits.yaml values).
//
// Run: cmake -DAEROCAL_BUILD_BENCHMARKS=ON ...; build/tests/bench/bench_rig
// Arg 0: distortion-free heads (homographies only); arg 1: K1/P1/B1 of a few px (grids).
#include "stitch/resample/raster.h"
#include "stitch/rig/error_analysis.h"
#include "stitch/rig/rig_convert.h"
#include "stitch/rig/rig_tie_matching.h"
#include "stitch/rig/self_calibration.h"
#include "stitch/rig/stitched_image.h"
#include "tests/bench/discard_sink.h"
#include "tests/bench/ratio_reporter.h"
#include "tests/stitch/rig_stitch_line.h"
#include "tests/support/test_support.h"
#include "triangulation/simulation/rig_flight_simulator.h"

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <random>

namespace aerocal::stitch {
namespace {

calib::Rig BenchRig(bool distorted) {
  calib::Rig rig = triangulation::MakeNominalRig(triangulation::RigPreset::kDualLens);
  if (distorted) {
    using Model = calib::BrownFraser10Model;
    rig.heads[0].camera.interior[Model::kK1] = 2e-7;  // 3 px at r = 45 mm
    rig.heads[0].camera.interior[Model::kP1] = 1e-6;
    rig.heads[1].camera.interior[Model::kK1] = -1.5e-7;
    rig.heads[1].camera.interior[Model::kB1] = 5e-5;
  }
  return rig;
}

const std::vector<MemoryRaster>& Heads() {
  static const std::vector<MemoryRaster> heads = [] {
    std::vector<MemoryRaster> out;
    std::mt19937 rng(1);
    for (int k = 0; k < 2; ++k) {
      MemoryRaster image({10000, 10000, 1, 8});
      for (auto& b : image.bytes()) b = static_cast<std::uint8_t>(rng());
      out.push_back(std::move(image));
    }
    return out;
  }();
  return heads;
}

void BM_RigConvert(benchmark::State& state) {
  const calib::Rig rig = BenchRig(state.range(0) != 0);
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, 1200.0));
  auto& heads = const_cast<std::vector<MemoryRaster>&>(Heads());
  std::vector<RasterSource*> sources = {&heads[0], &heads[1]};
  DiscardSink sink(rig.virtual_camera.camera.width_px);
  for (auto _ : state) ConvertRigExposure(converter, sources, &sink, {});
  benchmark::DoNotOptimize(sink.checksum_);
  const double mpx =
      rig.virtual_camera.camera.width_px * 1e-6 * rig.virtual_camera.camera.height_px;
  state.counters["Mpx/s"] =
      benchmark::Counter(mpx * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RigConvert)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// The same conversion with cv::remap: per strip, the maps of each head (homography + the same
// correction grid, bilinear), remap (bilinear, constant border), coverage from the maps, average.
void BM_CvRemap(benchmark::State& state) {
  const calib::Rig rig = BenchRig(state.range(0) != 0);
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, 1200.0));
  const HeadMapCorrections corrections = MakeHeadMapCorrections(converter);
  const int width = rig.virtual_camera.camera.width_px,
            height = rig.virtual_camera.camera.height_px;
  const int strip_rows = 256;
  std::vector<cv::Mat> sources;
  std::vector<Eigen::Matrix3d> homographies;
  for (int k = 0; k < 2; ++k) {
    sources.emplace_back(
        10000, 10000, CV_8UC1, const_cast<std::uint8_t*>(Heads()[k].bytes().data()));
    homographies.push_back(HeadFromVirtualHomography(converter, k));
  }
  cv::Mat map_x(strip_rows, width, CV_32FC1), map_y(strip_rows, width, CV_32FC1);
  cv::Mat warped, in_x, in_y, mask, sum(strip_rows, width, CV_32FC1),
      count(strip_rows, width, CV_32FC1);
  cv::Mat mean, out;
  double map_seconds = 0.0;
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    for (int y0 = 0; y0 < height; y0 += strip_rows) {
      const int rows = std::min(strip_rows, height - y0);
      sum.setTo(0);
      count.setTo(0);
      for (int k = 0; k < 2; ++k) {
        const auto start = std::chrono::steady_clock::now();
        const Eigen::Matrix3d& m = homographies[k];
        const MapCorrectionGrid& g = corrections.grids[k];
        for (int r = 0; r < rows; ++r) {
          float* mx = map_x.ptr<float>(r);
          float* my = map_y.ptr<float>(r);
          const double V = y0 + r;
          for (int c = 0; c < width; ++c) {
            const double w = m(2, 0) * c + m(2, 1) * V + m(2, 2);
            mx[c] = static_cast<float>((m(0, 0) * c + m(0, 1) * V + m(0, 2)) / w);
            my[c] = static_cast<float>((m(1, 0) * c + m(1, 1) * V + m(1, 2)) / w);
            if (g.step_px > 0) {
              const double gu = static_cast<double>(c) / g.step_px, gv = V / g.step_px;
              const int i = std::min(static_cast<int>(gu), g.cols - 2);
              const int j = std::min(static_cast<int>(gv), g.rows - 2);
              const float fu = static_cast<float>(gu - i), fv = static_cast<float>(gv - j);
              const float* t = g.duv.data() + 2 * (static_cast<size_t>(j) * g.cols + i);
              const float* b = t + 2 * g.cols;
              for (int a = 0; a < 2; ++a) {
                const float top = t[a] + fu * (t[2 + a] - t[a]);
                const float bottom = b[a] + fu * (b[2 + a] - b[a]);
                (a == 0 ? mx : my)[c] += top + fv * (bottom - top);
              }
            }
          }
        }
        map_seconds +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const cv::Rect roi(0, 0, width, rows);
        cv::remap(
            sources[k], warped, map_x(roi), map_y(roi), cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
        cv::inRange(map_x(roi), 0.0, 9999.0, in_x);
        cv::inRange(map_y(roi), 0.0, 9999.0, in_y);
        cv::bitwise_and(in_x, in_y, mask);
        cv::Mat sum_roi = sum(roi), count_roi = count(roi);
        cv::accumulate(warped, sum_roi, mask);
        cv::accumulate(mask / 255, count_roi);
      }
      cv::divide(sum, cv::max(count, 1.0f), mean);
      mean.convertTo(out, CV_8UC1);
      checksum += out.at<std::uint8_t>(rows / 2, width / 2);
    }
  }
  benchmark::DoNotOptimize(checksum);
  const double mpx = width * 1e-6 * height;
  state.counters["Mpx/s"] =
      benchmark::Counter(mpx * state.iterations(), benchmark::Counter::kIsRate);
  state.counters["map_s"] = map_seconds / state.iterations();
}
BENCHMARK(BM_CvRemap)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// Monte-Carlo of the conversion error analysis: 1e5 samples at head B's centre pixel, the limits
// of configs/rig_dual_lens_limits.yaml (0.5 px, 1 px, 10", 1 mm, 150 m; 3 sigma).
void BM_ErrorAnalysisMonteCarlo(benchmark::State& state) {
  const calib::Rig rig = BenchRig(false);
  ErrorLimits limits;
  limits.principal_point_px = 0.5;
  limits.principal_distance_px = 1.0;
  limits.angles_arcsec = 10.0;
  limits.lever_arm_mm = 1.0;
  limits.height_m = 150.0;
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, 1200.0));
  const Eigen::Vector2d virtual_px = *converter.VirtualFromHead(1, Eigen::Vector2d(4999.5, 4999.5));
  const ConversionErrorModel model(rig, 1200.0, MakeErrorSources(rig, limits), 1, virtual_px);
  for (auto _ : state) {
    const MonteCarloResult result = RunMonteCarlo(model, 3.0, 100000, 7, false);
    benchmark::DoNotOptimize(result.sigma_px);
  }
}
BENCHMARK(BM_ErrorAnalysisMonteCarlo)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

// One exposure's self-calibrating stitching (issue 16; stitch/rig/self_calibration.h): exposure
// 0001 of the default uav4 line (seed 11: 3 ties at each of the 12 standard positions, 40 dense
// ties, 10 check ties, ~180 head observations), line mode with the snooping and the covariance as
// `rig stitch` runs it (arg 0), against the same problem with the heads held at the ground
// calibration (arg 1: only the tie points adjust; RigStitchOptions::hold_heads). The adjustment
// only: ties from observations.csv (no matching, no resampling).
void BM_RigSelfCalibrationExposure(benchmark::State& state) {
  static const triangulation::SimulatedRigFlight flight =
      triangulation::SimulateRigFlight(testing::Uav4Line(11, 2));  // the simulator's least
  static const testing::RigStitchInputs in = [] {
    testing::RigStitchInputs all = testing::InputsFromFlight(flight);
    all.exposures.resize(1);
    std::vector<RigStitchObservation> first;
    for (const auto& o : all.observations)
      if (o.exposure == 0) first.push_back(o);
    all.observations = first;
    return all;
  }();
  RigStitchOptions options;
  options.hold_heads = state.range(0) != 0;
  for (auto _ : state) {
    const RigStitchResult r = SelfCalibrateRigStitching(
        flight.truth, in.exposures, in.ties, in.observations, in.positions, options);
    benchmark::DoNotOptimize(r.sigma0);
  }
  state.counters["observations"] = static_cast<double>(in.observations.size());
}
BENCHMARK(BM_RigSelfCalibrationExposure)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(1.0);

// One exposure's self-calibration WITH tie matching and the stitched image (issue 16 items 2, 6):
// the uav4 line at half its formats (heads 1456 x 2184 px, virtual 4330 x 5880 px), its head
// images rendered on the kite photograph (../shared/data; skipped without it) once outside the
// measurement; per iteration MatchRigExposureTies on exposure 0001's head images (projection onto
// the level plane, Foerstner + LSM per zone), SelfCalibrateRigStitching on those ties, and
// MakeStitchedImage from the raw heads with the refined increments (each head
// resampled once, coverage, balance, blending) into discard sinks. The peer in the same run
// (BM_StitchedPeerRemap): cv::remap (bilinear) of the four heads onto the same virtual format
// through their plane homographies, maps precomputed (only the remaps timed).
struct StitchedScene {
  triangulation::SimulatedRigFlight flight;
  testing::RigStitchInputs in;
  std::vector<MemoryRaster> heads;
  std::vector<GrayImage> gray;  // the same head images for the matcher
  bool ok = false;
};
// The format scale of the stitched scene: 0.5 (half formats) unless AEROCAL_BENCH_RIG_SCALE
// says otherwise (1: the full formats of issue 35's target).
double SceneFormatScale() {
  const char* text = std::getenv("AEROCAL_BENCH_RIG_SCALE");
  const double scale = text ? std::atof(text) : 0.5;
  return scale > 0.05 && scale <= 1.0 ? scale : 0.5;
}

const StitchedScene& Scene() {
  static const StitchedScene scene = [] {
    StitchedScene s;
    const std::string data = aerocal::testing::SharedDataDir("odm_boruszyn_kap_frames");
    if (data.empty()) return s;
    triangulation::RigFlightSimulationOptions o = testing::Uav4Line(11, 2);
    o.format_scale = SceneFormatScale();
    o.stitch_ties.standard_positions.clear();
    const calib::Rig rig = triangulation::ScaleRigFormats(
        triangulation::MakeNominalRig(triangulation::RigPreset::kUav4), o.format_scale);
    for (const auto& p : DesignRig(rig, o.flight.flying_height_m, 200).standard_positions)
      o.stitch_ties.standard_positions.push_back({p.name, p.virtual_px});
    o.stitch_ties.jitter_px *= o.format_scale;
    s.flight = triangulation::SimulateRigFlight(o);
    s.in = testing::InputsFromFlight(s.flight);
    s.in.positions = DesignRig(s.flight.nominal, o.flight.flying_height_m, 200).standard_positions;
    s.in.exposures.resize(1);
    std::vector<RigStitchObservation> first;
    for (const auto& ob : s.in.observations)
      if (ob.exposure == 0) first.push_back(ob);
    s.in.observations = first;
    triangulation::RigImageOptions render;
    render.texture_path = data + "/images/img_4880.jpg";
    const triangulation::TexturedGround ground =
        triangulation::MakeRigGroundTexture(s.flight, render);
    for (int k = 0; k < 4; ++k) {
      const GrayImage image = triangulation::RenderRigHeadImage(s.flight, ground, render, 0, k);
      s.gray.push_back(image);
      MemoryRaster raster({static_cast<int>(image.cols()), static_cast<int>(image.rows()), 1, 8});
      for (int r = 0; r < image.rows(); ++r)
        for (int c = 0; c < image.cols(); ++c) raster.Set(c, r, 0, image(r, c));
      s.heads.push_back(std::move(raster));
    }
    s.ok = true;
    return s;
  }();
  return scene;
}

bool SkipWithoutScene(const StitchedScene& s, benchmark::State& state) {
  if (!s.ok) state.SkipWithError("../shared/data/odm_boruszyn_kap_frames is absent");
  return !s.ok;
}

// Exposure 0's ties matched with `match`, then self-calibrated; the process CPU seconds of each
// stage (all threads) added to *match_s and *calibrate_s.
RigStitchResult MatchAndCalibrate(const StitchedScene& s,
                                  const RigTieMatchOptions& match,
                                  const RigStitchOptions& options,
                                  RigTieMatches* matches,
                                  double* match_s,
                                  double* calibrate_s) {
  const std::clock_t t0 = std::clock();
  MatchRigExposureTies(s.flight.truth, s.in.exposures[0], 0, s.gray, match, matches);
  const std::clock_t t1 = std::clock();
  RigStitchResult r = SelfCalibrateRigStitching(s.flight.truth,
                                                s.in.exposures,
                                                matches->ties,
                                                matches->observations,
                                                s.in.positions,
                                                options);
  *match_s += double(t1 - t0) / CLOCKS_PER_SEC;
  *calibrate_s += double(std::clock() - t1) / CLOCKS_PER_SEC;
  return r;
}

// The exposure's pose with the self-calibration's increments and offsets.
RigExposure RefinedPose(const StitchedScene& s, const RigStitchResult& r) {
  RigExposure pose = s.in.exposures[0].pose;
  pose.increment_rad.assign(4, Eigen::Vector3d::Zero());
  pose.dt_s.assign(4, 0.0);
  for (const auto& h : r.exposures[0].heads) {
    pose.increment_rad[s.flight.truth.HeadIndex(h.head)] = h.increment_rad;
    pose.dt_s[s.flight.truth.HeadIndex(h.head)] = h.dt_fitted_s;
  }
  return pose;
}

void BM_StitchedExposure(benchmark::State& state) {
  const StitchedScene& s = Scene();
  if (SkipWithoutScene(s, state)) return;
  const calib::Camera& v = s.flight.truth.virtual_camera.camera;
  RigStitchOptions options;
  options.standard_radius_px *= SceneFormatScale();
  // CPU seconds of the process per stage (all threads), summed over the iterations.
  double match_s = 0.0, calibrate_s = 0.0, stitch_s = 0.0;
  for (auto _ : state) {
    RigTieMatches matches;
    const RigStitchResult r = MatchAndCalibrate(s, {}, options, &matches, &match_s, &calibrate_s);
    const std::clock_t t0 = std::clock();
    const RigConverter converter(
        s.flight.truth, RefinedPose(s, r), {Eigen::Vector3d::UnitZ(), s.in.exposures[0].z_ref_m});
    std::vector<RasterSource*> sources;
    for (const auto& h : s.heads) sources.push_back(const_cast<MemoryRaster*>(&h));
    DiscardSink image(v.width_px), mask(v.width_px);
    const StitchedImageReport report = MakeStitchedImage(converter, sources, {}, &image, &mask);
    benchmark::DoNotOptimize(report.overall.rms_dn);
    stitch_s += double(std::clock() - t0) / CLOCKS_PER_SEC;
    state.counters["ties"] = static_cast<double>(matches.ties.size());
    state.counters["observations"] = static_cast<double>(r.report.n_observations);
    state.counters["solves"] = r.profile.solves;
    state.counters["lm_iterations"] = r.profile.iterations;
    state.counters["snoop_rounds"] = r.profile.snooping_rounds;
    state.counters["rejected"] = static_cast<double>(r.rejected.size());
    state.counters["solve_s"] = r.profile.solve_s;
    state.counters["testing_s"] = r.profile.testing_s;
    state.counters["covariance_s"] = r.profile.covariance_s;
    state.counters["effect_s"] = r.profile.effect_s;
    state.counters["setup_s"] = r.profile.setup_s;
    state.counters["figures_s"] = r.profile.figures_s;
    state.counters["calibrate_s"] = r.profile.total_s;
  }
  state.counters["virtual_mpx"] = v.width_px * 1e-6 * v.height_px;
  state.counters["match_cpu_s"] = match_s / state.iterations();
  state.counters["calibrate_cpu_s"] = calibrate_s / state.iterations();
  state.counters["stitch_cpu_s"] = stitch_s / state.iterations();
}
BENCHMARK(BM_StitchedExposure)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

// The seam misregistration the calibration error leaves in the stitched image (virtual px, per
// coordinate): on a grid of every 50th virtual px, each head covering the pixel under the TRUE
// increments and offsets sees the ground there at head pixel p_k; the refined pose carries p_k to
// virtual pixel v_k. Two heads at one pixel disagree by v_j - v_k (0 with a perfect calibration).
double SeamMisregistrationPx(const StitchedScene& s, const RigExposure& refined) {
  RigExposure true_pose = s.in.exposures[0].pose;
  true_pose.increment_rad.assign(4, Eigen::Vector3d::Zero());
  true_pose.dt_s.assign(4, 0.0);
  for (int k = 0; k < 4; ++k) {
    true_pose.increment_rad[k] = s.flight.rig_exposures[k].increment_rad;
    true_pose.dt_s[k] = s.flight.rig_exposures[k].dt_s;
  }
  const RectificationPlane plane{Eigen::Vector3d::UnitZ(), s.in.exposures[0].z_ref_m};
  const RigConverter truth(s.flight.truth, true_pose, plane), fit(s.flight.truth, refined, plane);
  const calib::Camera& v = s.flight.truth.virtual_camera.camera;
  double sum2 = 0.0;
  long pairs = 0;
  for (int r = 0; r < v.height_px; r += 50)
    for (int c = 0; c < v.width_px; c += 50) {
      std::vector<Eigen::Vector2d> seen;
      for (int k = 0; k < 4; ++k) {
        const calib::Camera& head = s.flight.truth.heads[k].camera;
        const auto p = truth.HeadFromVirtual(k, Eigen::Vector2d(c, r));
        if (!p || p->x() < 0 || p->y() < 0 || p->x() > head.width_px - 1 ||
            p->y() > head.height_px - 1)
          continue;
        if (const auto back = fit.VirtualFromHead(k, *p)) seen.push_back(*back);
      }
      for (size_t a = 0; a < seen.size(); ++a)
        for (size_t b = a + 1; b < seen.size(); ++b, ++pairs)
          sum2 += (seen[a] - seen[b]).squaredNorm();
    }
  return pairs > 0 ? std::sqrt(sum2 / (2.0 * pairs)) : NAN;
}

// Tie density against what the self-calibration gives (issue 35): the matcher's cell (arg,
// virtual px; one tie per cell and zone; no target count) against the ties, the CPU seconds of
// matching and self-calibration, the RMS of the increments' sigmas and of their errors against the
// simulator's truth (arcsec), and the seam misregistration the result leaves in the stitched
// image (SeamMisregistrationPx). Run with AEROCAL_BENCH_RIG_SCALE=1 for the full formats.
void BM_TieDensity(benchmark::State& state) {
  const StitchedScene& s = Scene();
  if (SkipWithoutScene(s, state)) return;
  RigTieMatchOptions match;
  match.cell_px = static_cast<double>(state.range(0));
  match.target_ties = 0;  // the arg is the cell at every format
  RigStitchOptions options;
  options.standard_radius_px *= SceneFormatScale();
  constexpr double kArcsec = 180.0 * 3600.0 / M_PI;
  for (auto _ : state) {
    RigTieMatches matches;
    double match_s = 0.0, calibrate_s = 0.0;
    const RigStitchResult r =
        MatchAndCalibrate(s, match, options, &matches, &match_s, &calibrate_s);
    double sigma2 = 0.0, error2 = 0.0;
    int n = 0;
    for (const auto& h : r.exposures[0].heads) {
      if (h.reference) continue;
      const Eigen::Vector3d truth =
          s.flight.rig_exposures[s.flight.truth.HeadIndex(h.head)].increment_rad;
      sigma2 += h.increment_sigma_rad.squaredNorm();
      error2 += (h.increment_rad - truth).squaredNorm();
      n += 3;
    }
    state.counters["ties"] = static_cast<double>(matches.ties.size());
    state.counters["match_cpu_s"] = match_s;
    state.counters["calibrate_cpu_s"] = calibrate_s;
    state.counters["sigma_arcsec"] = std::sqrt(sigma2 / n) * kArcsec;
    state.counters["error_arcsec"] = std::sqrt(error2 / n) * kArcsec;
    state.counters["seam_px"] = SeamMisregistrationPx(s, RefinedPose(s, r));
    state.counters["sigma0"] = r.sigma0;
    state.counters["valid"] = r.failures.empty() ? 1 : 0;
  }
}
BENCHMARK(BM_TieDensity)
    ->Arg(40)
    ->Arg(80)
    ->Arg(160)
    ->Arg(320)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

void BM_StitchedPeerRemap(benchmark::State& state) {
  const StitchedScene& s = Scene();
  if (SkipWithoutScene(s, state)) return;
  const calib::Camera& v = s.flight.truth.virtual_camera.camera;
  const RigConverter converter(s.flight.truth,
                               s.in.exposures[0].pose,
                               {Eigen::Vector3d::UnitZ(), s.in.exposures[0].z_ref_m});
  std::vector<cv::Mat> heads, map_x, map_y;
  for (int k = 0; k < 4; ++k) {
    const RasterInfo info = s.heads[k].Info();
    heads.push_back(cv::Mat(
        info.height, info.width, CV_8UC1, const_cast<std::uint8_t*>(s.heads[k].bytes().data())));
    const Eigen::Matrix3d h = HeadFromVirtualHomography(converter, k);
    cv::Mat mx(v.height_px, v.width_px, CV_32FC1), my(v.height_px, v.width_px, CV_32FC1);
    for (int r = 0; r < v.height_px; ++r)
      for (int c = 0; c < v.width_px; ++c) {
        const Eigen::Vector3d p = h * Eigen::Vector3d(c, r, 1.0);
        mx.at<float>(r, c) = p.z() > 0 ? float(p.x() / p.z()) : -1.0f;
        my.at<float>(r, c) = p.z() > 0 ? float(p.y() / p.z()) : -1.0f;
      }
    map_x.push_back(mx);
    map_y.push_back(my);
  }
  cv::Mat warped;
  for (auto _ : state)
    for (int k = 0; k < 4; ++k) {
      cv::remap(heads[k], warped, map_x[k], map_y[k], cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
      benchmark::DoNotOptimize(warped.data);
    }
}
BENCHMARK(BM_StitchedPeerRemap)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(1.0);

}  // namespace
}  // namespace aerocal::stitch

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  aerocal::testing::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto time_of = [&](const std::string& prefix) { return reporter.TimeOf(prefix); };  // ms
  for (const char* arg : {"/0", "/1"}) {
    const double ours = time_of(std::string("BM_RigConvert") + arg);
    const double cv = time_of(std::string("BM_CvRemap") + arg);
    if (ours > 0 && cv > 0)
      std::printf("rig convert%s: %.1f ms, cv::remap on the same maps: %.1f ms, ratio %.2f\n",
                  arg[1] == '0' ? " (distortion-free)" : " (distorted, grids)",
                  ours,
                  cv,
                  ours / cv);
  }
  const double ours = time_of("BM_RigSelfCalibrationExposure/0");
  const double held = time_of("BM_RigSelfCalibrationExposure/1");
  if (ours > 0 && held > 0)
    std::printf(
        "self-calibration of one exposure: %.1f ms, the same problem with the heads held: "
        "%.1f ms, ratio %.2f\n",
        ours,
        held,
        ours / held);
  const double stitched = time_of("BM_StitchedExposure");
  const double remap = time_of("BM_StitchedPeerRemap");
  if (stitched > 0 && remap > 0)
    std::printf(
        "one exposure's tie matching + self-calibration + stitched image (formats x %.2f): %.1f "
        "ms, cv::remap of the four heads onto the same format: %.1f ms, ratio %.2f\n",
        aerocal::stitch::SceneFormatScale(),
        stitched,
        remap,
        stitched / remap);
  benchmark::Shutdown();
  return 0;
}
