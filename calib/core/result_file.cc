#include "calib/core/result_file.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/json_file.h"
#include "calib/core/json_schema.h"

#include <algorithm>
#include <ostream>

namespace aerocal {

int ResultSchemaVersion(std::string_view kind) {
  for (const ResultKind& k : kResultKindTable)
    if (k.name == kind) return k.schema_version;
  AEROCAL_CHECK(false) << "result kind " << kind
                       << " is not in kResultKinds (calib/core/result_file.h)";
  return 0;
}

namespace {

// `document` checked and stamped with `kind` and its kind's `schema_version` (ResultText's
// contract); LogicError for a kind not listed.
void Stamp(std::string_view kind, nlohmann::json* document) {
  const int version = ResultSchemaVersion(kind);
  AEROCAL_CHECK(document->is_object()) << "a result document is a JSON object";
  if (document->contains("kind")) {
    AEROCAL_CHECK((*document)["kind"] == std::string(kind))
        << "result of kind " << (*document)["kind"].dump() << " written as " << kind;
  }
  (*document)["kind"] = std::string(kind);
  (*document)["schema_version"] = version;
}

// The text of document.dump(indent) written straight into `os`: the same serializer with the
// same arguments as dump() (pretty for indent >= 0, ensure_ascii off, strict UTF-8), but no string
// of the whole document in memory (47 MB, grown by doubling, at the peak heap of `adjust` with
// 600 exposures: heaptrack).
void DumpTo(const nlohmann::json& document, int indent, std::ostream& os) {
  nlohmann::detail::serializer<nlohmann::json> serializer(
      nlohmann::detail::output_adapter<char>(os), ' ', nlohmann::json::error_handler_t::strict);
  serializer.dump(document, indent >= 0, false, static_cast<unsigned int>(std::max(indent, 0)));
  os << '\n';
}

}  // namespace

std::string ResultText(std::string_view kind, nlohmann::json document, int indent) {
  Stamp(kind, &document);
  return document.dump(indent) + "\n";
}

void WriteResult(const std::string& path,
                 std::string_view kind,
                 nlohmann::json document,
                 int indent) {
  Stamp(kind, &document);
  WriteFileAtomically(path, [&](std::ostream& os) { DumpTo(document, indent, os); });
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
