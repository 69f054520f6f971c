#include "calib/core/csv.h"

#include "calib/core/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string_view>

namespace aerocal {
namespace {

std::string Trim(const std::string& s) {
  const auto begin = s.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const auto end = s.find_last_not_of(" \t\r\n");
  return s.substr(begin, end - begin + 1);
}

}  // namespace

std::vector<std::string> SplitLines(const std::string& text_in) {
  std::string_view text(text_in);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte-order mark
  std::vector<std::string> lines;
  std::string line;
  for (size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (ch == '\n' || ch == '\r') {
      lines.push_back(std::move(line));
      line.clear();
      if (ch == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;  // CRLF
    } else {
      line += ch;
    }
  }
  if (!line.empty()) lines.push_back(std::move(line));
  return lines;
}

std::vector<std::string> SplitCommaList(const std::string& text, ListSplit how) {
  std::vector<std::string> out;
  if (text.empty()) return out;
  size_t begin = 0;
  while (true) {
    const size_t comma = text.find(',', begin);
    std::string field =
        text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    if (how.trim) field = Trim(field);
    if (how.keep_empty || !field.empty()) out.push_back(std::move(field));
    if (comma == std::string::npos) return out;
    begin = comma + 1;
  }
}

std::optional<double> ParseDouble(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end != text.c_str() + text.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string FormatNumber(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*g", digits, value);
  return buffer;
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& file) {
  CsvTable table;
  table.file_ = file;
  int line_number = 0;
  for (const std::string& line : SplitLines(text)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty()) continue;
    // A comment: before the header, any line whose first non-blank character is '#'; after it,
    // only such a line that cannot be a row (not the header's number of fields). A row whose
    // first field starts with '#' (an image id "#101") is data (issue 28: it was once dropped).
    if (trimmed[0] == '#' &&
        (table.header_.empty() ||
         SplitCommaList(trimmed, {true, true}).size() != table.header_.size())) {
      if (!table.header_.empty()) table.comment_lines_.push_back(line_number);
      continue;
    }
    std::vector<std::string> fields = SplitCommaList(trimmed, {true, true});
    if (table.header_.empty()) {
      // A spreadsheet's export in a comma-decimal locale separates by ';' (or a tab): said
      // before any column is looked for, instead of "missing column 'a;b;c'".
      for (const char separator : {';', '\t'})
        if (fields.size() == 1 && fields[0].find(separator) != std::string::npos)
          ThrowInputError({file, line_number},
                          std::string("the fields are separated by '") +
                              (separator == ';' ? ";" : "\\t") +
                              "', aerocal reads ',' (and '.' as the decimal mark): export the "
                              "table as comma-separated values");
      table.header_ = fields;
      table.header_line_ = line_number;
      for (size_t i = 0; i < fields.size(); ++i) {
        if (fields[i].empty()) ThrowInputError({file, line_number}, "empty column name in header");
        if (!table.columns_.emplace(fields[i], static_cast<int>(i)).second)
          ThrowInputError({file, line_number}, "duplicate column '" + fields[i] + "' in header");
      }
      continue;
    }
    if (fields.size() > table.header_.size())
      ThrowInputError({file, line_number},
                      "too many fields (got " + std::to_string(fields.size()) + ", header has " +
                          std::to_string(table.header_.size()) + ")");
    fields.resize(table.header_.size());
    table.rows_.push_back({line_number, std::move(fields)});
  }
  if (table.header_.empty())
    ThrowInputError({file, 0}, "empty file (no header row; expected a header and data rows)");
  return table;
}

CsvTable CsvTable::Read(const std::string& path) { return Parse(ReadTextFile(path), path); }

double CsvTable::Bounded(const Row& row, const std::string& column, double lo, double hi) const {
  const double value = Number(row, column);
  if (!(value >= lo && value <= hi))
    ThrowInputError(Where(row),
                    "column '" + column + "' out of range (got " + FormatNumber(value) +
                        ", expected " + FormatNumber(lo) + " .. " + FormatNumber(hi) + ")");
  return value;
}

std::optional<double> CsvTable::OptionalBounded(const Row& row,
                                                const std::string& column,
                                                double lo,
                                                double hi) const {
  if (String(row, column).empty()) return std::nullopt;
  return Bounded(row, column, lo, hi);
}

void CsvTable::RequireColumns(const std::vector<std::string>& names) const {
  for (const auto& name : names)
    if (!HasColumn(name)) ThrowInputError({file_, header_line_}, "missing column '" + name + "'");
}

void CsvTable::RejectUnknownColumns(const std::vector<std::string>& known) const {
  for (const std::string& name : header_) {
    if (std::find(known.begin(), known.end(), name) != known.end()) continue;
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    ThrowInputError({file_, header_line_}, "unknown column '" + name + "' (known: " + list + ")");
  }
}

std::string CsvTable::String(const Row& row, const std::string& column) const {
  const auto it = columns_.find(column);
  if (it == columns_.end()) return "";
  return row.fields[it->second];
}

double CsvTable::Number(const Row& row, const std::string& column) const {
  const std::string text = String(row, column);
  const auto value = ParseDouble(text);
  if (!value)
    ThrowInputError(Where(row), "column '" + column + "' must be a number (got '" + text + "')");
  return *value;
}

std::optional<double> CsvTable::OptionalNumber(const Row& row, const std::string& column) const {
  const std::string text = String(row, column);
  if (text.empty()) return std::nullopt;
  return Number(row, column);
}

}  // namespace aerocal
