// aerocal batch: a flight split into work units that run anywhere a shard index is set (one
// process, GNU Parallel, a Slurm job array, a Kubernetes Indexed Job) and merged into exactly what
// `aerocal flight` writes. plan | run | status | merge | slurm; the files in
// tools/batch_manifest.h.
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "stitch/io/frame_run_json.h"
#include "stitch/simulation/stitch_simulator.h"
#include "tools/batch_manifest.h"
#include "tools/batch_slurm.h"
#include "tools/batch_units.h"
#include "tools/command_registry.h"
#include "tools/option_ranges.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <unistd.h>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;

// A unit id from a frame id: letters, digits, '-', '_' and '.' kept, anything else '_'; made
// unique with the frame's index where two frames would share one.
std::string UnitId(const std::string& frame,
                   size_t index,
                   const std::map<std::string, int>& taken) {
  std::string id = "stitch-";
  for (char c : frame)
    id +=
        (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return taken.count(id) ? id + "-" + std::to_string(index) : id;
}

// Memory of one frame's stitching (four candidate models, dense normal equations of the mapping
// and tie unknowns) and of the merge (the flight's adjustments in one process), from the rows of
// stitching measurements: estimates for the scheduler, above the measured peak resident memory
// (/usr/bin/time, tools/README.md "Batch"): a unit of 430 rows 65 MB, of 1,900 rows 76 MB (nearly
// all of it the executable and its libraries); the merge of 5,195 rows 134 MB, of 70,300 rows
// 381 MB (the default simulated flight).
int UnitMemoryMb(size_t rows) { return 96 + static_cast<int>(rows / 100); }
int MergeMemoryMb(size_t rows) { return 512 + static_cast<int>(rows / 200); }

int Plan(const std::string& work, const std::vector<std::string>& flight_arguments) {
  CheckOutputFolder(work, "--work");
  const auto flight = ParseFlightArguments(flight_arguments);
  const triangulation::FlightStitching stitching =
      triangulation::ReadFlightStitching(flight->options);
  BatchManifest m;
  m.work = fs::absolute(work).string();
  m.directory = fs::current_path().string();
  m.version = AEROCAL_VERSION;
  m.flight_arguments = flight_arguments;
  std::map<std::string, std::vector<stitch::StitchObservation>> rows;
  for (const auto& row : stitching.rows) rows[row.frame].push_back(row);
  std::map<std::string, int> taken;
  for (size_t i = 0; i < stitching.frames.size(); ++i) {
    const std::string& frame = stitching.frames[i].frame;
    BatchUnit unit{UnitId(frame, i, taken), frame, UnitMemoryMb(rows[frame].size())};
    taken[unit.id] = 1;
    stitch::WriteStitchObservations(m.Input(unit), rows[frame], /*exact=*/true);
    m.units.push_back(unit);
  }
  m.merge_memory_mb = MergeMemoryMb(stitching.rows.size());
  WriteManifest(m);
  std::printf(
      "planned %zu units (one per exposure: stitching with the model choice) in %s/manifest.json\n",
      m.units.size(),
      m.work.c_str());
  return kExitOk;
}

// "K/N" with 0 <= K < N.
std::pair<int, int> ParseShard(const std::string& text) {
  int k = -1, n = 0;
  char slash = 0, rest = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &k, &slash, &n, &rest) != 3 || slash != '/' || n < 1 ||
      k < 0 || k >= n)
    throw ConfigError("--shard: expected K/N with 0 <= K < N (got '" + text + "')");
  return {k, n};
}

// The `flight` options given to `batch plan`, as arguments `flight` parses again (a flag by its
// name, once per use; an option by its name and each value as given).
std::vector<std::string> FlightArgumentsGiven(const CLI::App& plan) {
  std::vector<std::string> arguments;
  for (const CLI::Option* option : plan.get_options()) {
    if (option->count() == 0 || option->get_name() == "--work" || option->get_lnames().empty())
      continue;
    const std::string name = "--" + option->get_lnames().front();
    if (option->get_expected_min() == 0) {
      for (size_t i = 0; i < option->count(); ++i) arguments.push_back(name);
      continue;
    }
    for (const std::string& value : option->results()) {
      arguments.push_back(name);
      arguments.push_back(value);
    }
  }
  return arguments;
}

struct RunArgs {
  std::string manifest, shard;
  std::vector<std::string> units;
};

