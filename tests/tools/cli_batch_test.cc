// `aerocal batch` (issue 35) on a simulated 12-exposure flight: plan + run (in shards, in one
// process, under GNU Parallel) + merge writes the same result.json (to the last bit, the clock's
// timings aside; with --residuals-csv its tables read back) and the same camera_calibrated.yaml
// (byte for byte) as `aerocal flight`; a run killed midway and a rerun finish only what is
// missing; a changed input is redone, a failing unit leaves its log, a failed record and no
// output, and the merge refuses to run without every unit.
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"
#include "tools/observation_tables.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <string>

namespace aerocal {
namespace {

namespace fs = std::filesystem;

class Batch : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir("aerocal_batch");
    const auto sim = testing::RunAerocal(
        "simulate --out " + dir_->File("data") +
        " --seed 3 --exposures 12 --strips 2 --stitch-ties 200 --gnss-sigma-m 0.05");
    ASSERT_EQ(sim.exit_code, 0) << sim.output;
    const auto flight = testing::RunAerocal("flight " + FlightArguments("single"));
    ASSERT_EQ(flight.exit_code, 0) << flight.output;
  }
  static void TearDownTestSuite() { delete dir_; }

  static std::string FlightArguments(const std::string& out) {
    return "--camera " + dir_->File("data/camera_nominal.yaml") + " --data " + dir_->File("data") +
           " --base III,IV --no-report --out " + dir_->File(out);
  }
  // `batch plan` of the flight (and `extra` flight options) into WORK whose merge writes OUT.
  static std::string Plan(const std::string& work,
                          const std::string& out,
                          const std::string& extra = "") {
    const auto r = testing::RunAerocal("batch plan --work " + dir_->File(work) + " " +
                                       FlightArguments(out) + extra);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return dir_->File(work + "/manifest.json");
  }
  static testing::CommandResult Batch_(const std::string& arguments) {
    return testing::RunAerocal("batch " + arguments);
  }
  static void ExpectTheFlightsFiles(const std::string& out) {
    std::string result = dir_->File(out + "/result.json");
    ASSERT_TRUE(fs::exists(result)) << out;
    EXPECT_EQ(ReadTextFile(dir_->File(out + "/camera_calibrated.yaml")),
              ReadTextFile(dir_->File("single/camera_calibrated.yaml")));
    if (fs::exists(dir_->File(out + "/residuals_stitching.csv"))) {
      // `--residuals-csv`: the tables beside it read back into the arrays first.
      nlohmann::json document = testing::ReadJson(result);
      tools::InflateResidualTables(&document, result);
      result = dir_->File(out + "_inflated.json");
      WriteFileAtomically(result, document.dump());
    }
    EXPECT_TRUE(testing::ResultWithoutClock(result) ==
                testing::ResultWithoutClock(dir_->File("single/result.json")))
        << out << "/result.json differs from the single-process flight's";
  }
  static int DoneRecords(const std::string& work) {
    int n = 0;
    if (fs::exists(dir_->File(work + "/done")))
      for (const auto& e : fs::directory_iterator(dir_->File(work + "/done")))
        n += e.path().extension() == ".json";  // not a record's temporary file left by the kill
    return n;
  }
  static testing::TempDir* dir_;
};
testing::TempDir* Batch::dir_ = nullptr;

TEST_F(Batch, ShardsThenMergeGiveTheFlightsFiles) {
  // The merge writes the flight's residual tables beside result.json (issue 33): read back, the
  // single-process flight's arrays.
  const std::string manifest = Plan("work", "merged", " --residuals-csv");
  EXPECT_EQ(testing::ReadJson(manifest)["units"].size(), 12u);
  // The merge needs every unit: refused (exit 2, the missing ones named), nothing written.
  auto merge = Batch_("merge --manifest " + manifest);
  EXPECT_EQ(merge.exit_code, 2) << merge.output;
  EXPECT_NE(merge.output.find("12 of 12 units are not done"), std::string::npos) << merge.output;
  EXPECT_FALSE(fs::exists(dir_->File("merged")));
  for (const char* shard : {"0/3", "1/3", "2/3"}) {
    const auto r = Batch_("run --manifest " + manifest + " --shard " + shard);
    ASSERT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("4 units: 4 run, 0 already done, 0 failed"), std::string::npos)
        << r.output;
  }
  const auto status = Batch_("status --manifest " + manifest + " --list");
  EXPECT_NE(status.output.find("stitch-0007"), std::string::npos)
      << status.output;  // --list: one line per unit
  EXPECT_NE(status.output.find("12 units: 12 done, 0 changed since done, 0 failed, 0 missing"),
            std::string::npos)
      << status.output;
  EXPECT_NE(status.output.find("units/s"), std::string::npos) << status.output;
  merge = Batch_("merge --manifest " + manifest);
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  for (const char* table : {"stitching", "conventional", "self_calibration", "joint"})
    EXPECT_TRUE(fs::exists(dir_->File("merged/residuals_" + std::string(table) + ".csv"))) << table;
  ExpectTheFlightsFiles("merged");
}

