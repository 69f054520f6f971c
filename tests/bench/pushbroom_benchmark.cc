// Pushbroom line cameras (issue 17's benchmark): in seconds,
// - BM_PushbroomCalibrate: `CalibrateLineCamera` of a 3 x 1000-detector camera from 10,000 cloud
//   control points (simulated flight of 10,000 lines, noise as the acceptance: 0.25 px,
//   0.1 m control, POS 5 cm / 0.005 deg; spline nodes every 100 lines, degree test from 5, the
//   covariance for the sigmas), against its peer BM_PushbroomPolynomialFit: the patent's plain
//   second step on the same observations (misclosures at the POS and the nominal camera, a degree-5
//   least-squares polynomial per sub-camera and axis; no trajectory, no sigmas);
// - BM_L1Rectification: `RectifyLineImage` of a 3000 x 10000 line image (that flight's POS and
//   nominal camera, map nodes every 8 cells), against its peer BM_CvRemap: cv::remap (bilinear) of
//   the same image through the same maps into the same L1 size (the maps given: the difference is
//   the exact inverse at the map nodes).
// The end prints the time ratios of the pairs, measured in one run.
//
// Run: cmake -DAEROCAL_BUILD_BENCHMARKS=ON ...; build/tests/bench/bench_pushbroom
#include "tests/bench/ratio_reporter.h"
#include "triangulation/pushbroom/line_calibration.h"
#include "triangulation/pushbroom/line_rectification.h"
#include "triangulation/pushbroom/line_simulation.h"

#include <Eigen/QR>
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <map>
#include <random>

namespace aerocal::triangulation {
namespace {

// The flight of both benchmarks, simulated once.
const LineSimulation& Flight() {
  static const LineSimulation flight = [] {
    LineSimulationOptions o;
    o.detectors_per_camera = 1000;
    o.lines = 10000;
    o.control_points = 10000;
    o.seed = 17;
    return SimulateLineFlight(o);
  }();
  return flight;
}

const PosTrajectory& FlightPos() {
  static const PosTrajectory pos = PosTrajectory::FromRecords(Flight().pos, "pos.csv");
  return pos;
}

void BM_PushbroomCalibrate(benchmark::State& state) {
  const LineSimulation& f = Flight();
  LineCalibrationOptions options;
  LineCalibrationResult result;
  for (auto _ : state) {
    result = CalibrateLineCamera(
        f.nominal, FlightPos(), f.observations, f.points, options, "observations.csv");
    benchmark::DoNotOptimize(result.dx_mm.data());
  }
  if (!result.valid) state.SkipWithError("the calibration is not valid");
  state.counters["observations"] = double(result.n_observations);
  state.counters["sigma0"] = result.report.sigma0;
  state.counters["iterations"] = double(result.report.iterations);
}
BENCHMARK(BM_PushbroomCalibrate)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_PushbroomPolynomialFit(benchmark::State& state) {
  const LineSimulation& f = Flight();
  const calib::LineCamera& camera = f.nominal;
  std::map<std::string, Eigen::Vector3d> point;
  for (const auto& p : f.points) point[p.id] = *p.xyz_m;
  const auto ranges = camera.Ranges();
  for (auto _ : state) {
    std::vector<std::vector<std::pair<double, Eigen::Vector2d>>> per_subcamera(ranges.size());
    for (const auto& o : f.observations) {
      Eigen::Vector2d xy;
      if (!ProjectAtLine(camera, FlightPos(), o.line, point.at(o.point), &xy)) continue;
      per_subcamera[camera.SubcameraOf(o.detector)].emplace_back(
          o.detector, (xy - camera.DetectorPosition(o.detector)) / camera.pitch_mm);
    }
    for (size_t s = 0; s < ranges.size(); ++s) {
      const auto& samples = per_subcamera[s];
      const double first = ranges[s].first, last = ranges[s].second;
      Eigen::MatrixXd a(samples.size(), 6);
      Eigen::MatrixXd b(samples.size(), 2);
      for (size_t r = 0; r < samples.size(); ++r) {
        const double u = (2 * samples[r].first - first - last) / (last - first);
        double power = 1;
        for (int t = 0; t < 6; ++t, power *= u) a(r, t) = power;
        b.row(r) = samples[r].second.transpose();
      }
      const Eigen::MatrixXd coefficients = a.colPivHouseholderQr().solve(b);
      benchmark::DoNotOptimize(coefficients.data());
    }
  }
}
BENCHMARK(BM_PushbroomPolynomialFit)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(0.5);

// The 3000 x 10000 line image: a random texture (the content does not change the work).
const stitch::GrayImage& LineImage() {
  static const stitch::GrayImage image = [] {
    stitch::GrayImage out(Flight().pos.size(), Flight().nominal.detectors);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> grey(0.0f, 255.0f);
    for (int r = 0; r < out.rows(); ++r)
      for (int c = 0; c < out.cols(); ++c) out(r, c) = grey(rng);
    return out;
  }();
  return image;
}

L1Image last_l1;  // kept for the peer: the same maps and size

void BM_L1Rectification(benchmark::State& state) {
  for (auto _ : state) {
    last_l1 = RectifyLineImage(Flight().nominal, FlightPos(), LineImage(), 0.0, 0.0, 8);
    benchmark::DoNotOptimize(last_l1.image.data());
  }
  state.counters["l1_Mcells"] = double(last_l1.grid.width) * last_l1.grid.height / 1e6;
  state.counters["line_Mpx"] = double(LineImage().size()) / 1e6;
}
BENCHMARK(BM_L1Rectification)->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

void BM_CvRemap(benchmark::State& state) {
  if (last_l1.image.size() == 0) {
    state.SkipWithError("run BM_L1Rectification first (the maps)");
    return;
  }
  const stitch::GrayImage& line = LineImage();
  // cv::Mat copies of the image and the maps (the copies are not timed).
  cv::Mat source(int(line.rows()), int(line.cols()), CV_32FC1), map_x, map_y, out;
  map_x.create(int(last_l1.detector_map.rows()), int(last_l1.detector_map.cols()), CV_32FC1);
  map_y.create(map_x.size(), CV_32FC1);
  for (int r = 0; r < source.rows; ++r)
    for (int c = 0; c < source.cols; ++c) source.at<float>(r, c) = line(r, c);
  for (int r = 0; r < map_x.rows; ++r)
    for (int c = 0; c < map_x.cols; ++c) {
      map_x.at<float>(r, c) = last_l1.detector_map(r, c);
      map_y.at<float>(r, c) = last_l1.line_map(r, c);
    }
  for (auto _ : state) {
    cv::remap(source, out, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, 0);
    benchmark::DoNotOptimize(out.data);
  }
}
BENCHMARK(BM_CvRemap)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(1.0);

}  // namespace
}  // namespace aerocal::triangulation

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  aerocal::testing::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const auto ratio =
      [&](const char* what, const char* ours, const char* peer, const char* peer_what) {
        const double a = reporter.TimeOf(ours), b = reporter.TimeOf(peer);  // s
        if (a > 0 && b > 0)
          std::printf("%s: %.3f s, %s: %.3f s, ratio %.1f\n", what, a, peer_what, b, a / b);
      };
  ratio("calibration of 3 x 1000 detectors from 10,000 control points",
        "BM_PushbroomCalibrate",
        "BM_PushbroomPolynomialFit",
        "the plain polynomial fit of the same observations");
  ratio("L1 rectification of a 3000 x 10000 line image",
        "BM_L1Rectification",
        "BM_CvRemap",
        "cv::remap through the same maps");
  benchmark::Shutdown();
  return 0;
}
