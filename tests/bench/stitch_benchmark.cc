// Stitching benchmarks (issue "sub-image stitching"):
// (a) BM_AdjustFrame: one 6-CCD frame (2 x 3, 14000 x 12000 px, base II and V) with 900 tie points
//     adjusted, affine with data snooping, and with the model chosen by the F test (all 4 models).
// (b) BM_Resample / BM_OpenCvWarpAffine / BM_Copy: the 14000 x 12000 16-bit virtual image from 6
//     sub-images (sub-pixel affine misplacements), bilinear, overlaps averaged, ON ONE CORE (one
//     TBB thread, cv::setNumThreads(1)); ours strip-wise, OpenCV's cv::warpAffine doing the same
//     six warps (plus a coverage warp each) into the same strips and the same averaging, and a
//     plain copy (std::memcpy) of as many bytes as the virtual image has, from one buffer to
//     another, both far larger than the caches: the machine's memory bandwidth for this amount of
//     output. Arg 0 of BM_Resample is the fast path, arg 1 the reference (per-pixel double) path.
//     Counter "Mpx/s" is virtual-image Mpx per second; the program ends by printing the ratios.
// Run: cmake -DAEROCAL_BUILD_BENCHMARKS=ON ...; build/tests/bench/bench_stitch
#include "stitch/adjustment/model_selection.h"
#include "stitch/resample/virtual_image.h"
#include "tests/bench/discard_sink.h"
#include "tests/bench/ratio_reporter.h"
#include "tests/stitch/simulated_camera.h"

#include <Eigen/LU>
#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cstring>
#include <random>
#include <string>

