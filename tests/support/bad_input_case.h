// The bad-input tables of tests/tools/bad_input_test.cc (issue 12) and bad_input2_test.cc (issue
// 37): one row per case, run the same way: the case's files in a fresh folder, the aerocal binary
// (under `timeout`, so a hang fails instead of blocking), then the exit code, the message naming
// FILE:LINE (or the option, or the key path), no internal error and no output left behind.
#pragma once

#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <sys/stat.h>

namespace aerocal::testing {

/// The whole file (binary).
inline std::string ReadFileText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Writes `text` to `path` (binary, replacing it).
inline void WriteFileText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// Replaces the first `from` in the file by `to` (a case's one defect); `from` must be there.
inline void ReplaceFirstInFile(const std::string& path,
                               const std::string& from,
                               const std::string& to) {
  std::string text = ReadFileText(path);
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " not in " << path;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  WriteFileText(path, text);
}

struct BadInputCase {
  const char* name;
  // Prepares the files in `dir` and returns the aerocal arguments.
  std::function<std::string(const TempDir& dir)> setup;
  int exit_code;
  std::string expect;  // substring of the output; "{DIR}" is the case's folder
  std::string output;  // path (below {DIR}) that must not exist afterwards; "" for none
};

/// Runs `c` in a fresh folder and checks it (gtest expectations).
inline void RunBadInputCase(const BadInputCase& c, int timeout_s = 60) {
  SCOPED_TRACE(c.name);
  TempDir dir("aerocal_bad_input");
  const std::string args = c.setup(dir);
  const auto r =
      RunCommand("timeout " + std::to_string(timeout_s) + " " + AerocalBinary() + " " + args);
  EXPECT_EQ(r.exit_code, c.exit_code) << args << "\n" << r.output;
  std::string expect = c.expect;
  const auto at = expect.find("{DIR}");
  if (at != std::string::npos) expect.replace(at, 5, dir.path());
  EXPECT_NE(r.output.find(expect), std::string::npos) << "expected '" << expect << "' in\n"
                                                      << r.output;
  EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
  if (!c.output.empty()) {
    EXPECT_FALSE(std::filesystem::exists(dir.File(c.output))) << c.output << " was written";
  }
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced";
}

}  // namespace aerocal::testing
