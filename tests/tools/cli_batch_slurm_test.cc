// `aerocal batch slurm` for real (issue 35): a one-node Slurm cluster on this machine
// (tests/tools/slurm_localhost.sh: munged, slurmctld, slurmd), the written submit.sh sends a
// 4-task job array over a simulated 12-exposure flight and the merge as a dependent job; the
// merged files equal `aerocal flight`'s (result.json to the last bit, the clock's timings aside;
// the camera byte for byte). Units made missing afterwards are all a resubmission runs. Skipped
// with the reason when Slurm or munge is not installed or the cluster does not come up.
#include "calib/core/atomic_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <unistd.h>

namespace aerocal {
namespace {

namespace fs = std::filesystem;

const std::string kScript = std::string(AEROCAL_TEST_DATA_DIR) + "/../tools/slurm_localhost.sh";

class SlurmBatch : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto start = testing::RunCommand("bash " + kScript + " start " + dir_.File("cluster"));
    if (start.exit_code == 77) GTEST_SKIP() << start.output;
    ASSERT_EQ(start.exit_code, 0) << start.output;
    started_ = true;
    setenv("SLURM_CONF", dir_.File("cluster/slurm.conf").c_str(), 1);
  }
  void TearDown() override {
    if (started_) testing::RunCommand("bash " + kScript + " stop " + dir_.File("cluster"));
  }
  std::string Flight(const std::string& out) const {
    return "--camera " + dir_.File("data/camera_nominal.yaml") + " --data " + dir_.File("data") +
           " --base III,IV --no-report --out " + dir_.File(out);
  }
  // Submits the scripts and waits until the queue is empty (at most `seconds`).
  void SubmitAndWait(int seconds) {
    const auto submit = testing::RunCommand(dir_.File("slurm/submit.sh"));
    ASSERT_EQ(submit.exit_code, 0) << submit.output;
    std::printf("%s", submit.output.c_str());
    for (int i = 0; i < seconds; ++i) {
      std::this_thread::sleep_for(std::chrono::seconds(1));
      const auto queue = testing::RunCommand("squeue -h");
      if (queue.exit_code == 0 && queue.output.empty()) return;
    }
    FAIL() << "the jobs did not finish within " << seconds
           << " s: " << testing::RunCommand("squeue").output;
  }
  void ExpectTheFlightsFiles() {
    ASSERT_TRUE(fs::exists(dir_.File("merged/result.json")))
        << testing::RunCommand("cat " + dir_.File("work/logs") + "/slurm-*.out").output;
    EXPECT_EQ(ReadTextFile(dir_.File("merged/camera_calibrated.yaml")),
              ReadTextFile(dir_.File("single/camera_calibrated.yaml")));
    EXPECT_TRUE(testing::ResultWithoutClock(dir_.File("merged/result.json")) ==
                testing::ResultWithoutClock(dir_.File("single/result.json")));
  }
  testing::TempDir dir_{"aerocal_slurm"};
  bool started_ = false;
};

TEST_F(SlurmBatch, JobArrayAndDependentMergeGiveTheFlightsFiles) {
  ASSERT_EQ(testing::RunAerocal(
                "simulate --out " + dir_.File("data") +
                " --seed 3 --exposures 12 --strips 2 --stitch-ties 200 --gnss-sigma-m 0.05")
                .exit_code,
            0);
  ASSERT_EQ(testing::RunAerocal("flight " + Flight("single")).exit_code, 0);
  ASSERT_EQ(testing::RunAerocal("batch plan --work " + dir_.File("work") + " " + Flight("merged"))
                .exit_code,
            0);
  const std::string manifest = dir_.File("work/manifest.json");
  const auto scripts =
      testing::RunAerocal("batch slurm --manifest " + manifest +
                          " --shards 4 --max-running 2 --out " + dir_.File("slurm"));
  ASSERT_EQ(scripts.exit_code, 0) << scripts.output;
  SubmitAndWait(300);
  ExpectTheFlightsFiles();
  for (int task = 0; task < 4; ++task)  // each task ran its three units
    EXPECT_NE(testing::RunCommand("cat " + dir_.File("work/logs") + "/slurm-*_" +
                                  std::to_string(task) + ".out")
                  .output.find("3 units: 3 run, 0 already done, 0 failed"),
              std::string::npos);

  // Three units lost (their done records gone, as if their tasks had been killed), the merged
  // files removed: the resubmitted array runs only those, the merge gives the same files again.
  for (const char* unit : {"stitch-0002", "stitch-0007", "stitch-0011"})
    fs::remove(dir_.File(std::string("work/done/") + unit + ".json"));
  fs::remove_all(dir_.File("merged"));
  for (const auto& log : fs::directory_iterator(dir_.File("work/logs")))
    if (log.path().filename().string().rfind("slurm-", 0) == 0) fs::remove(log.path());
  SubmitAndWait(300);
  ExpectTheFlightsFiles();
  const auto logs = testing::RunCommand("cat " + dir_.File("work/logs") + "/slurm-*_*.out").output;
  EXPECT_NE(logs.find("3 units: 1 run, 2 already done"), std::string::npos) << logs;
  EXPECT_NE(logs.find("3 units: 0 run, 3 already done"), std::string::npos) << logs;
}

}  // namespace
}  // namespace aerocal
