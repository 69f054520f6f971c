// Self-calibrating block adjustment: aerocal vs `colmap bundle_adjuster` (Debian package colmap)
// on the same data, in the same run. Simulated blocks of 37, 600 and 2400 exposures (seeded
// example flight scaled up; aerocal with its control points, COLMAP as a free network with
// intrinsics refined) and the real DBAT Roma block (published answer). Counters:
//   aerocal_s / colmap_s / ratio      wall time of the whole adjustment (aerocal: with covariance)
//   aerocal_solve_s                   aerocal without the covariance
//   c_error_px / colmap_c_error_px    estimated principal distance minus the truth (or published)
//   aerocal_sigma0_px, colmap_final_rms_px (COLMAP's report)
//   peak_rss_mb                       peak of this benchmark process (simulation included)
//   adjust_cli_peak_rss_mb / _s       `aerocal adjust` alone on the block's files, in a child
//                                     process (its own ru_maxrss from wait4), and its wall time
// BM_AdjustDefaults: `aerocal adjust` with its default options (snooping on) at 150 / 600 / 2400
// exposures against COLMAP, with the snooping share and the peak RSS (see there).
// Run: build with -DAEROCAL_BUILD_BENCHMARKS=ON, then build/tests/bench/bench_triangulation.
#include "tests/bench/bench_blocks.h"
#include "tests/support/simulated_block.h"
#include "tests/support/test_support.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/import/colmap_export.h"
#include "triangulation/import/dbat_import.h"
#include "triangulation/import/write_project.h"
#include "triangulation/simulation/flight_simulator.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace aerocal::triangulation {
namespace {

using bench::Clock;
using bench::PeakRssMb;
using bench::Seconds;
using bench::SimulateBlock;
using testing::ProjectFromFlight;
using Model = calib::BrownFraser10Model;

// Starting coordinates of every point seen twice (the same start aerocal computes).
std::map<std::string, Eigen::Vector3d> StartPoints(const Project& p) {
  std::map<std::string, std::vector<ImageRay>> rays;
  for (const auto& o : p.observations) {
    const Exposure* e = p.FindExposure(o.image);
    rays[o.point].push_back(
        RayFromPixel(p.cameras.at(e->camera), e->opk_rad, e->center_m, o.pixel));
  }
  std::map<std::string, Eigen::Vector3d> out;
  for (const auto& [id, r] : rays)
    if (auto x = IntersectRays(r)) out[id] = *x;
  return out;
}

struct ColmapRun {
  bool ok = false;
  double seconds = 0, f_px = 0, final_rms_px = 0;
  double cpu_seconds = 0;  // user + system of bundle_adjuster (all its threads)
  int iterations = 0;      // Ceres' iterations in COLMAP's report
  double peak_rss_mb = 0;  // bundle_adjuster's own peak (GNU time), 0 without /usr/bin/time
};

// User + system CPU time of the reaped children of this process, s.
double ChildrenCpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

ColmapRun RunColmap(const Project& project) {
  ColmapRun run;
  if (std::system("command -v colmap > /dev/null 2>&1") != 0) return run;
  testing::TempDir dir("aerocal_bench_colmap");
  std::filesystem::create_directories(dir.File("in"));
  std::filesystem::create_directories(dir.File("out"));
  WriteColmapModel(project, StartPoints(project), dir.File("in"));
  // GNU time reports the peak resident memory of bundle_adjuster alone (%M, KiB).
  const bool timed = std::filesystem::exists("/usr/bin/time");
  const std::string command =
      (timed ? "/usr/bin/time -f %M -o " + dir.File("rss.txt") + " " : std::string()) +
      "env QT_QPA_PLATFORM=offscreen colmap bundle_adjuster --input_path " + dir.File("in") +
      " --output_path " + dir.File("out") +
      " --BundleAdjustment.refine_focal_length 1 --BundleAdjustment.refine_principal_point 1"
      " --BundleAdjustment.refine_extra_params 1 --log_to_stderr 1 > " +
      dir.File("log.txt") + " 2>&1";
  const auto start = Clock::now();
  const double cpu_start = ChildrenCpuSeconds();
  const int rc = std::system(command.c_str());
  run.seconds = Seconds(start);
  run.cpu_seconds = ChildrenCpuSeconds() - cpu_start;
  if (rc != 0) return run;
  if (timed) {
    std::ifstream rss(dir.File("rss.txt"));
    double kib = 0;
    if (rss >> kib) run.peak_rss_mb = kib / 1024.0;
  }
  // Export to text (bundle_adjuster writes the binary format).
  const std::string convert = "colmap model_converter --input_path " + dir.File("out") +
                              " --output_path " + dir.File("out") +
                              " --output_type TXT > /dev/null 2>&1";
  if (std::system(convert.c_str()) != 0) return run;
  std::ifstream cameras(dir.File("out/cameras.txt"));
  std::string line;
  while (std::getline(cameras, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream in(line);
    std::string id, model;
    double w, h, fx, fy;
    in >> id >> model >> w >> h >> fx >> fy;
    run.f_px = fy;
    break;
  }
  // COLMAP's bundle-adjustment report: "Final cost : X [px]" (RMS reprojection error).
  std::ifstream log(dir.File("log.txt"));
  while (std::getline(log, line)) {
    const auto iterations = line.find("Iterations");
    if (iterations != std::string::npos && line.find(':', iterations) != std::string::npos)
      run.iterations = std::atoi(line.substr(line.find(':', iterations) + 1).c_str());
    const auto at = line.find("Final cost");
    if (at == std::string::npos) continue;
    std::istringstream in(line.substr(line.find(':', at) + 1));
    in >> run.final_rms_px;
  }
  run.ok = run.f_px > 0;
  return run;
}

struct CliRun {
  bool ok = false;
  int exit_code = -1;
  double seconds = 0, peak_rss_mb = 0;
  double cpu_seconds = 0;  // user + system of the child
  int iterations = 0;      // the final solve's, from the result
};

// `aerocal adjust` on the project file `project_file`, result written to `out`.
CliRun RunAdjustCli(const std::string& project_file,
                    const std::string& out,
                    const std::vector<std::string>& extra) {
  CliRun run;
  const std::string binary = testing::AerocalBinary();
  std::vector<std::string> args = {"aerocal", "adjust", "--project", project_file, "--out", out};
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const auto start = Clock::now();
  const pid_t pid = fork();
  if (pid == 0) {
    if (!std::freopen("/dev/null", "w", stdout)) _exit(126);
    execv(binary.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  rusage usage{};
  if (pid < 0 || wait4(pid, &status, 0, &usage) != pid) return run;
  run.seconds = Seconds(start);
  run.peak_rss_mb = usage.ru_maxrss / 1024.0;
  run.cpu_seconds = usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
                    1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
  // 0 converged; 3 ran but flagged (e.g. the rejection cap): a finished run all the same.
  run.ok = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 3);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (run.ok) run.iterations = testing::ReadJson(out).value("iterations", 0);
  return run;
}

// The adjustment as a user runs it: the block written as FORMATS.md files, `aerocal adjust` in a
// child process. wait4 reports that child's own peak resident memory, free of what this process
// holds (the simulation, earlier blocks).
// `extra`: further options (none: the defaults of `aerocal adjust`, data snooping on).
CliRun RunAerocalAdjust(const Project& project, const std::vector<std::string>& extra) {
  testing::TempDir dir("aerocal_bench_cli");
  WriteProjectFolder(project, dir.File("block"));
  return RunAdjustCli(dir.File("block/project.yaml"), dir.File("result.json"), extra);
}

void Compare(benchmark::State& state,
             const Project& project,
             const AdjustOptions& options,
             const std::string& self_calibration,
             double c_truth_mm) {
  AdjustmentResult r;
  double seconds = 0;
  for (auto _ : state) {
    const auto start = Clock::now();
    r = Adjust(project, options);
    seconds = Seconds(start);
  }
  const double p = project.cameras.begin()->second.pixel_size_mm;
  state.counters["aerocal_s"] = seconds;
  state.counters["aerocal_solve_s"] = r.solve.seconds;
  state.counters["aerocal_sigma0_px"] = r.sigma0_px;
  state.counters["c_error_px"] = (r.cameras[0].estimated[Model::kC] - c_truth_mm) / p;
  state.counters["c_sigma_px"] = r.cameras[0].sigma[Model::kC] / p;
  state.counters["converged"] = r.converged();
  state.counters["peak_rss_mb"] = PeakRssMb();
  const CliRun cli =
      RunAerocalAdjust(project, {"--self-calibration", self_calibration, "--no-snooping"});
  if (cli.ok) {
    state.counters["adjust_cli_s"] = cli.seconds;
    state.counters["adjust_cli_peak_rss_mb"] = cli.peak_rss_mb;
  }
  const ColmapRun colmap = RunColmap(project);
  if (colmap.ok) {
    state.counters["colmap_s"] = colmap.seconds;
    state.counters["ratio_colmap_over_aerocal"] = colmap.seconds / seconds;
    state.counters["colmap_c_error_px"] = colmap.f_px - c_truth_mm / p;
    state.counters["colmap_final_rms_px"] = colmap.final_rms_px;
  } else {
    state.SetLabel("colmap not available or failed");
  }
}

void BM_SimulatedBlock(benchmark::State& state) {
  const int exposures = static_cast<int>(state.range(0));
  const SimulatedFlight f = SimulateBlock(exposures);
  const Project project = ProjectFromFlight(f);
  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("all");
  options.data_snooping = false;  // neither solver tests for gross errors here
  state.counters["observations"] = static_cast<double>(f.observations.size());
  Compare(state, project, options, "all", f.truth.c_mm());
}
BENCHMARK(BM_SimulatedBlock)
    ->Arg(37)
    ->Arg(600)
    ->Arg(2400)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

// `aerocal adjust` as a user runs it, DEFAULT options (data snooping on, covariance), against
// `colmap bundle_adjuster` on the same block (issue 9's acceptance: at most 0.5 x COLMAP's wall
// time). Counters:
//   adjust_s, adjust_peak_rss_mb     the default run (child process, its own peak RSS)
//   adjust_no_snooping_s             the same with --no-snooping
//   snooping_share                   1 - adjust_no_snooping_s / adjust_s
//   colmap_s, ratio_aerocal_over_colmap (adjust_s / colmap_s), adjust_exit_code
//   colmap_peak_rss_mb               bundle_adjuster's own peak RSS (GNU time); observations,
//                                    points: the block's (memory per observation / point)
//   *_cpu_s, snooping_share_cpu, ratio_cpu_aerocal_over_colmap: the same in CPU time (user +
//   system of the child; COLMAP's over all its threads, aerocal solves on one): on a machine
//   shared with other work the wall times measure the load as much as the programs.
void BM_AdjustDefaults(benchmark::State& state) {
  const int exposures = static_cast<int>(state.range(0));
  const Project project = ProjectFromFlight(SimulateBlock(exposures));
  CliRun with, without;
  for (auto _ : state) {
    with = RunAerocalAdjust(project, {});
    without = RunAerocalAdjust(project, {"--no-snooping"});
  }
  state.counters["observations"] = static_cast<double>(project.observations.size());
  state.counters["adjust_exit_code"] = with.exit_code;
  if (!with.ok || !without.ok) {
    state.SkipWithError("aerocal adjust failed");
    return;
  }
  state.counters["adjust_s"] = with.seconds;
  state.counters["adjust_iterations"] = with.iterations;  // the final solve's
  state.counters["adjust_no_snooping_iterations"] = without.iterations;
  state.counters["adjust_cpu_s"] = with.cpu_seconds;
  state.counters["adjust_peak_rss_mb"] = with.peak_rss_mb;
  state.counters["points"] = static_cast<double>(project.points.size());
  state.counters["adjust_no_snooping_s"] = without.seconds;
  state.counters["adjust_no_snooping_cpu_s"] = without.cpu_seconds;
  state.counters["snooping_share"] = 1.0 - without.seconds / with.seconds;
  state.counters["snooping_share_cpu"] = 1.0 - without.cpu_seconds / with.cpu_seconds;
  const ColmapRun colmap = RunColmap(project);
  if (colmap.ok) {
    state.counters["colmap_s"] = colmap.seconds;
    state.counters["colmap_cpu_s"] = colmap.cpu_seconds;
    state.counters["ratio_aerocal_over_colmap"] = with.seconds / colmap.seconds;
    state.counters["ratio_cpu_aerocal_over_colmap"] = with.cpu_seconds / colmap.cpu_seconds;
    state.counters["colmap_iterations"] = colmap.iterations;
    state.counters["colmap_s_per_iteration"] = colmap.seconds / std::max(1, colmap.iterations);
    state.counters["colmap_peak_rss_mb"] = colmap.peak_rss_mb;
  } else {
    state.SetLabel("colmap missing (apt-get install colmap) or failed: no ratio");
  }
}
BENCHMARK(BM_AdjustDefaults)
    ->Arg(150)
    ->Arg(600)
    ->Arg(2400)
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

// issue 9's large block: `aerocal simulate --exposures N --strips S` (tie and surveyed point
// densities of SimulateBlock: 16 tie points and 2 surveyed points per exposure, one control point
// per 20 exposures), then `aerocal adjust` with its DEFAULT options (snooping and covariance on) in
// a child process. Target at 10,000 / 40: < 15 min and < 16 GiB. Counters: adjust_s, adjust_cpu_s,
// adjust_peak_rss_mb, the stages from the result's `timing` (solve_s, snooping_s, testing_s,
// covariance_s), snooping_share (snooping_s / total_s), observations, exit code.
// Run: /work/bin/cpu-long build/tests/bench/bench_triangulation
//      --benchmark_filter=BM_AdjustLargeSimulated
void BM_AdjustLargeSimulated(benchmark::State& state) {
  const int exposures = static_cast<int>(state.range(0)), strips = static_cast<int>(state.range(1));
  testing::TempDir dir("aerocal_bench_large");
  const std::string simulate = testing::AerocalBinary() + " simulate --exposures " +
                               std::to_string(exposures) + " --strips " + std::to_string(strips) +
                               " --tie-points " + std::to_string(16 * exposures) +
                               " --surveyed-points " + std::to_string(2 * exposures) +
                               " --control " + std::to_string(exposures / 20) +
                               " --stitch-ties 0 --out " + dir.File("block") + " > /dev/null";
  if (std::system(simulate.c_str()) != 0) {
    state.SkipWithError("aerocal simulate failed");
    return;
  }
  CliRun run;
  for (auto _ : state)
    run = RunAdjustCli(dir.File("block/project.yaml"), dir.File("result.json"), {});
  state.counters["adjust_exit_code"] = run.exit_code;
  if (!run.ok) {
    state.SkipWithError("aerocal adjust failed");
    return;
  }
  state.counters["adjust_s"] = run.seconds;
  state.counters["adjust_cpu_s"] = run.cpu_seconds;
  state.counters["adjust_peak_rss_mb"] = run.peak_rss_mb;
  const nlohmann::json result = testing::ReadJson(dir.File("result.json"));
  state.counters["observations"] = result.value("n_observations", 0.0);
  const nlohmann::json timing = result.value("timing", nlohmann::json::object());
  for (const char* key : {"solve_s", "snooping_s", "testing_s", "covariance_s", "total_s"})
    state.counters[key] = timing.value(key, 0.0);
  const double total = timing.value("total_s", 0.0);
  if (total > 0) state.counters["snooping_share"] = timing.value("snooping_s", 0.0) / total;
  state.counters["valid"] = result.value("valid", false);
}
BENCHMARK(BM_AdjustLargeSimulated)
    ->Args({10000, 40})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

void BM_DbatRoma(benchmark::State& state) {
  const std::string dir = testing::SharedDataDir("dbat_roma_canon_eos5d");
  if (dir.empty()) {
    state.SkipWithError("../shared/data/dbat_roma_canon_eos5d is absent");
    return;
  }
  DbatImportOptions in;
  in.camera_xml = dir + "/cameras/EOS5DMarkII.xml";
  in.marks = dir + "/measurements/markpts.txt";
  in.images = dir + "/images/images.txt";
  in.initial_eo = dir + "/prior/initial_eo.txt";
  const Project project = ImportDbat(in);
  AdjustOptions options;
  options.free_interior = ParseSelfCalibration("c,x0,y0,K1,K2");
  options.data_snooping = false;
  Compare(state, project, options, "c,x0,y0,K1,K2", 24.5425);  // published c (DBAT)
}
BENCHMARK(BM_DbatRoma)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
}  // namespace aerocal::triangulation

BENCHMARK_MAIN();