namespace aerocal::stitch {
namespace {

void BM_AdjustFrame(benchmark::State& state) {
  const bool choose = state.range(0) == 1;
  const auto camera = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 2e-4, 7);
  const auto frames = testing::SimulateFrames(camera, 1, 900, 11);
  StitchOptions options;
  options.base_ids = camera.base;
  double sigma0_px = 0;
  for (auto _ : state) {
    if (choose)
      sigma0_px = ChooseModel(camera.nominal, frames[0], options).Chosen().sigma0_px;
    else
      sigma0_px =
          AdjustFrame(camera.nominal, frames[0], calib::MappingModel::kAffine, options).sigma0_px;
  }
  state.SetLabel(choose ? "auto (4 models, F test)" : "affine");
  state.counters["ties"] = static_cast<double>(frames[0].ties.size());
  state.counters["sigma0_px"] = sigma0_px;
}
BENCHMARK(BM_AdjustFrame)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// The 6 misplaced sub-images of the 14000 x 12000 camera, 16 bit, a smooth random texture.
struct ResampleScene {
  calib::Camera truth;
  std::vector<MemoryRaster> images;
};

const ResampleScene& Scene() {
  static const ResampleScene scene = [] {
    ResampleScene s;
    s.truth = testing::MakeSimulatedCamera(2, 3, {"II", "V"}, 1e-4, 3).truth;
    std::mt19937 rng(1);
    for (const auto& sub : s.truth.subimages) {
      MemoryRaster image({sub.width_px, sub.height_px, 1, 16});
      auto* p = reinterpret_cast<std::uint16_t*>(image.bytes().data());
      for (size_t i = 0; i < static_cast<size_t>(sub.width_px) * sub.height_px; ++i)
        p[i] = static_cast<std::uint16_t>(20000 + (rng() & 4095));
      s.images.push_back(std::move(image));
    }
    return s;
  }();
  return scene;
}

void BM_Resample(benchmark::State& state) {
  auto& scene = const_cast<ResampleScene&>(Scene());
  std::vector<RasterSource*> sources;
  for (auto& image : scene.images) sources.push_back(&image);
  ResampleOptions options;
  options.strip_rows = 256;
  options.threads = 1;
  DiscardSink sink(static_cast<size_t>(scene.truth.width_px) * 2);
  options.reference = state.range(0) == 1;
  for (auto _ : state) ResampleVirtualImage(scene.truth, sources, &sink, options);
  const double mpx = scene.truth.width_px * 1e-6 * scene.truth.height_px;
  state.counters["Mpx/s"] =
      benchmark::Counter(mpx * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Resample)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

void BM_OpenCvWarpAffine(benchmark::State& state) {
  cv::setNumThreads(1);
  const ResampleScene& scene = Scene();
  const int width = scene.truth.width_px, height = scene.truth.height_px, strip_rows = 256;
  std::vector<cv::Mat> sources;
  for (const auto& image : scene.images) {
    const RasterInfo info = image.Info();
    sources.emplace_back(
        info.height, info.width, CV_16UC1, const_cast<std::uint8_t*>(image.bytes().data()));
  }
  std::vector<cv::Mat> ones;
  for (const auto& s : sources) ones.emplace_back(s.size(), CV_8UC1, cv::Scalar(1));
  cv::Mat sum(strip_rows, width, CV_32FC1), count(strip_rows, width, CV_32FC1);
  cv::Mat warped, coverage, out(strip_rows, width, CV_16UC1);
  std::uint64_t checksum = 0;
  for (auto _ : state) {
    for (int y0 = 0; y0 < height; y0 += strip_rows) {
      const int rows = std::min(strip_rows, height - y0);
      sum.setTo(0);
      count.setTo(0);
      for (size_t k = 0; k < sources.size(); ++k) {
        const auto& s = scene.truth.subimages[k];
        // Footprint of the sub-image in this strip (its bounding box), the warp's output ROI.
        const double u0 = s.params[2], v0 = s.params[5];
        const int x0 = std::max(0, static_cast<int>(u0) - 1);
        const int x1 = std::min(width, static_cast<int>(u0 + s.width_px) + 2);
        const int r0 = std::max(y0, static_cast<int>(v0) - 1);
        const int r1 = std::min(y0 + rows, static_cast<int>(v0 + s.height_px) + 2);
        if (x0 >= x1 || r0 >= r1) continue;
        // Affine map from the ROI's pixels to the sub-image (inverse map).
        const Eigen::Matrix3d m = calib::HomographyFromParams(s.model, s.params.data()).inverse();
        cv::Mat map = (cv::Mat_<double>(2, 3) << m(0, 0),
                       m(0, 1),
                       m(0, 2) + m(0, 0) * x0 + m(0, 1) * r0,
                       m(1, 0),
                       m(1, 1),
                       m(1, 2) + m(1, 0) * x0 + m(1, 1) * r0);
        const cv::Size size(x1 - x0, r1 - r0);
        cv::warpAffine(sources[k],
                       warped,
                       map,
                       size,
                       cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT,
                       0);
        cv::warpAffine(ones[k],
                       coverage,
                       map,
                       size,
                       cv::INTER_NEAREST | cv::WARP_INVERSE_MAP,
                       cv::BORDER_CONSTANT,
                       0);
        const cv::Rect roi(x0, r0 - y0, size.width, size.height);
        cv::Mat sum_roi = sum(roi), count_roi = count(roi);
        cv::accumulate(warped, sum_roi);
        cv::accumulate(coverage, count_roi);
      }
      cv::Mat mean;
      cv::divide(sum, cv::max(count, 1.0f), mean);
      mean.convertTo(out, CV_16UC1);
      checksum += out.at<std::uint16_t>(rows / 2, width / 2);
    }
  }
  benchmark::DoNotOptimize(checksum);
  const double mpx = width * 1e-6 * height;
  state.counters["Mpx/s"] =
      benchmark::Counter(mpx * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OpenCvWarpAffine)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(5.0);

// The memory-bandwidth peer: the virtual image's bytes copied from one buffer to another.
void BM_Copy(benchmark::State& state) {
  const ResampleScene& scene = Scene();
  const size_t bytes = static_cast<size_t>(scene.truth.width_px) * scene.truth.height_px * 2;
  std::vector<std::uint8_t> from(bytes, 1), to(bytes, 0);
  for (auto _ : state) {
    std::memcpy(to.data(), from.data(), bytes);
    benchmark::DoNotOptimize(to.data());
    benchmark::ClobberMemory();
  }
  state.counters["GB/s"] =
      benchmark::Counter(2e-9 * bytes * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Copy)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

}  // namespace
}  // namespace aerocal::stitch

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  aerocal::testing::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  // Wall time (the reporter's) and CPU time: all three run on one thread, so on a machine shared
  // with other jobs the CPU time is the work and the wall time adds the waits for a core.
  for (const bool cpu : {false, true}) {
    const auto time_of = [&](const std::string& name) {
      return cpu ? reporter.CpuTimeOf(name) : reporter.TimeOf(name);
    };
    const double warp = time_of("BM_OpenCvWarpAffine"), copy = time_of("BM_Copy");
    for (const std::string name : {"BM_Resample/0", "BM_Resample/1"}) {
      const double ours = time_of(name);
      if (ours <= 0) continue;
      std::printf("%s %s (%s): %.1f ms",
                  cpu ? "CPU " : "wall",
                  name.c_str(),
                  name.back() == '0' ? "fast" : "reference",
                  ours);
      if (warp > 0) std::printf(", cv::warpAffine %.1f ms: %.2fx as fast", warp, warp / ours);
      if (copy > 0)
        std::printf(", copy %.1f ms: %.1f %% of the copy's bandwidth", copy, 100 * copy / ours);
      std::printf("\n");
    }
  }
  benchmark::Shutdown();
  return 0;
}
