// The schema check of input documents (issue 37 class 1, calib/core/json_schema.h): any JSON text
// against the certificate's input schema (docs/schema/certificate_inputs.schema.json), rooted at
// each of its documents. Text that is not JSON is nlohmann's to refuse (discarded here).
#include "calib/core/json_schema.h"
#include "tests/fuzz/fuzz_support.h"

#include <nlohmann/json.hpp>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const nlohmann::json schema =
      aerocal::ReadJsonSchema(std::string(AEROCAL_SCHEMA_DIR) + "/certificate_inputs.schema.json");
  const nlohmann::json document = nlohmann::json::parse(data, data + size, nullptr, false);
  if (document.is_discarded()) return 0;
  for (const char* definition : {"calibrate_result", "previous"}) {
    const nlohmann::json rooted = {{"$ref", std::string("#/definitions/") + definition},
                                   {"definitions", schema.at("definitions")}};
    AEROCAL_FUZZ_EXPECTED_ERRORS(aerocal::ValidateJson(document, rooted, "fuzz.json"));
  }
  return 0;
}
