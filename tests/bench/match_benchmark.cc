// Matching one 6-CCD frame (the Boruszyn scene of tests/stitch/match_test_scene.h: 2 x 3 grid,
// 2404 x 1286 px sub-images, 200 px overlaps), LSM on: BM_MatchFrame/<method>/<one core> with
// method 0 = descriptor search with SIFT, 1 = descriptor search with Foerstner, 2 = predicted
// search; one core: TBB and OpenCV limited to one thread, as issue 35 measures a unit. Reports
// seconds per frame and the mean tie points per strip (counters "points_per_strip", "ties").
// BM_MatchLargeFrame: the same scene enlarged to the production size, predicted search against
// the descriptor search as its peer; the program ends by printing the ratio.
// Run: build/tests/bench/bench_match (AEROCAL_BUILD_BENCHMARKS=ON, Release).
#include "stitch/matching/overlap_matcher.h"
#include "tests/bench/ratio_reporter.h"
#include "tests/stitch/match_test_scene.h"

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <tbb/global_control.h>

#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

namespace aerocal::stitch {
namespace {

void BM_MatchFrame(benchmark::State& state) {
  const auto& scene = testing::BoruszynScene();
  if (!scene) {
    state.SkipWithError("shared data odm_boruszyn_kap_frames absent");
    return;
  }
  std::unique_ptr<tbb::global_control> one_core;
  if (state.range(1) == 1) {
    one_core =
        std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, 1);
    cv::setNumThreads(1);
  }
  MatchOptions options;
  static const char* const kLabels[] = {"sift", "foerstner", "predicted"};
  options.detector = state.range(0) == 0 ? Detector::kSift : Detector::kFoerstner;
  options.search = state.range(0) == 2 ? Search::kPredicted : Search::kDescriptors;
  state.SetLabel(kLabels[state.range(0)]);
  FrameMatches matches;
  for (auto _ : state) matches = MatchFrame(scene->nominal, scene->images, "4880", options);
  double points = 0;
  for (const StripReport& s : matches.strips) points += s.points;
  state.counters["strips"] = static_cast<double>(matches.strips.size());
  state.counters["points_per_strip"] = points / static_cast<double>(matches.strips.size());
  state.counters["ties"] = points;
}
// A /proc/self/status line's value in MB ("VmHWM:", "VmRSS:").
double StatusMb(const std::string& key) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(key, 0) == 0) return std::stod(line.substr(key.size())) / 1024.0;
  return -1;
}

// The production size (issue 35: a 6-CCD 14,000 x 12,000 frame in under 1 s on one core): the
// scene enlarged 3 times, 13,824 x 10,368 px; the predicted search, and the descriptor search
// (SIFT) as the peer in the same run. Memory: "images_mb" the six float sub-images, the process's
// peak RSS while matching ("match_peak_rss_mb", the peak reset before) and its RSS after
// ("scene_rss_mb": the scene the benchmark keeps, the enlarged photograph included).
void BM_MatchLargeFrame(benchmark::State& state) {
  static const std::optional<testing::MatchScene> scene = testing::MakeBoruszynScene(3);
  if (!scene) {
    state.SkipWithError("shared data odm_boruszyn_kap_frames absent");
    return;
  }
  tbb::global_control one_core(tbb::global_control::max_allowed_parallelism, 1);
  cv::setNumThreads(1);
  MatchOptions options;
  options.search = state.range(0) == 0 ? Search::kPredicted : Search::kDescriptors;
  state.SetLabel(state.range(0) == 0 ? "predicted" : "descriptors (sift), peer");
  std::ofstream("/proc/self/clear_refs") << "5";  // peak RSS := current RSS (Linux >= 4.0)
  FrameMatches matches;
  for (auto _ : state) matches = MatchFrame(scene->nominal, scene->images, "4880", options);
  double points = 0;
  for (const StripReport& s : matches.strips) points += s.points;
  const testing::TieAgreement agreement =
      testing::AgreementThroughTruth(scene->truth, matches.observations);
  state.counters["ties"] = points;
  state.counters["rms_px"] = agreement.rms_px;
  double images_mb = 0;
  for (const GrayImage& image : scene->images) images_mb += image.size() * 4.0 / (1 << 20);
  state.counters["images_mb"] = images_mb;
  state.counters["match_peak_rss_mb"] = StatusMb("VmHWM:");
  state.counters["scene_rss_mb"] = StatusMb("VmRSS:");
}
BENCHMARK(BM_MatchLargeFrame)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(1);

BENCHMARK(BM_MatchFrame)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Args({2, 0})
    ->Args({2, 1})
    ->Unit(benchmark::kSecond)
    ->Iterations(2);

}  // namespace
}  // namespace aerocal::stitch
int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  aerocal::testing::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  // One thread each: the CPU time is the work on a machine shared with other jobs.
  const double ours = reporter.CpuTimeOf("BM_MatchLargeFrame/0");
  const double peer = reporter.CpuTimeOf("BM_MatchLargeFrame/1");
  if (ours > 0 && peer > 0)
    std::printf(
        "CPU 13824 x 10368 frame, one core: predicted search %.3f s, descriptor search "
        "(SIFT) %.3f s: %.1fx as fast (target: under 1 s)\n",
        ours,
        peer,
        peer / ours);
  benchmark::Shutdown();
  return 0;
}
