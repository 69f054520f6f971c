// yaml-cpp helpers that keep FILE:LINE in every error (STYLE.md section 6: unknown keys are
// errors, missing keys keep defaults, YAML::Node::Mark() is 0-based so +1 for humans).
#pragma once

#include "calib/core/error.h"

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace aerocal {

/// Parses a YAML file strictly; a syntax error, a duplicate key or a key that is a list or map
/// becomes InputError("PATH:LINE: ...").
YAML::Node LoadYamlFile(const std::string& path);
/// Parses YAML text; `file` is used in messages.
YAML::Node LoadYamlText(const std::string& text, const std::string& file);

/// Location of a node as FILE:LINE (1-based).
SourceRef WhereIs(const YAML::Node& node, const std::string& file);

/// Throws InputError naming the first key of a map that is not in `allowed`.
void RejectUnknownKeys(const YAML::Node& map,
                       const std::vector<std::string>& allowed,
                       const std::string& file);

/// Reads a scalar as double / int / string; InputError at the node's line when it is not one.
double YamlDouble(const YAML::Node& node, const std::string& file, const std::string& what);
int YamlInt(const YAML::Node& node, const std::string& file, const std::string& what);
/// A number within [lo, hi] (the physical bounds FORMATS/READMEs state); InputError otherwise.
double YamlBounded(
    const YAML::Node& node, const std::string& file, const std::string& what, double lo, double hi);
std::string YamlString(const YAML::Node& node, const std::string& file, const std::string& what);
/// A list of exactly 3 numbers, each within [lo, hi]; InputError at the node's line otherwise.
Eigen::Vector3d YamlVector3(
    const YAML::Node& node, const std::string& file, const std::string& what, double lo, double hi);

}  // namespace aerocal
