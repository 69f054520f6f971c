// Result documents of the commands (JSON): ONE writer and ONE reader check for all of them.
// Every result carries `kind` (which command wrote it: one of kResultKinds) and `schema_version`
// (kResultSchemaVersion), and is written atomically (calib/core/atomic_file.h). A reader of a
// result (the certificate, the report, a stitch result applied to a camera) checks both and
// refuses any other document with `FILE: what` (an InputError: exit 2). The keys of each kind are
// in its JSON Schema, docs/schema/<kind>.schema.json (docs/schema/README.md), which the CLI tests
// check every written result against.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <initializer_list>
#include <string>
#include <string_view>

namespace aerocal {

/// Version of every result document; raised when a key is renamed, removed or changes meaning or
/// type (adding a key does not raise it), each raise listed in docs/schema/CHANGES.md. Readers
/// accept exactly this version.
inline constexpr int kResultSchemaVersion = 2;  // docs/schema/CHANGES.md

/// Every kind of result document; each has its schema docs/schema/<kind>.schema.json (the test
/// tools/cli_results fails for a kind without one). `calibrate` writes an "adjust" result with
/// `command: "calibrate"`; `batch_manifest` is the manifest of `aerocal batch plan`.
inline constexpr std::array<std::string_view, 14> kResultKinds = {"adjust",
                                                                  "flight",
                                                                  "stitch",
                                                                  "rig_stitch",
                                                                  "rig_error_analysis",
                                                                  "rig_design",
                                                                  "pushbroom",
                                                                  "pushbroom_control",
                                                                  "camera_conversion",
                                                                  "certificate",
                                                                  "quality_mtf",
                                                                  "quality_bars",
                                                                  "quality_star",
                                                                  "batch_manifest"};

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
/// N (kind K)") unless its `schema_version` is kResultSchemaVersion. `what` names the
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
