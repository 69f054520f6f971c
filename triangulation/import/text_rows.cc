#include "triangulation/import/text_rows.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <sstream>

namespace aerocal::triangulation::internal {

std::vector<TextRow> ReadTextRows(const std::string& path, bool comma_separates, bool keep_blank) {
  const std::string text = ReadTextFile(path);
  std::vector<TextRow> rows;
  std::istringstream in(text);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const auto first = line.find_first_not_of(" \t");
    if (first == std::string::npos && keep_blank) {
      rows.push_back({number, {}});
      continue;
    }
    if (first == std::string::npos || line[first] == '#') continue;
    if (comma_separates)
      for (char& ch : line)
        if (ch == ',') ch = ' ';
    TextRow row;
    row.line = number;
    std::istringstream fields(line);
    std::string field;
    while (fields >> field) row.fields.push_back(field);
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
