// One finding of a result: something that makes the result doubtful, by name, for people and
// programs. Every result's `warnings` is a list of these, written by FindingsToJson
// (docs/schema/common.schema.json#/definitions/finding):
//   {"name": "group_rms", "subject": "image", "value": 4.1, "limit": 3, "message": "..."}
// `name` is the stable code a program tests (snake_case, documented where it is raised), `subject`
// what it is about (a residual group, a point, a parameter), `value` and `limit` the measured
// figure and the bound it broke in the finding's own unit (null when the finding has none), and
// `message` one sentence for people.
#pragma once

#include <nlohmann/json.hpp>

#include <cmath>
#include <string>
#include <vector>

namespace aerocal {

struct Finding {
  std::string name;     // stable code, e.g. "group_rms"
  std::string subject;  // what it is about
  double value = NAN;   // NaN: none (written as null)
  double limit = NAN;   // NaN: none (written as null)
  std::string message;  // one sentence for people
};

/// {name, subject, value, limit, message}; a non-finite value or limit is null.
nlohmann::json FindingToJson(const Finding& finding);
/// A JSON array of FindingToJson.
nlohmann::json FindingsToJson(const std::vector<Finding>& findings);

}  // namespace aerocal
