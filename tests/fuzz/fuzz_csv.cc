// CsvTable (every FORMATS.md CSV): parse, then read every field as a number and bounded number.
#include "calib/core/csv.h"
#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  AEROCAL_FUZZ_EXPECTED_ERRORS({
    const auto table = aerocal::CsvTable::Parse(text, "fuzz.csv");
    for (const auto& row : table.rows())
      for (const auto& column : table.header()) {
        AEROCAL_FUZZ_EXPECTED_ERRORS(table.OptionalNumber(row, column));
        AEROCAL_FUZZ_EXPECTED_ERRORS(table.Bounded(row, column, -1e7, 1e7));
      }
  });
  return 0;
}