int Run(const RunArgs& args) {
  const BatchManifest m = ReadManifest(args.manifest);
  EnterPlanDirectory(m);
  const UnitContext context = MakeUnitContext(*ParseFlightArguments(m.flight_arguments));
  std::vector<const BatchUnit*> selected;
  if (!args.units.empty()) {
    if (!args.shard.empty()) throw ConfigError("--unit and --shard: give one");
    for (const std::string& id : args.units) selected.push_back(&m.Find(id));
  } else {
    const auto [k, n] = args.shard.empty() ? std::pair<int, int>{0, 1} : ParseShard(args.shard);
    for (size_t i = k; i < m.units.size(); i += n) selected.push_back(&m.units[i]);
  }
  int ran = 0, skipped = 0, failed = 0, exit_code = kExitOk;
  Progress progress("batch run", static_cast<long>(selected.size()));
  for (const BatchUnit* unit : selected) {
    const std::string hash = UnitInputHash(context, m, *unit);
    if (ReadUnitRecord(m, *unit, hash).state == UnitState::kDone) {
      ++skipped;
    } else {
      std::string error;
      bool input_error = false;
      if (RunUnit(context, m, *unit, hash, &error, &input_error)) {
        ++ran;
      } else {
        ++failed;
        exit_code = std::max(exit_code, input_error ? kExitBadInput : kExitInternal);
        std::fprintf(stderr,
                     "\nunit %s failed: %s (log %s)\n",
                     unit->id.c_str(),
                     error.c_str(),
                     m.Log(*unit).c_str());
      }
    }
    progress.Advance();
  }
  progress.Finish();
  std::printf("%s: %zu units: %d run, %d already done, %d failed\n",
              args.shard.empty() ? (args.units.empty() ? "all" : "--unit")
                                 : ("shard " + args.shard).c_str(),
              selected.size(),
              ran,
              skipped,
              failed);
  return exit_code;
}

int Status(const std::string& path, bool list) {
  const BatchManifest m = ReadManifest(path);
  EnterPlanDirectory(m);
  const UnitContext context = MakeUnitContext(*ParseFlightArguments(m.flight_arguments));
  std::map<UnitState, int> count;
  double first_start = 0, last_finish = 0;
  std::vector<std::string> failures;
  for (const BatchUnit& unit : m.units) {
    const UnitRecord r = ReadUnitRecord(m, unit, UnitInputHash(context, m, unit));
    ++count[r.state];
    if (r.state == UnitState::kDone) {
      first_start = first_start == 0 ? r.started : std::min(first_start, r.started);
      last_finish = std::max(last_finish, r.finished);
    }
    if (r.state == UnitState::kFailed)
      failures.push_back(unit.id + ": " + r.error + " (log " + m.Log(unit) + ")");
    if (list)
      std::printf(
          "%-30s %-8s frame %s\n", unit.id.c_str(), UnitStateName(r.state), unit.frame.c_str());
  }
  const int total = static_cast<int>(m.units.size()), done = count[UnitState::kDone];
  std::printf("%d units: %d done, %d changed since done, %d failed, %d missing (%.0f %% done)\n",
              total,
              done,
              count[UnitState::kChanged],
              count[UnitState::kFailed],
              count[UnitState::kMissing],
              total ? 100.0 * done / total : 100.0);
  // The rate over the wall time the done units span: with several shards at work, the batch's.
  if (done > 0 && last_finish > first_start) {
    const double rate = done / (last_finish - first_start);
    std::printf(
        "rate %.3g units/s (the done units from first start to last finish); %d left: ETA %.0f s "
        "at "
        "that rate\n",
        rate,
        total - done,
        (total - done) / rate);
  }
  for (const std::string& f : failures) std::printf("failed %s\n", f.c_str());
  if (done == total)
    std::printf("all units done: `aerocal batch merge --manifest %s`\n", path.c_str());
  return kExitOk;
}

int Merge(const std::string& path) {
  const BatchManifest m = ReadManifest(path);
  EnterPlanDirectory(m);
  const auto flight = ParseFlightArguments(m.flight_arguments);
  const UnitContext context = MakeUnitContext(*flight);
  std::vector<stitch::FrameRun> runs;
  std::vector<std::string> not_done;
  for (const BatchUnit& unit : m.units) {
    const UnitState state = ReadUnitRecord(m, unit, UnitInputHash(context, m, unit)).state;
    if (state != UnitState::kDone) {
      not_done.push_back(unit.id + " (" + UnitStateName(state) + ")");
      continue;
    }
    runs.push_back(stitch::FrameRunFromJson(nlohmann::json::parse(ReadTextFile(m.Output(unit))),
                                            m.Output(unit)));
  }
  if (!not_done.empty()) {
    std::string names;
    for (size_t i = 0; i < not_done.size() && i < 10; ++i) names += (i ? ", " : "") + not_done[i];
    throw InputError(path + ": " + std::to_string(not_done.size()) + " of " +
                     std::to_string(m.units.size()) + " units are not done: " + names +
                     (not_done.size() > 10 ? ", ..." : "") +
                     " (`aerocal batch run` finishes them; `aerocal batch status` lists them)");
  }
  if (!m.units.empty()) flight->options.stitched_frames = &runs;
  return RunFlight(*flight);
}

