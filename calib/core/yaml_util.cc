#include "calib/core/yaml_util.h"

#include <algorithm>

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal {

YAML::Node LoadYamlText(const std::string& text, const std::string& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    ThrowInputError({file, e.mark.line + 1}, "invalid YAML: " + e.msg);
  }
}

YAML::Node LoadYamlFile(const std::string& path) { return LoadYamlText(ReadTextFile(path), path); }

SourceRef WhereIs(const YAML::Node& node, const std::string& file) {
  const int line = node.Mark().line;
  return {file, line >= 0 ? line + 1 : 0};
}

void RejectUnknownKeys(const YAML::Node& map, const std::vector<std::string>& allowed,
                       const std::string& file) {
  if (!map.IsMap()) ThrowInputError(WhereIs(map, file), "expected a map");
  for (const auto& entry : map) {
    const std::string key = entry.first.as<std::string>();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      ThrowInputError(WhereIs(entry.first, file),
                      "unknown key '" + key + "' (expected one of: " + list + ")");
    }
  }
}

double YamlDouble(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node.IsScalar()) ThrowInputError(WhereIs(node, file), what + " must be a number");
  const auto value = ParseDouble(node.Scalar());
  if (!value)
    ThrowInputError(WhereIs(node, file),
                    what + " must be a number (got '" + node.Scalar() + "')");
  return *value;
}

int YamlInt(const YAML::Node& node, const std::string& file, const std::string& what) {
  const double value = YamlDouble(node, file, what);
  if (value != static_cast<double>(static_cast<long>(value)))
    ThrowInputError(WhereIs(node, file), what + " must be an integer (got " + node.Scalar() + ")");
  return static_cast<int>(value);
}

std::string YamlString(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node.IsScalar()) ThrowInputError(WhereIs(node, file), what + " must be a string");
  return node.Scalar();
}

}  // namespace aerocal
