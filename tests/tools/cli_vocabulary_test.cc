// One command-line vocabulary (issue 33 item 4): the same option name means the same thing in
// every command, the option reference docs/options.md is the program's own listing, old spellings
// work as deprecated aliases with a warning, the global options are accepted after the command's
// name, and a missing parent folder of an output is an error unless --mkdir is given.
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace aerocal {
namespace {

using testing::RunAerocal;
using testing::TempDir;

struct Option {
  std::string command, name, type, default_value, description;
};

std::vector<Option> AllOptions() {
  const auto r = RunAerocal("options");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::vector<Option> out;
  std::istringstream in(r.output);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> f;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, '\t');) f.push_back(x);
    f.resize(5);
    out.push_back({f[0], f[1], f[2], f[3], f[4]});
  }
  return out;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A DJI DewarpData record (the layout DJI documents): a camera that needs a pixel size for our
// format, so `camera show` uses --pixel-size-mm.
std::string DjiCamera(const TempDir& tmp) {
  const std::string path = tmp.File("dji.txt");
  std::ofstream(path) << "2018-09-06;3684.48,3677.57,2.24,22.05,-0.263482,0.106788,3.71107e-5,"
                         "-3.27247e-4,-0.0300783\n";
  return path;
}

TEST(CliVocabulary, TheOptionReferenceIsTheProgramsOwnListing) {
  const auto r = RunAerocal("options --markdown");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const std::string committed = ReadFile(std::string(AEROCAL_SOURCE_DIR) + "/docs/options.md");
  EXPECT_EQ(committed, r.output) << "docs/options.md is out of date: regenerate it with\n"
                                    "  build/tools/aerocal options --markdown > docs/options.md";
}

TEST(CliVocabulary, EveryOutSaysWhetherItIsAFileOrAFolder) {
  int checked = 0;
  for (const Option& o : AllOptions()) {
    if (o.name != "--out") continue;
    ++checked;
    const bool file = o.description.rfind("Output file", 0) == 0;
    const bool folder = o.description.rfind("Output folder", 0) == 0;
    EXPECT_TRUE(file || folder) << o.command << " --out: '" << o.description << "'";
  }
  EXPECT_GT(checked, 20);
}

TEST(CliVocabulary, SharedNamesHaveOneTypeAndUnit) {
  // name -> (type prefix, a word every description holds, or "" for none)
  const std::map<std::string, std::pair<std::string, std::string>> rules = {
      {"--sigma-px", {"FLOAT", "px"}},
      {"--pixel-size-mm", {"FLOAT", "mm"}},
      {"--images", {"TEXT", ""}},
      {"--project", {"TEXT", ""}},
      {"--model", {"TEXT", ""}},
      {"--camera", {"TEXT", ""}},
      {"--height-m", {"FLOAT", ""}},
      {"--seed", {"UINT", ""}}};
  std::map<std::string, int> seen;
  for (const Option& o : AllOptions()) {
    const auto rule = rules.find(o.name);
    if (rule == rules.end()) continue;
    ++seen[o.name];
    SCOPED_TRACE(o.command + " " + o.name + " " + o.type + ": " + o.description);
    EXPECT_EQ(o.type.rfind(rule->second.first, 0), 0u);
    if (!rule->second.second.empty())
      EXPECT_NE(o.description.find(rule->second.second), std::string::npos);
  }
  for (const auto& [name, rule] : rules)
    EXPECT_GE(seen[name], 2) << name << " is in fewer than two commands";
}

TEST(CliVocabulary, NoCommandOffersAnOldSpelling) {
  const std::set<std::string> old = {"--pixel-mm", "--sigma", "--out-dir"};
  for (const Option& o : AllOptions())
    EXPECT_EQ(old.count(o.name), 0u) << o.command << " " << o.name;
}

