// CSV tables as FORMATS.md defines them: a header row, comma separators, '#' comment lines, blank
// lines ignored, fields trimmed, a UTF-8 byte-order mark and CRLF or CR line ends accepted. Every
// value access names FILE:LINE in its error.
// Comments (issue 28): before the header, every line whose first non-blank character is '#';
// after the header, such a line only when it does not have the header's number of fields. A line
// that does is a row whose first field starts with '#' (an id "#101" is an id, never a comment).
// The comment lines after the header are kept by number (comment_lines) so that a reader can
// name them.
#pragma once

#include "calib/core/error.h"

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal {

class CsvTable {
 public:
  /// Parses CSV text. `file` is used in messages only.
  static CsvTable Parse(const std::string& text, const std::string& file);
  /// Reads and parses a file; throws InputError when it is missing or malformed.
  static CsvTable Read(const std::string& path);

  struct Row {
    int line = 0;  // 1-based line number in the file
    std::vector<std::string> fields;
  };

  const std::string& file() const { return file_; }
  const std::vector<std::string>& header() const { return header_; }
  const std::vector<Row>& rows() const { return rows_; }
  /// Line numbers of the comment lines after the header (those before it are the file's preamble).
  const std::vector<int>& comment_lines() const { return comment_lines_; }
  bool HasColumn(const std::string& name) const { return columns_.count(name) > 0; }
  /// Throws InputError("FILE:HEADER_LINE: missing column NAME") when absent.
  void RequireColumns(const std::vector<std::string>& names) const;
  /// Throws InputError("FILE:HEADER_LINE: unknown column 'NAME' (known: ...)") for a header column
  /// not in `known` (issue 12: a misspelt optional column, `vY_` for `vY`, is refused by name,
  /// never read as an absent one).
  void RejectUnknownColumns(const std::vector<std::string>& known) const;

  SourceRef Where(const Row& row) const { return {file_, row.line}; }
  /// Raw string of a column (empty when the column is absent or the field is empty).
  std::string String(const Row& row, const std::string& column) const;
  /// Parsed number; throws InputError naming file, line, column and value when not a number.
  double Number(const Row& row, const std::string& column) const;
  /// Number when present and non-empty, nullopt otherwise.
  std::optional<double> OptionalNumber(const Row& row, const std::string& column) const;
  /// Number within [lo, hi]; InputError naming the range otherwise.
  double Bounded(const Row& row, const std::string& column, double lo, double hi) const;
  std::optional<double> OptionalBounded(const Row& row,
                                        const std::string& column,
                                        double lo,
                                        double hi) const;

 private:
  std::string file_;
  int header_line_ = 0;
  std::vector<std::string> header_;
  std::map<std::string, int> columns_;
  std::vector<Row> rows_;
  std::vector<int> comment_lines_;
};

/// Lines of a text: LF, CRLF or CR line ends; a leading UTF-8 byte-order mark is dropped.
std::vector<std::string> SplitLines(const std::string& text);

/// How SplitCommaList splits `text` at commas: fields trimmed of blanks (space, tab, CR, LF) or
/// not; empty fields kept (n commas give n + 1 fields: a row or a value list, where an empty field
/// must be seen) or dropped (a list of names or ID=PATH items, where a stray comma means nothing).
/// An empty text has no fields.
struct ListSplit {
  bool trim = true;
  bool keep_empty = false;
};
/// THE comma splitter (CSV rows, command-line lists, lists inside XML tags).
std::vector<std::string> SplitCommaList(const std::string& text, ListSplit how = {});

/// Parses a double from the whole of `text`; nullopt when it is not a finite number.
std::optional<double> ParseDouble(const std::string& text);

/// Formats a double with up to `digits` significant digits, shortest exact form otherwise.
std::string FormatNumber(double value, int digits = 12);

}  // namespace aerocal
