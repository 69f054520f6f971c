// Result documents of the commands (JSON): ONE writer and ONE reader check for all of them.
// Every result carries `kind` (which command wrote it: one of kResultKinds) and `schema_version`
// (the kind's version, ResultSchemaVersion), and is written atomically (calib/core/atomic_file.h).
// A reader of a result (the certificate, the report, a stitch result applied to a camera) checks
// both and refuses any other document with `FILE: what` (an InputError: exit 2). The keys of each
// kind are in its JSON Schema, docs/schema/<kind>.schema.json (docs/schema/README.md), which the
// CLI tests check every written result against.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <initializer_list>
#include <string>
#include <string_view>

namespace aerocal {

/// A kind of result document and the version of its keys, raised when a key of that kind is
/// renamed, removed or changes meaning or type (adding a key does not raise it), each raise listed
/// in docs/schema/CHANGES.md. Readers accept exactly the kind's current version.
struct ResultKind {
  std::string_view name;
  int schema_version;
};

/// Every kind of result document; each has its schema docs/schema/<kind>.schema.json (the test
/// tools/cli_results fails for a kind without one). `calibrate` writes an "adjust" result with
/// `command: "calibrate"`; `batch_manifest` is the manifest of `aerocal batch plan`.
inline constexpr std::array<ResultKind, 14> kResultKindTable = {{{"adjust", 3},
                                                                 {"flight", 2},
                                                                 {"stitch", 2},
                                                                 {"rig_stitch", 3},
                                                                 {"rig_error_analysis", 2},
                                                                 {"rig_design", 2},
                                                                 {"pushbroom", 3},
                                                                 {"pushbroom_control", 2},
                                                                 {"camera_conversion", 2},
                                                                 {"certificate", 3},
                                                                 {"quality_mtf", 2},
                                                                 {"quality_bars", 2},
                                                                 {"quality_star", 2},
                                                                 {"batch_manifest", 2}}};

/// The names of kResultKindTable, in its order.
inline constexpr std::array<std::string_view, kResultKindTable.size()> kResultKinds = [] {
  std::array<std::string_view, kResultKindTable.size()> names{};
  for (size_t i = 0; i < names.size(); ++i) names[i] = kResultKindTable[i].name;
  return names;
}();

/// The current schema_version of `kind`; LogicError when `kind` is not one of kResultKinds.
int ResultSchemaVersion(std::string_view kind);

/// `document` (a JSON object) stamped with `kind` and `schema_version`, as text (`indent` spaces,
/// newline at the end). Throws LogicError when `kind` is not one of kResultKinds, `document` is not
/// an object or already names another kind.
std::string ResultText(std::string_view kind, nlohmann::json document, int indent = 2);

/// Writes ResultText(kind, document, indent) to `path` atomically (nothing partial on failure).
void WriteResult(const std::string& path,
                 std::string_view kind,
                 nlohmann::json document,
                 int indent = 2);

/// Throws InputError("PATH: not a result of WHAT (kind is K, expected A or B)") unless `document`
/// is an object whose `kind` is one of `kinds`, and InputError("PATH: schema_version is V, expected
/// N (kind K)") unless its `schema_version` is ResultSchemaVersion(K). `what` names the
/// command for people ("`aerocal calibrate`").
void CheckResult(const nlohmann::json& document,
                 const std::string& path,
                 std::initializer_list<std::string_view> kinds,
                 std::string_view what);

/// CheckResult for any of kResultKinds, then ValidateJson against its schema
/// `schema_dir`/<kind>.schema.json (calib/core/json_schema.h): InputError("PATH: KEY.PATH: what")
/// at the first value the schema does not allow. The CLI tests and `aerocal validate` use it.
void ValidateResult(const nlohmann::json& document,
                    const std::string& path,
                    const std::string& schema_dir);

/// ReadJsonFile(path) (FILE:LINE on invalid JSON) + CheckResult.
nlohmann::json ReadResult(const std::string& path,
                          std::initializer_list<std::string_view> kinds,
                          std::string_view what);

}  // namespace aerocal
