// Matching one 6-CCD frame (the Boruszyn scene of tests/stitch/match_test_scene.h: 2 x 3 grid,
// 2404 x 1286 px sub-images, 200 px overlaps) with each detector, LSM on. Reports seconds per
// frame and the mean tie points per strip (counter "points_per_strip", "ties").
// Run: build/tests/bench/bench_match (AEROCAL_BUILD_BENCHMARKS=ON, Release).
#include <benchmark/benchmark.h>

#include "stitch/matching/overlap_matcher.h"
#include "tests/stitch/match_test_scene.h"

namespace aerocal::stitch {
namespace {

void BM_MatchFrame(benchmark::State& state) {
  const auto& scene = testing::BoruszynScene();
  if (!scene) {
    state.SkipWithError("shared data odm_boruszyn_kap_frames absent");
    return;
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
BENCHMARK(BM_MatchFrame)->Arg(0)->Arg(1)->Unit(benchmark::kSecond)->Iterations(2);

}  // namespace
}  // namespace aerocal::stitch
BENCHMARK_MAIN();
