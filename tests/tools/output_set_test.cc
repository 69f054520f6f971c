// tools/output_set.h: the outputs of one command moved into place together or not at all, across
// several folders, files and folders alike (issue 37 class 8).
#include "tools/output_set.h"

#include "calib/core/error.h"
#include "tests/support/bad_input_case.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>

namespace aerocal::tools {
namespace {

namespace fs = std::filesystem;
using testing::ReadFileText;
using testing::TempDir;

// Writes `text` to `path`, creating its folder.
void WriteFileText(const std::string& path, const std::string& text) {
  fs::create_directories(fs::path(path).parent_path());
  testing::WriteFileText(path, text);
}

// Every file and folder under `folder` (relative path -> content, "/" for a folder).
std::map<std::string, std::string> Tree(const std::string& folder) {
  std::map<std::string, std::string> tree;
  for (const auto& e : fs::recursive_directory_iterator(folder))
    tree[fs::relative(e.path(), folder).string()] =
        e.is_directory() ? "/" : ReadFileText(e.path().string());
  return tree;
}

TEST(OutputSet, PartsInTwoFoldersAndAFolderPartAreCommittedTogether) {
  TempDir d("aerocal_output_set");
  WriteFileText(d.File("a/result.json"), "old result");
  WriteFileText(d.File("a/cert/certificate.json"), "old certificate");
  WriteFileText(d.File("b/image.tif"), "old image");
  {
    OutputSet set(d.File("a"));
    WriteFileText(set.Staged("result.json"), "new result");
    WriteFileText(set.Staged("cert") + "/certificate.json", "new certificate");
    WriteFileText(set.StagePath(d.File("b/image.tif")), "new image");
    WriteFileText(set.StagePath(d.File("c/new.tif")), "new folder");
    set.Commit({"result.json", "cert"});
  }
  EXPECT_EQ(Tree(d.path()),
            (std::map<std::string, std::string>{{"a", "/"},
                                                {"a/result.json", "new result"},
                                                {"a/cert", "/"},
                                                {"a/cert/certificate.json", "new certificate"},
                                                {"b", "/"},
                                                {"b/image.tif", "new image"},
                                                {"c", "/"},
                                                {"c/new.tif", "new folder"}}));
}

TEST(OutputSet, APartNotWrittenReplacesNothingAndLeavesNoStaging) {
  TempDir d("aerocal_output_set_fail");
  WriteFileText(d.File("a/result.json"), "old result");
  WriteFileText(d.File("b/image.tif"), "old image");
  const auto before = Tree(d.path());
  {
    OutputSet set(d.File("a"));
    WriteFileText(set.Staged("result.json"), "new result");
    set.StagePath(d.File("b/image.tif"));  // staged, never written (the part that failed)
    set.StagePath(d.File("new/x.tif"));    // a folder the set creates
    EXPECT_THROW(set.Commit({"result.json"}), InputError);
  }
  EXPECT_EQ(Tree(d.path()), before);  // the created folder "new" is removed again
}

TEST(OutputSet, ObsoletePartsOfThePreviousSetAreRemovedAndAPathIsStagedOnce) {
  TempDir d("aerocal_output_set_obsolete");
  WriteFileText(d.File("a/camera.yaml"), "old camera");
  WriteFileText(d.File("a/cert/certificate.json"), "old certificate");
  {
    OutputSet set(d.File("a"));
    WriteFileText(set.Staged("result.json"), "new result");
    set.StagePath(d.File("x/y.tif"));
    EXPECT_THROW(set.StagePath(d.File("x/./y.tif")), LogicError);
  }
  {
    OutputSet set(d.File("a"));
    WriteFileText(set.Staged("result.json"), "new result");
    set.Commit({"result.json"}, {"camera.yaml", "cert", "result.json"});
  }
  EXPECT_EQ(Tree(d.File("a")), (std::map<std::string, std::string>{{"result.json", "new result"}}));
}

TEST(OutputSetPaths, AnOutputNamingAnInputIsRefusedWithItsOption) {
  TempDir d("aerocal_output_set_paths");
  WriteFileText(d.File("in.yml"), "x");
  fs::create_hard_link(d.File("in.yml"), d.File("hard.yml"));
  EXPECT_THROW(CheckDistinctPath(d.File("in.yml"), "OUT", d.File("in.yml"), "IN"), ConfigError);
  EXPECT_THROW(CheckDistinctPath(d.File("sub/../in.yml"), "OUT", d.File("./in.yml"), "IN"),
               ConfigError);
  EXPECT_THROW(CheckDistinctPath(d.File("hard.yml"), "--report", d.File("in.yml"), "IN"),
               ConfigError);
  EXPECT_NO_THROW(CheckDistinctPath(d.File("out.yml"), "OUT", d.File("in.yml"), "IN"));
  EXPECT_NO_THROW(CheckDistinctPath("", "--report", d.File("in.yml"), "IN"));
  try {
    CheckDistinctPath(d.File("in.yml"), "--report", d.File("in.yml"), "OUT");
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--report: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace aerocal::tools
