// `aerocal rig stitch` on a line of `simulate --rig uav4`: the issue's keys (rig_exposures,
// stitching_rms_px before/after fit/check per_coordinate/pair_2d for the flight, each exposure and
// zone), increments within 3 sigma of the simulator's truth, the three modes (per-exposure names
// the dT-rotation correlations and writes no dT it cannot determine; angles holds dT), and exit 3
// by name: an absurd sigma0, a standard position the snooping would empty.
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/result_file.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

namespace aerocal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ReadJson;
using testing::RunAerocal;
using testing::TempDir;

// One simulated line of 3 exposures (seed 5), made once; each test copies it.
const std::string& Line() {
  static TempDir dir("aerocal_rig_stitch_line");
  static const std::string path = dir.File("uav4");
  static const bool made = [] {
    const auto r = RunAerocal("simulate --rig uav4 --exposures 3 --seed 5 --out " + path);
    EXPECT_EQ(r.exit_code, 0) << r.output;
    return true;
  }();
  (void)made;
  return path;
}

std::string Stitch(const std::string& line, const std::string& extra, const std::string& out) {
  return "rig stitch --camera " + line + "/rig_truth.yaml --project " + line + " " + extra +
         " --out " + out;
}

// truth/rig_exposures.csv: (image, head) -> domega, dphi, dkappa (deg), dT_ms.
std::map<std::pair<std::string, std::string>, std::vector<double>> Truth(const std::string& line) {
  std::map<std::pair<std::string, std::string>, std::vector<double>> truth;
  std::istringstream in(ReadTextFile(line + "/truth/rig_exposures.csv"));
  std::string row;
  std::getline(in, row);  // header
  while (std::getline(in, row)) {
    const auto f = SplitCommaList(row, {true, true});
    truth[{f[0], f[1]}] = {std::stod(f[2]), std::stod(f[3]), std::stod(f[4]), std::stod(f[5])};
  }
  return truth;
}

void ExpectRms(const json& rms, const std::string& where) {
  for (const char* phase : {"before", "after"})
    for (const char* set : {"fit", "check"})
      for (const char* metric : {"per_coordinate", "pair_2d", "pairs", "ties"})
        EXPECT_TRUE(rms[phase][set].contains(metric))
            << where << " " << phase << " " << set << " " << metric;
}

