#include "calib/core/result_file.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/json_schema.h"

#include <algorithm>

namespace aerocal {

int ResultSchemaVersion(std::string_view kind) {
  for (const ResultKind& k : kResultKindTable)
    if (k.name == kind) return k.schema_version;
  AEROCAL_CHECK(false) << "result kind " << kind
                       << " is not in kResultKinds (calib/core/result_file.h)";
  return 0;
}

std::string ResultText(std::string_view kind, nlohmann::json document, int indent) {
  const int version = ResultSchemaVersion(kind);  // LogicError for a kind not listed
  AEROCAL_CHECK(document.is_object()) << "a result document is a JSON object";
  if (document.contains("kind")) {
    AEROCAL_CHECK(document["kind"] == std::string(kind))
        << "result of kind " << document["kind"].dump() << " written as " << kind;
  }
  document["kind"] = std::string(kind);
  document["schema_version"] = version;
  return document.dump(indent) + "\n";
}

void WriteResult(const std::string& path,
                 std::string_view kind,
                 nlohmann::json document,
                 int indent) {
  WriteFileAtomically(path, ResultText(kind, std::move(document), indent));
}

void CheckResult(const nlohmann::json& document,
                 const std::string& path,
                 std::initializer_list<std::string_view> kinds,
                 std::string_view what) {
  std::string expected;
  for (std::string_view k : kinds)
    expected += (expected.empty() ? "\"" : " or \"") + std::string(k) + "\"";
  const nlohmann::json kind =
      document.is_object() && document.contains("kind") ? document["kind"] : nlohmann::json();
  bool known = false;
  for (std::string_view k : kinds) known = known || (kind.is_string() && kind == std::string(k));
  if (!known)
    throw InputError(path + ": not a result of " + std::string(what) + " (kind is " + kind.dump() +
                     ", expected " + expected + ")");
  const nlohmann::json version =
      document.contains("schema_version") ? document["schema_version"] : nlohmann::json();
  const int expected_version = ResultSchemaVersion(kind.get<std::string>());
  if (!version.is_number_integer() || version.get<long long>() != expected_version)
    throw InputError(path + ": schema_version is " + version.dump() + ", expected " +
                     std::to_string(expected_version) + " (kind " + kind.dump() + ")");
}

void ValidateResult(const nlohmann::json& document,
                    const std::string& path,
                    const std::string& schema_dir) {
  const nlohmann::json kind =
      document.is_object() && document.contains("kind") ? document["kind"] : nlohmann::json();
  const auto known = std::find_if(kResultKinds.begin(), kResultKinds.end(), [&](auto k) {
    return kind.is_string() && kind == std::string(k);
  });
  if (known == kResultKinds.end())
    throw InputError(path + ": not a result of aerocal (kind is " + kind.dump() + ")");
  CheckResult(document, path, {*known}, "aerocal");
  ValidateJson(
      document, ReadJsonSchema(schema_dir + "/" + std::string(*known) + ".schema.json"), path);
}

nlohmann::json ReadResult(const std::string& path,
                          std::initializer_list<std::string_view> kinds,
                          std::string_view what) {
  nlohmann::json document = ReadJsonFile(path);
  CheckResult(document, path, kinds, what);
  return document;
}

}  // namespace aerocal