// A run killed at a random point (SIGKILL, no chance to clean up) leaves finished units done and
// nothing else: the rerun runs exactly the others, and the merge is the flight's.
TEST_F(Batch, KilledRunAndRerunFinishOnlyWhatIsMissing) {
  const std::string manifest = Plan("killed", "killed_out");
  const auto killed = testing::RunCommand("timeout -s KILL 0.3 " + testing::AerocalBinary() +
                                          " batch run --manifest " + manifest);
  const int done = DoneRecords("killed");
  std::printf("killed after %d of 12 units (exit %d)\n", done, killed.exit_code);
  const auto rerun = Batch_("run --manifest " + manifest);
  ASSERT_EQ(rerun.exit_code, 0) << rerun.output;
  EXPECT_NE(rerun.output.find("12 units: " + std::to_string(12 - done) + " run, " +
                              std::to_string(done) + " already done"),
            std::string::npos)
      << rerun.output;
  // A unit killed while writing: its output's temporary file and no done record (deterministic).
  const std::string unit = dir_->File("killed/units/stitch-0005/frame_run.json");
  fs::remove(dir_->File("killed/done/stitch-0005.json"));
  WriteFileAtomically(unit + ".tmp99999", "{\"adjustment\": {\"fra");
  EXPECT_NE(Batch_("status --manifest " + manifest)
                .output.find("11 done, 0 changed since done, 0 failed, 1 missing"),
            std::string::npos);
  const auto again = Batch_("run --manifest " + manifest);
  EXPECT_NE(again.output.find("12 units: 1 run, 11 already done"), std::string::npos)
      << again.output;
  EXPECT_FALSE(fs::exists(unit + ".tmp99999"));
  const auto merge = Batch_("merge --manifest " + manifest);
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  ExpectTheFlightsFiles("killed_out");
}

// A unit whose input changed is run again (its done record names other inputs); a unit that
// fails leaves a log and a failed record, and the merge refuses until it is done.
TEST_F(Batch, ChangedInputIsRedoneAndAFailureIsRecorded) {
  const std::string manifest = Plan("changed", "changed_out");
  ASSERT_EQ(Batch_("run --manifest " + manifest).exit_code, 0);
  const std::string input = dir_->File("changed/units/stitch-0003/input.csv");
  const std::string original = ReadTextFile(input);
  // Another sigma_px on the first measurement: the unit's inputs changed.
  std::string changed = original;
  const size_t row_end = changed.find('\n', changed.find('\n') + 1);
  const size_t sigma = changed.rfind(',', row_end) + 1;
  changed.replace(sigma, row_end - sigma, "0.2");
  WriteFileAtomically(input, changed);
  auto status = Batch_("status --manifest " + manifest);
  EXPECT_NE(status.output.find("11 done, 1 changed since done"), std::string::npos)
      << status.output;
  auto run = Batch_("run --manifest " + manifest);
  EXPECT_NE(run.output.find("12 units: 1 run, 11 already done"), std::string::npos) << run.output;
  // A sub-image the camera lacks: the unit fails with the reason, a failed record and its log.
  std::string bad = original;
  bad.replace(bad.find(",I,"), 3, ",XI,");
  WriteFileAtomically(input, bad);
  const auto failed = Batch_("run --manifest " + manifest + " --unit stitch-0003");
  EXPECT_EQ(failed.exit_code, 2) << failed.output;
  EXPECT_NE(failed.output.find("sub-image 'XI' is not in the camera"), std::string::npos)
      << failed.output;
  EXPECT_TRUE(fs::exists(dir_->File("changed/failed/stitch-0003.json")));
  EXPECT_NE(ReadTextFile(dir_->File("changed/logs/stitch-0003.log")).find("failed: "),
            std::string::npos);
  status = Batch_("status --manifest " + manifest);
  EXPECT_NE(status.output.find("11 done, 0 changed since done, 1 failed"), std::string::npos)
      << status.output;
  EXPECT_NE(status.output.find("failed stitch-0003: "), std::string::npos) << status.output;
  const auto merge = Batch_("merge --manifest " + manifest);
  EXPECT_EQ(merge.exit_code, 2) << merge.output;
  EXPECT_NE(merge.output.find("stitch-0003 (failed)"), std::string::npos) << merge.output;
  EXPECT_FALSE(fs::exists(dir_->File("changed_out")));
  // The planned input back: the unit runs once more and the merge is the flight's again.
  WriteFileAtomically(input, original);
  run = Batch_("run --manifest " + manifest);
  EXPECT_NE(run.output.find("12 units: 1 run, 11 already done, 0 failed"), std::string::npos)
      << run.output;
  ASSERT_EQ(Batch_("merge --manifest " + manifest).exit_code, 0);
  ExpectTheFlightsFiles("changed_out");
}

