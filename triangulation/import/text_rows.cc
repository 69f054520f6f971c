#include "triangulation/import/text_rows.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <sstream>

namespace aerocal::triangulation::internal {

std::vector<TextRow> ReadTextRows(const std::string& path, bool comma_separates, bool keep_blank) {
  std::vector<TextRow> rows;
  int number = 0;
  for (const std::string& line : SplitLines(ReadTextFile(path))) {
    ++number;
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos) {
      if (keep_blank) rows.push_back({number, {}});
      continue;
    }
    if (line[0] == '#') continue;  // a comment only where '#' is the line's first character
    TextRow row;
    row.line = number;
    if (comma_separates && line.find(',') != std::string::npos) {
      // Comma-separated: every field must be there; an empty one would shift the columns.
      row.fields = SplitCommaList(line, {true, true});
      for (size_t k = 0; k < row.fields.size(); ++k)
        if (row.fields[k].empty())
          ThrowInputError({path, number},
                          "empty field " + std::to_string(k + 1) + " (give every value)");
    } else {
      std::istringstream fields(line);
      std::string field;
      while (fields >> field) row.fields.push_back(field);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

double NumberField(const TextRow& row, size_t k, const std::string& file, const char* what) {
  if (k >= row.fields.size())
    ThrowInputError({file, row.line},
                    std::string("missing ") + what + " (field " + std::to_string(k + 1) + ")");
  const auto value = ParseDouble(row.fields[k]);
  if (!value)
    ThrowInputError({file, row.line},
                    std::string(what) + " must be a number (got '" + row.fields[k] + "')");
  return *value;
}

double BoundedField(
    const TextRow& row, size_t k, const std::string& file, const char* what, double lo, double hi) {
  const double value = NumberField(row, k, file, what);
  if (!(value >= lo && value <= hi))
    ThrowInputError({file, row.line},
                    std::string(what) + " out of range (got " + FormatNumber(value) +
                        ", expected " + FormatNumber(lo) + " .. " + FormatNumber(hi) + ")");
  return value;
}

int IntegerField(
    const TextRow& row, size_t k, const std::string& file, const char* what, int lo, int hi) {
  const double value = BoundedField(row, k, file, what, lo, hi);
  if (value != static_cast<double>(static_cast<int>(value)))
    ThrowInputError({file, row.line},
                    std::string(what) + " must be an integer (got '" + row.fields[k] + "')");
  return static_cast<int>(value);
}

const std::string& StringField(const TextRow& row,
                               size_t k,
                               const std::string& file,
                               const char* what) {
  if (k >= row.fields.size())
    ThrowInputError({file, row.line},
                    std::string("missing ") + what + " (field " + std::to_string(k + 1) + ")");
  return row.fields[k];
}

}  // namespace aerocal::triangulation::internal
