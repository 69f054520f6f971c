#include "calib/core/json_schema.h"

#include "calib/core/csv.h"  // FormatNumber
#include "calib/core/error.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <vector>

namespace aerocal {
namespace {

std::string Shown(const nlohmann::json& value) {
  std::string text = value.dump();
  if (text.size() > 60) text = text.substr(0, 57) + "...";
  return text;
}

std::string TypeOf(const nlohmann::json& v) {
  if (v.is_object()) return "object";
  if (v.is_array()) return "array";
  if (v.is_boolean()) return "boolean";
  if (v.is_null()) return "null";
  if (v.is_string()) return "string";
  return "number";
}

bool HasType(const nlohmann::json& v, const std::string& type) {
  if (type == "integer")
    return v.is_number_integer() ||
           (v.is_number_float() && std::isfinite(v.get<double>()) &&
            std::floor(v.get<double>()) == v.get<double>() && std::abs(v.get<double>()) < 9e15);
  if (type == "number") return v.is_number() && std::isfinite(v.get<double>());
  return TypeOf(v) == type;
}

class Validator {
 public:
  Validator(const nlohmann::json& root_schema, const std::string& file)
      : root_(root_schema), file_(file) {}

  void Check(const nlohmann::json& v, const nlohmann::json& schema, const std::string& path) const {
    if (schema.is_boolean()) {
      if (!schema.get<bool>()) Fail(path, "not allowed here", v);
      return;
    }
    AEROCAL_CHECK(schema.is_object()) << "schema at " << path << " is not an object";
    for (const auto& [key, _] : schema.items())
      AEROCAL_CHECK(kKeywords.count(key)) << "schema keyword '" << key << "' is not supported";
    if (schema.contains("$ref")) {
      const std::string ref = schema["$ref"];
      const std::string prefix = "#/definitions/";
      AEROCAL_CHECK(ref == "#" || (ref.rfind(prefix, 0) == 0 && root_.contains("definitions") &&
                                   root_["definitions"].contains(ref.substr(prefix.size()))))
          << "schema $ref " << ref;
      Check(v, ref == "#" ? root_ : root_["definitions"][ref.substr(prefix.size())], path);
    }
    if (schema.contains("allOf"))
      for (const nlohmann::json& part : schema["allOf"]) Check(v, part, path);
    if (schema.contains("type")) {
      const nlohmann::json& t = schema["type"];
      std::vector<std::string> types = t.is_array()
                                           ? t.get<std::vector<std::string>>()
                                           : std::vector<std::string>{t.get<std::string>()};
      bool ok = false;
      for (const auto& type : types) ok = ok || HasType(v, type);
      if (!ok) {
        std::string expected;
        for (size_t i = 0; i < types.size(); ++i)
          expected += (i ? (i + 1 == types.size() ? " or " : ", ") : "") +
                      (types[i] == "number"    ? "a finite number"
                       : types[i] == "integer" ? "an integer"
                                               : "a " + types[i]);
        Fail(path, "expected " + expected, v);
      }
    }
    if (schema.contains("enum")) {
      bool found = false;
      for (const auto& e : schema["enum"]) found = found || e == v;
      if (!found) Fail(path, "expected one of " + schema["enum"].dump(), v);
    }
    if (v.is_number()) {
      const double x = v.get<double>();
      if (schema.contains("minimum") && !(x >= schema["minimum"].get<double>()))
        Fail(path, "must be >= " + FormatNumber(schema["minimum"].get<double>()), v);
      if (schema.contains("exclusiveMinimum") && !(x > schema["exclusiveMinimum"].get<double>()))
        Fail(path, "must be > " + FormatNumber(schema["exclusiveMinimum"].get<double>()), v);
      if (schema.contains("maximum") && !(x <= schema["maximum"].get<double>()))
        Fail(path, "must be <= " + FormatNumber(schema["maximum"].get<double>()), v);
    }
    if (v.is_string() && schema.contains("maxLength") &&
        v.get_ref<const std::string&>().size() > schema["maxLength"].get<size_t>())
      Fail(path, "longer than " + schema["maxLength"].dump() + " characters", v);
    if (v.is_array()) {
      if (schema.contains("minItems") && v.size() < schema["minItems"].get<size_t>())
        Fail(path, "expected at least " + schema["minItems"].dump() + " items", v);
      if (schema.contains("maxItems") && v.size() > schema["maxItems"].get<size_t>())
        Fail(path, "expected at most " + schema["maxItems"].dump() + " items", v);
      if (schema.contains("items"))
        for (size_t i = 0; i < v.size(); ++i)
          Check(v[i], schema["items"], path + "[" + std::to_string(i) + "]");
    }
    if (v.is_object()) {
      for (const auto& key : schema.value("required", nlohmann::json::array()))
        if (!v.contains(key.get<std::string>()))
          Fail(Join(path, key.get<std::string>()), "missing", nullptr);
      const nlohmann::json properties = schema.value("properties", nlohmann::json::object());
      for (const auto& [key, value] : v.items()) {
        if (properties.contains(key))
          Check(value, properties[key], Join(path, key));
        else if (schema.contains("additionalProperties"))
          Check(value, schema["additionalProperties"], Join(path, key));
      }
    }
  }