TEST_F(Batch, BadShardAndUnitAreRefusedByName) {
  const std::string manifest = Plan("bad", "bad_out");
  for (const char* shard : {"3/3", "-1/2", "1", "a/b", "1/0"}) {
    const auto r = Batch_("run --manifest " + manifest + " --shard " + shard);
    EXPECT_EQ(r.exit_code, 2) << shard;
    EXPECT_NE(r.output.find("--shard"), std::string::npos) << r.output;
  }
  const auto r = Batch_("run --manifest " + manifest + " --unit nope");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("--unit: no unit 'nope'"), std::string::npos) << r.output;
  const auto plan =
      testing::RunAerocal("batch plan --work " + dir_->File("bad2") + " --camera " +
                          dir_->File("data/camera_nominal.yaml") + " --data " + dir_->File("data"));
  EXPECT_EQ(plan.exit_code, 2) << plan.output;  // the flight's options as `flight` checks them
  EXPECT_NE(plan.output.find("--out is required"), std::string::npos) << plan.output;
  EXPECT_FALSE(fs::exists(dir_->File("bad2")));
}

// The README's GNU Parallel line: shards as parallel jobs, then the merge.
TEST_F(Batch, GnuParallelGivesTheFlightsFiles) {
  if (testing::RunCommand("command -v parallel").exit_code != 0)
    GTEST_SKIP()
        << "GNU Parallel is not installed (apt-get install parallel; tools/setup.sh installs it)";
  const std::string manifest = Plan("parallel", "parallel_out");
  const auto r = testing::RunCommand("parallel --will-cite -j 2 --halt now,fail=1 " +
                                     testing::AerocalBinary() + " batch run --manifest " +
                                     manifest + " --shard {}/4 ::: 0 1 2 3");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto merge = Batch_("merge --manifest " + manifest);
  ASSERT_EQ(merge.exit_code, 0) << merge.output;
  ExpectTheFlightsFiles("parallel_out");
}

TEST_F(Batch, SlurmScriptsNameTheArrayShardsAndTheDependentMerge) {
  const std::string manifest = Plan("slurm_work", "slurm_out");
  const auto r = Batch_("slurm --manifest " + manifest +
                        " --shards 4 --max-running 2 --partition p1 --time 01:00:00 "
                        "--account a1 --aerocal /opt/aerocal/bin/aerocal --out " +
                        dir_->File("slurm"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string units = ReadTextFile(dir_->File("slurm/units.sbatch"));
  for (const char* line : {"#SBATCH --array=0-3%2",
                           "#SBATCH --partition=p1",
                           "#SBATCH --time=01:00:00",
                           "#SBATCH --account=a1",
                           "exec '/opt/aerocal/bin/aerocal' batch run",
                           "--shard \"${SLURM_ARRAY_TASK_ID}/4\""})
    EXPECT_NE(units.find(line), std::string::npos) << line << "\n" << units;
  EXPECT_NE(ReadTextFile(dir_->File("slurm/merge.sbatch")).find("batch merge --manifest"),
            std::string::npos);
  EXPECT_NE(ReadTextFile(dir_->File("slurm/submit.sh")).find("--dependency=afterok:$array"),
            std::string::npos);
}

}  // namespace
}  // namespace aerocal