TEST(RigStitchCommand, LineModeOnASimulatedLineWithTheIssueKeys) {
  TempDir dir;
  const auto run = RunAerocal(Stitch(Line(), "--relief-m 15 --dt-sigma-ms 20", dir.File("r.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("before -> after"), std::string::npos) << run.output;
  const json doc = ReadJson(dir.File("r.json"));
  EXPECT_EQ(doc["kind"], "rig_stitch");
  EXPECT_EQ(doc["schema_version"], ResultSchemaVersion("rig_stitch"));
  EXPECT_FALSE(doc["camera_models"].empty());
  EXPECT_EQ(doc["mode"], "line");
  EXPECT_TRUE(doc["converged"].get<bool>());
  EXPECT_TRUE(doc["valid"].get<bool>());
  const double r = doc["redundancy"].get<double>();
  EXPECT_NEAR(doc["sigma0"].get<double>(), 1.0, 3.0 / std::sqrt(2.0 * r) + 0.05);
  ExpectRms(doc["stitching_rms_px"], "flight");
  ASSERT_EQ(doc["exposures"].size(), 3u);
  for (const json& e : doc["exposures"]) {
    ExpectRms(e["stitching_rms_px"], e["image"]);
    EXPECT_GE(e["zones"].size(), 5u) << "AB AC AD BC CD (and the triple zones)";
  }
  const json& flight = doc["stitching_rms_px"];
  const double after = flight["after"]["fit"]["per_coordinate"].get<double>();
  // Tie noise 0.3 px; the metric carries two rays' noise (sqrt 2) at the tilted heads' scale.
  EXPECT_GT(flight["before"]["fit"]["per_coordinate"].get<double>(), 1.0);
  EXPECT_LT(after, 2.0 * 0.3);
  EXPECT_NEAR(flight["after"]["fit"]["pair_2d"].get<double>() / after, std::sqrt(2.0), 1e-9);
  EXPECT_LT(flight["after"]["check"]["per_coordinate"].get<double>(), 2.5 * 0.3);
  // rig_exposures: every exposure and head, increments within 3 sigma of the truth.
  const auto truth = Truth(Line());
  ASSERT_EQ(doc["rig_exposures"].size(), 12u);
  int outside = 0;
  for (const json& h : doc["rig_exposures"]) {
    const auto& t = truth.at({h["image"], h["head"]});
    if (h["reference"].get<bool>()) {
      EXPECT_TRUE(h["sigma"]["domega"].is_null()) << "held: no sigma, never 0";
      continue;
    }
    const char* angles[] = {"domega", "dphi", "dkappa"};
    for (int a = 0; a < 3; ++a)
      outside +=
          std::abs(h[angles[a]].get<double>() - t[a]) > 3 * h["sigma"][angles[a]].get<double>();
  }
  EXPECT_LE(outside, 1) << "of 27 angles beyond 3 sigma";
  EXPECT_FALSE(doc["time_offsets"]["held"].get<bool>());
  EXPECT_NEAR(doc["relief_displacement"]["relief_m"].get<double>(), 15.0, 0);
  EXPECT_GT(doc["relief_displacement"]["largest_px"].get<double>(), 0.0);
}

TEST(RigStitchCommand, PerExposureNamesTheCorrelationsAndAnglesHoldsTheOffsets) {
  TempDir dir;
  auto run = RunAerocal(Stitch(Line(), "--mode per-exposure --no-snooping", dir.File("p.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  json doc = ReadJson(dir.File("p.json"));
  double largest = 0.0;
  for (const json& c : doc["time_offsets"]["correlations"]) {
    EXPECT_EQ(c["dT"].get<std::string>().rfind("dT[", 0), 0u) << c;
    EXPECT_EQ(c["angle"].get<std::string>().rfind("E[", 0), 0u) << c;
    largest = std::max(largest, std::abs(c["rho"].get<double>()));
  }
  EXPECT_GT(largest, 0.9) << "a 2 ms offset at 10 m/s is nearly a rotation";
  EXPECT_EQ(doc["time_offsets"]["correlations"].size(), 9u) << "3 exposures x 3 heads";
  if (!doc["time_offsets"]["determinable"].get<bool>()) {
    int nulls = 0;
    for (const json& h : doc["rig_exposures"]) nulls += h["dT_ms"].is_null();
    EXPECT_GT(nulls, 0) << "no dT value the run cannot determine";
  }
  run = RunAerocal(Stitch(Line(),
                          "--mode angles --increment-sigma-arcsec 600 --alpha 0.01 --sigma-px 0.3",
                          dir.File("a.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  doc = ReadJson(dir.File("a.json"));
  EXPECT_EQ(doc["snooping"]["alpha"].get<double>(), 0.01);
  EXPECT_TRUE(doc["time_offsets"]["held"].get<bool>());
  for (const json& h : doc["rig_exposures"]) {
    EXPECT_EQ(h["dT_ms"].get<double>(), 0.0);
    EXPECT_TRUE(h["sigma"]["dT_ms"].is_null());
  }
}

// A tie observed but not listed in points.csv is a tie, as in the block adjustment (found by
// fuzz/cli: an id mangled in observations.csv ended in an internal error, map::at).
TEST(RigStitchCommand, AnObservedPointNotInPointsCsvIsATie) {
  TempDir dir;
  auto run = RunAerocal(Stitch(Line(), "", dir.File("listed.json")));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string line = dir.File("uav4");
  fs::copy(Line(), line, fs::copy_options::recursive);
  std::istringstream in(ReadTextFile(line + "/points.csv"));
  std::string text, row;
  int dropped = 0;
  while (std::getline(in, row)) {
    if (row.rfind("0001_t000,", 0) == 0) {
      ++dropped;
      continue;
    }
    text += row + "\n";
  }
  ASSERT_EQ(dropped, 1);
  std::ofstream(line + "/points.csv") << text;
  run = RunAerocal(Stitch(line, "", dir.File("unlisted.json")));
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const json listed = ReadJson(dir.File("listed.json")),
             unlisted = ReadJson(dir.File("unlisted.json"));
  EXPECT_NEAR(unlisted["sigma0"].get<double>(),
              listed["sigma0"].get<double>(),
              1e-9 * listed["sigma0"].get<double>());
}

TEST(RigStitchCommand, ExitThreeByNameForAnAbsurdSigma0AndAnEmptiedStandardPosition) {
  TempDir dir;
  auto run = RunAerocal(Stitch(Line(), "--max-sigma0 0.5", dir.File("s.json")));
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("sigma0"), std::string::npos) << run.output;
  EXPECT_FALSE(ReadJson(dir.File("s.json"))["valid"].get<bool>()) << "written, marked invalid";

  // The first standard position of exposure 0001 left with one tie (0001_t000, seen by A and B),
  // one of its two rays 12 px off: rejecting it would empty the position, so the run stops.
  const std::string line = dir.File("uav4");
  fs::copy(Line(), line, fs::copy_options::recursive);
  std::istringstream in(ReadTextFile(line + "/observations.csv"));
  std::string text, row;
  while (std::getline(in, row)) {
    if (row.find(",0001_t001,") != std::string::npos ||
        row.find(",0001_t002,") != std::string::npos)
      continue;
    if (row.rfind("0001,B,0001_t000,", 0) == 0) {
      auto f = SplitCommaList(row, {true, true});
      f[3] = std::to_string(std::stod(f[3]) + 12.0);
      row = f[0] + "," + f[1] + "," + f[2] + "," + f[3] + "," + f[4] + "," + f[5];
    }
    text += row + "\n";
  }
  std::ofstream(line + "/observations.csv") << text;
  const std::string stitch = "rig stitch --camera " + line + "/rig_truth.yaml --project " + line +
                             " --standard-radius-px 50 --out ";
  run = RunAerocal(stitch + dir.File("stop.json"));
  EXPECT_NE(run.output.find("standard position"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("of exposure 0001"), std::string::npos) << run.output;
  const json doc = ReadJson(dir.File("stop.json"));
  EXPECT_TRUE(doc["snooping"]["stopped"].get<bool>());
  for (const json& s : doc["snooping"]["standard_positions"])
    EXPECT_GE(s["ties_after"].get<int>(), 1) << s;
  // The stop is judged by its effect (issue 28 part 2): the increments and offsets re-estimated
  // without the kept ray. A 12 px error on one of the two rays of the position's only tie bends
  // its exposure's increments by more than their sigma: not valid, exit 3, the effect named.
  const json& effect = doc["snooping"]["stop_effect"];
  ASSERT_TRUE(effect["computed"].get<bool>()) << effect;
  const double sigmas = effect["max_sigmas"].get<double>();
  EXPECT_GT(sigmas, 1.0) << effect;
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("leaving them out moves " + effect["parameter"].get<std::string>()),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(doc["valid"].get<bool>());
  // The same stop under a limit above its effect: valid, exit 0, the warning names the effect;
  // the numbers are those of the first run (the effect leaves the solution as it was).
  run = RunAerocal(stitch + dir.File("lenient.json") + " --suspect-effect-limit " +
                   std::to_string(2.0 * sigmas));
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const json lenient = ReadJson(dir.File("lenient.json"));
  EXPECT_TRUE(lenient["valid"].get<bool>());
  EXPECT_EQ(lenient["snooping"]["stop_effect"]["max_sigmas"], effect["max_sigmas"]);
  EXPECT_EQ(lenient["sigma0"], doc["sigma0"]);
  EXPECT_NE(run.output.find("the result stands"), std::string::npos) << run.output;
}

}  // namespace
}  // namespace aerocal
