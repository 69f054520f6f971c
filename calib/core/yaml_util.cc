#include "calib/core/yaml_util.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

#include <climits>

#include <algorithm>
#include <cmath>
#include <set>

namespace aerocal {

namespace {

// Strict reading (STYLE.md section 6): every map key a scalar and given once. yaml-cpp keeps a
// duplicate key silently (the first wins on lookup), so the whole tree is walked once.
void CheckStrict(const YAML::Node& node, const std::string& file, int depth, long* visited) {
  if (++*visited > 1000000) ThrowInputError(WhereIs(node, file), "YAML document too large");
  if (depth > 64) ThrowInputError(WhereIs(node, file), "YAML nested more than 64 levels deep");
  if (node.IsSequence()) {
    for (const auto& item : node) CheckStrict(item, file, depth + 1, visited);
  } else if (node.IsMap()) {
    std::set<std::string> keys;
    for (const auto& entry : node) {
      if (!entry.first.IsScalar())
        ThrowInputError(WhereIs(entry.first, file),
                        "a map key must be a plain name, not a list or map");
      if (!keys.insert(entry.first.Scalar()).second)
        ThrowInputError(WhereIs(entry.first, file), "duplicate key '" + entry.first.Scalar() + "'");
      CheckStrict(entry.second, file, depth + 1, visited);
    }
  }
}

int LineOf(const YAML::Mark& mark) { return mark.line >= 0 ? mark.line + 1 : 0; }

}  // namespace

YAML::Node LoadYamlText(const std::string& text, const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    ThrowInputError({file, LineOf(e.mark)}, "invalid YAML: " + e.msg);
  }
  long visited = 0;
  CheckStrict(root, file, 0, &visited);
  return root;
}

YAML::Node LoadYamlFile(const std::string& path) { return LoadYamlText(ReadTextFile(path), path); }

SourceRef WhereIs(const YAML::Node& node, const std::string& file) {
  if (!node.IsDefined()) return {file, 0};  // a missing key has no position (Mark() would throw)
  return {file, LineOf(node.Mark())};
}

void RejectUnknownKeys(const YAML::Node& map,
                       const std::vector<std::string>& allowed,
                       const std::string& file) {
  if (!map.IsMap()) ThrowInputError(WhereIs(map, file), "expected a map");
  for (const auto& entry : map) {
    if (!entry.first.IsScalar())
      ThrowInputError(WhereIs(entry.first, file),
                      "a map key must be a plain name, not a list or map");
    const std::string key = entry.first.Scalar();
    if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      ThrowInputError(WhereIs(entry.first, file),
                      "unknown key '" + key + "' (expected one of: " + list + ")");
    }
  }
}

double YamlDouble(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node.IsDefined()) ThrowInputError({file, 0}, "missing " + what);
  if (!node.IsScalar()) ThrowInputError(WhereIs(node, file), what + " must be a number");
  const auto value = ParseDouble(node.Scalar());
  if (!value)
    ThrowInputError(WhereIs(node, file), what + " must be a number (got '" + node.Scalar() + "')");
  return *value;
}

int YamlInt(const YAML::Node& node, const std::string& file, const std::string& what) {
  const double value = YamlDouble(node, file, what);
  if (std::abs(value) > INT_MAX || value != std::floor(value))
    ThrowInputError(WhereIs(node, file),
                    what + " must be an integer within +-" + std::to_string(INT_MAX) + " (got " +
                        node.Scalar() + ")");
  return static_cast<int>(value);
}

double YamlBounded(const YAML::Node& node,
                   const std::string& file,
                   const std::string& what,
                   double lo,
                   double hi) {
  const double value = YamlDouble(node, file, what);
  if (!(value >= lo && value <= hi))
    ThrowInputError(WhereIs(node, file),
                    what + " out of range (got " + node.Scalar() + ", expected " +
                        FormatNumber(lo) + " .. " + FormatNumber(hi) + ")");
  return value;
}

Eigen::Vector3d YamlVector3(const YAML::Node& node,
                            const std::string& file,
                            const std::string& what,
                            double lo,
                            double hi) {
  if (!node.IsSequence() || node.size() != 3)
    ThrowInputError(WhereIs(node, file), what + " must be a list of 3 numbers");
  return {YamlBounded(node[0], file, what, lo, hi),
          YamlBounded(node[1], file, what, lo, hi),
          YamlBounded(node[2], file, what, lo, hi)};
}

std::string YamlString(const YAML::Node& node, const std::string& file, const std::string& what) {
  if (!node.IsDefined()) ThrowInputError({file, 0}, "missing " + what);
  if (!node.IsScalar()) ThrowInputError(WhereIs(node, file), what + " must be a string");
  return node.Scalar();
}

}  // namespace aerocal