// The executable the scheduler's jobs run: this one, by its absolute path.
std::string ThisExecutable() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("aerocal") : self.string();
}

// Adds `batch slurm`; returns its run.
std::function<int()> AddSlurm(CLI::App& batch) {
  auto manifest = std::make_shared<std::string>();
  auto o = std::make_shared<SlurmOptions>();
  CLI::App* s =
      batch.add_subcommand("slurm",
                           "Write the Slurm job scripts: the units as a job array, the merge "
                           "as a job depending on it, submit.sh");
  s->option_defaults()->always_capture_default();
  s->add_option("--manifest", *manifest, "manifest.json of `batch plan`")->required();
  s->add_option("--shards", o->shards, "Array tasks N (task ID runs shard ID/N), 1..100000")
      ->check(FiniteRange(1, 100000))
      ->required();
  s->add_option("--max-running",
                o->max_running,
                "Tasks running at once (--array=0-(N-1)%K); 0: no limit, 0..100000")
      ->check(FiniteRange(0, 100000));
  s->add_option("--partition", o->partition, "Slurm partition (default: the cluster's)");
  s->add_option("--time", o->time_limit, "Time limit of a task, Slurm's format (e.g. 01:00:00)");
  s->add_option("--account", o->account, "Slurm account");
  s->add_option("--aerocal", o->aerocal, "The aerocal the jobs run (default: this one)");
  s->add_option("--out", o->out, "Output folder: units.sbatch, merge.sbatch, submit.sh")
      ->required();
  return [manifest, o] {
    CheckOutputFolder(o->out, "--out");
    if (o->aerocal.empty()) o->aerocal = ThisExecutable();
    const BatchManifest m = ReadManifest(*manifest);
    WriteSlurmScripts(m, *manifest, *o);
    std::printf("wrote %s/units.sbatch (--array=0-%d%s), merge.sbatch, submit.sh\n",
                o->out.c_str(),
                o->shards - 1,
                o->max_running > 0 ? ("%" + std::to_string(o->max_running)).c_str() : "");
    return kExitOk;
  };
}

CommandRun Setup(CLI::App& app) {
  app.require_subcommand(1);
  auto work = std::make_shared<std::string>();
  auto flight = std::make_shared<FlightArgs>();
  CLI::App* plan =
      app.add_subcommand("plan",
                         "Write the manifest of a flight's units; the other options are "
                         "those of `aerocal flight` (its --out: where the merge writes)");
  plan->option_defaults()->always_capture_default();
  plan->add_option("--work",
                   *work,
                   "Work folder on storage every node shares: manifest.json, units/, done/, logs/")
      ->required();
  AddFlightOptions(*plan, flight);

  auto run = std::make_shared<RunArgs>();
  CLI::App* r =
      app.add_subcommand("run",
                         "Run units: a shard K/N (units K, K+N, ...), named units, or all; "
                         "done units are skipped");
  r->add_option("--manifest", run->manifest, "manifest.json of `batch plan`")->required();
  r->add_option("--shard",
                run->shard,
                "K/N: this process's share (0 <= K < N), e.g. ${SLURM_ARRAY_TASK_ID}/64");
  r->add_option("--unit", run->units, "A unit id (repeatable)");

  auto status = std::make_shared<std::string>();
  auto list = std::make_shared<bool>(false);
  CLI::App* st =
      app.add_subcommand("status", "Units done / changed / failed / missing, rate and ETA");
  st->add_option("--manifest", *status, "manifest.json of `batch plan`")->required();
  st->add_flag("--list", *list, "One line per unit");

  auto merge = std::make_shared<std::string>();
  CLI::App* mg =
      app.add_subcommand("merge",
                         "What needs all frames: the flight's stability, adjustments, "
                         "result.json, camera and report, as `aerocal flight` writes them");
  mg->add_option("--manifest", *merge, "manifest.json of `batch plan`")->required();
  const std::function<int()> slurm = AddSlurm(app);
  // Run after parsing (main catches the errors there), the one sub-command given.
  return [=] {
    if (plan->parsed()) return Plan(*work, FlightArgumentsGiven(*plan));
    if (r->parsed()) return Run(*run);
    if (st->parsed()) return Status(*status, *list);
    if (mg->parsed()) return Merge(*merge);
    return slurm();
  };
}

}  // namespace

AEROCAL_REGISTER_COMMAND(
    batch,
    "batch",
    "A flight as units on a cluster: plan, run --shard K/N, status, merge, slurm",
    Setup);

}  // namespace aerocal::tools