TEST(CliVocabulary, AnOldSpellingWorksWithAWarningNamingTheNewOne) {
  TempDir tmp("aerocal_vocabulary");
  const std::string camera = DjiCamera(tmp);
  const std::string common = "camera show --from dji " + camera + " --width 5472 --height 3648 ";
  const auto now = RunAerocal(common + "--pixel-size-mm 0.0024");
  const auto old = RunAerocal(common + "--pixel-mm=0.0024");
  ASSERT_EQ(now.exit_code, 0) << now.output;
  ASSERT_EQ(old.exit_code, 0) << old.output;
  EXPECT_EQ(now.output.find("deprecated"), std::string::npos) << now.output;
  const std::string warning =
      "warning: camera show --pixel-mm is deprecated and goes in release 0.2.0: use "
      "--pixel-size-mm\n";
  ASSERT_EQ(old.output.rfind(warning, 0), 0u) << old.output;
  EXPECT_EQ(old.output.substr(warning.size()), now.output);  // the same run otherwise
  // The alias takes the new option's range check, and --quiet silences the warning.
  const auto out_of_range = RunAerocal(common + "--pixel-mm 7");
  EXPECT_EQ(out_of_range.exit_code, 2);
  EXPECT_NE(out_of_range.output.find("--pixel-size-mm: must be in"), std::string::npos)
      << out_of_range.output;
  EXPECT_EQ(RunAerocal(common + "--pixel-mm 0.0024 --quiet").output.find("deprecated"),
            std::string::npos);
  // An old spelling of another command is not rewritten: calibrate never had --sigma.
  EXPECT_EQ(RunAerocal("calibrate --sigma 0.3").output.find("deprecated"), std::string::npos);
}

TEST(CliVocabulary, AMissingParentFolderIsAnErrorUnlessMkdirIsGiven) {
  TempDir tmp("aerocal_vocabulary");
  const std::string in = std::string(AEROCAL_CONFIGS_DIR) + "/camera_2x3.yaml";
  const std::string nested = tmp.File("no/such/folder/camera.yml");
  const auto refused = RunAerocal("camera convert --from aerocal --to opencv " + in + " " + nested);
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("OUT '" + nested + "': folder '" + tmp.File("no") +
                                "' does not exist (create it, or give --mkdir to have it created)"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(std::filesystem::exists(tmp.File("no")));
  // --mkdir before and after the command's name.
  const auto before =
      RunAerocal("--mkdir camera convert --from aerocal --to opencv " + in + " " + nested);
  ASSERT_EQ(before.exit_code, 0) << before.output;
  EXPECT_TRUE(std::filesystem::is_regular_file(nested));
  const std::string other = tmp.File("other/camera.yml");
  const auto after =
      RunAerocal("camera convert --mkdir --from aerocal --to opencv " + in + " " + other);
  ASSERT_EQ(after.exit_code, 0) << after.output;
  EXPECT_EQ(ReadFile(other), ReadFile(nested));
  // An output folder itself is created; only its parents must exist.
  const auto folder = RunAerocal(
      "simulate --exposures 2 --strips 1 --surveyed-points 6 --control 3 "
      "--tie-points 10 --stitch-ties 10 --out " +
      tmp.File("sim"));
  EXPECT_EQ(folder.exit_code, 0) << folder.output;
}

TEST(CliVocabulary, SimulateHelpIsGroupedByMode) {
  const auto r = RunAerocal("simulate --help");
  ASSERT_EQ(r.exit_code, 0);
  std::vector<size_t> at;
  for (const char* heading : {"Output:",
                              "Frame-camera flight",
                              "Multi-head rig flight (--rig):",
                              "Calibration test field (--test-field):",
                              "Pushbroom line camera (--pushbroom):",
                              "Rendered images (--render-images"}) {
    at.push_back(r.output.find(heading));
    EXPECT_NE(at.back(), std::string::npos) << heading << "\n" << r.output;
  }
  // Each mode's own options sit under its heading: --planar after the test field's, before the
  // pushbroom's.
  const size_t planar = r.output.find("--planar");
  EXPECT_GT(planar, at[3]);
  EXPECT_LT(planar, at[4]);
}

}  // namespace
}  // namespace aerocal
