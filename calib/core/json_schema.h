// Input documents read through their schema (issue 37 class 1): a value taken from a JSON file and
// printed as a fact (a certificate's U, a previous certificate's value) is first checked against a
// JSON-Schema subset, and a document that does not validate is refused with the key path:
// `result.json: calibration.uncertainty[3].U: expected a finite number (got "0.1")`.
//
// The subset (JSON Schema draft 7 keywords, same meaning): type (a name or a list of names:
// object, array, number, integer, string, boolean, null), properties, required,
// additionalProperties (false or a schema), items (one schema), minItems, maxItems, minimum,
// maximum, exclusiveMinimum (a number), maxLength, enum, allOf, $ref ("#/definitions/NAME"; and,
// through ReadJsonSchema, "FILE#/definitions/NAME" or "FILE" for another schema file of the same
// folder). A number is always finite (a JSON 1e400 reads as infinity). The schemas live in
// docs/schema/ (docs/schema/README.md).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal {

/// Throws InputError("FILE: KEY.PATH: what (got VALUE)") at the first value of `document` that
/// does not satisfy `schema`; `root_path` prefixes the key path ("" for the document itself).
/// LogicError for a keyword of `schema` outside the subset (a schema is ours, not user input).
void ValidateJson(const nlohmann::json& document,
                  const nlohmann::json& schema,
                  const std::string& file,
                  const std::string& root_path = "");

/// Reads a schema file (our own, e.g. docs/schema/certificate_inputs.schema.json) with every schema
/// file it refers to (`"$ref": "common.schema.json#/definitions/finding"`), bundled into one
/// document whose references ValidateJson resolves (the other file's definitions copied into
/// `definitions` as "FILE#NAME", its whole schema as "FILE#"); LogicError when a file is missing
/// or not JSON (an installation fault, not bad input).
nlohmann::json ReadJsonSchema(const std::string& path);

}  // namespace aerocal