 private:
  static std::string Join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  [[noreturn]] void Fail(const std::string& path,
                         const std::string& what,
                         const nlohmann::json& v) const {
    throw InputError(file_ + ": " + (path.empty() ? "the document" : path) + ": " + what +
                     (v.is_null() && what == "missing" ? "" : " (got " + Shown(v) + ")"));
  }

  inline static const std::set<std::string> kKeywords = {"type",
                                                         "allOf",
                                                         "properties",
                                                         "required",
                                                         "additionalProperties",
                                                         "items",
                                                         "minItems",
                                                         "maxItems",
                                                         "minimum",
                                                         "maximum",
                                                         "exclusiveMinimum",
                                                         "maxLength",
                                                         "enum",
                                                         "$ref",
                                                         "definitions",
                                                         "$schema",
                                                         "$id",
                                                         "title",
                                                         "description",
                                                         "$comment"};
  const nlohmann::json& root_;
  const std::string& file_;
};

}  // namespace

void ValidateJson(const nlohmann::json& document,
                  const nlohmann::json& schema,
                  const std::string& file,
                  const std::string& root_path) {
  Validator(schema, file).Check(document, schema, root_path);
}

namespace {

nlohmann::json ReadSchemaFile(const std::string& path) {
  std::ifstream in(path);
  AEROCAL_CHECK(in.good()) << "schema " << path << " is missing (installation)";
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    AEROCAL_CHECK(false) << "schema " << path << " is not JSON: " << e.what();
  }
  return nullptr;
}

// Makes the schema of one file self-contained for the Validator, which resolves only
// "#/definitions/NAME": a reference to another file, "FILE#/definitions/NAME" or "FILE" (its
// whole schema; FILE relative to the folder of the schema that names it), becomes
// "#/definitions/FILE#NAME" (or "FILE#"), and that definition is copied into the root's
// definitions, its own references rewritten the same way ("#/definitions/X" inside FILE becomes
// "#/definitions/FILE#X"). Each file is read once; cycles between files are therefore fine.
class Bundler {
 public:
  Bundler(std::string folder, nlohmann::json* definitions)
      : folder_(std::move(folder)), definitions_(definitions) {}

  // Rewrites the references in `node`, which belongs to `file` ("" for the root file).
  void Rewrite(nlohmann::json* node, const std::string& file) {
    if (node->is_array()) {
      for (auto& item : *node) Rewrite(&item, file);
      return;
    }
    if (!node->is_object()) return;
    for (auto& [key, value] : node->items()) {
      if (key == "$ref" && value.is_string()) {
        value = Resolved(value.get<std::string>(), file);
      } else if (key != "definitions" && key != "enum") {
        Rewrite(&value, file);
      }
    }
  }

 private:
  std::string Resolved(const std::string& ref, const std::string& file) {
    const std::string local = "#/definitions/";
    const size_t hash = ref.find('#');
    const std::string target = ref.substr(0, hash);
    const std::string fragment = hash == std::string::npos ? "" : ref.substr(hash);
    AEROCAL_CHECK(fragment.empty() || fragment == "#" || fragment.rfind(local, 0) == 0)
        << "schema $ref " << ref << " (expected FILE, FILE#/definitions/NAME or "
        << "#/definitions/NAME)";
    const std::string name = fragment.size() > local.size() ? fragment.substr(local.size()) : "";
    const std::string owner = target.empty() ? file : target;
    if (owner.empty()) return ref;  // a definition of the root file
    Load(owner);
    return local + owner + "#" + name;
  }

  void Load(const std::string& file) {
    if (!loaded_.insert(file).second) return;
    nlohmann::json schema = ReadSchemaFile((std::filesystem::path(folder_) / file).string());
    nlohmann::json own = schema.value("definitions", nlohmann::json::object());
    schema.erase("definitions");
    Rewrite(&schema, file);
    (*definitions_)[file + "#"] = schema;
    for (auto& [name, definition] : own.items()) {
      Rewrite(&definition, file);
      (*definitions_)[file + "#" + name] = definition;
    }
  }

  std::string folder_;
  nlohmann::json* definitions_;
  std::set<std::string> loaded_;
};

}  // namespace

nlohmann::json ReadJsonSchema(const std::string& path) {
  nlohmann::json schema = ReadSchemaFile(path);
  AEROCAL_CHECK(schema.is_object()) << "schema " << path << " is not an object";
  nlohmann::json definitions = schema.value("definitions", nlohmann::json::object());
  Bundler bundler(std::filesystem::path(path).parent_path().string(), &definitions);
  std::vector<std::string> names;  // first: bundling adds definitions while it rewrites
  for (const auto& [name, _] : definitions.items()) names.push_back(name);
  for (const std::string& name : names) bundler.Rewrite(&definitions[name], "");
  bundler.Rewrite(&schema, "");
  schema["definitions"] = definitions;
  return schema;
}

}  // namespace aerocal
