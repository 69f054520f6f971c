// Helpers shared by the test suites: temporary folders, running the aerocal binary, paths.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::testing {

/// A fresh empty folder under the system temp dir, removed at destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "aerocal_test");
  ~TempDir();
  const std::string& path() const { return path_; }
  std::string File(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr together
};

/// Runs a shell command, capturing stdout+stderr.
CommandResult RunCommand(const std::string& command);
/// Path of the aerocal binary of this build.
std::string AerocalBinary();
/// Runs the aerocal binary with the given arguments.
CommandResult RunAerocal(const std::string& arguments);

/// The JSON document in `path` (a result the aerocal binary wrote). A result document (one with
/// `kind` and `schema_version`) is checked by ExpectValidResult on the way.
nlohmann::json ReadJson(const std::string& path);

/// docs/schema/<kind>.schema.json of the source tree.
std::string SchemaPath(const std::string& kind);

/// Adds a test failure unless `document` (read from `path`) is a result of one of kResultKinds, of
/// its kind's ResultSchemaVersion, that validates against docs/schema/<kind>.schema.json (the
/// failure names the first key path that does not, calib/core/json_schema.h).
void ExpectValidResult(const nlohmann::json& document, const std::string& path);
/// The same for the result file `path`.
void ExpectValidResult(const std::string& path);

/// The result document in `path` without the clock's keys (`seconds`, `timing`,
/// `seconds_testing`, at any depth), as text: two runs' texts are equal byte for byte exactly
/// when every other value is equal to the last bit (doubles are written in the shortest text that
/// reads back to the same bits).
std::string ResultWithoutClock(const std::string& path);

/// The number in NAME="..." of an XMP text (a regular expression on ":NAME=", whatever the prefix;
/// NaN when absent): the tests' reading of image metadata, independent of calib/metadata.
double XmpAttribute(const std::string& bytes, const std::string& name);

/// Path of a shared real data set, or "" when ../shared/data is absent (tests then GTEST_SKIP).
std::string SharedDataDir(const std::string& name);

}  // namespace aerocal::testing
