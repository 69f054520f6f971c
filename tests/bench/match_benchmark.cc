// Matching one 6-CCD frame (the Boruszyn scene of tests/stitch/match_test_scene.h: 2 x 3 grid,
// 2404 x 1286 px sub-images, 200 px overlaps) with each detector, LSM on. Reports seconds per
// frame and the mean tie points per strip (counter "points_per_strip", "ties").
// Arg 1: on one core (TBB and OpenCV limited to one thread), as issue 35 measures a unit.
// Run: build/tests/bench/bench_match (AEROCAL_BUILD_BENCHMARKS=ON, Release).
#include "stitch/matching/overlap_matcher.h"
#include "tests/stitch/match_test_scene.h"

#include <benchmark/benchmark.h>
#include <opencv2/core/utility.hpp>
#include <tbb/global_control.h>

#include <memory>

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
  options.detector = state.range(0) == 0 ? Detector::kSift : Detector::kFoerstner;
  state.SetLabel(state.range(0) == 0 ? "sift" : "foerstner");
  FrameMatches matches;
  for (auto _ : state) matches = MatchFrame(scene->nominal, scene->images, "4880", options);
  double points = 0;
  for (const StripReport& s : matches.strips) points += s.points;
  state.counters["strips"] = static_cast<double>(matches.strips.size());
  state.counters["points_per_strip"] = points / static_cast<double>(matches.strips.size());
  state.counters["ties"] = points;
}
BENCHMARK(BM_MatchFrame)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kSecond)
    ->Iterations(2);

}  // namespace
}  // namespace aerocal::stitch
BENCHMARK_MAIN();
