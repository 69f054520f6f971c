// Header-less text tables of other tools (DBAT, PhotoModeler, ODM, COLMAP): a line holding a comma
// is split on commas (an empty field is an error, never a column shift), others on blanks; '#'
// comment lines ('#' as the first character) and blank lines skipped; BOM, CRLF and CR line ends
// accepted; every value error as FILE:LINE.
#pragma once

#include <string>
#include <vector>

namespace aerocal::triangulation::internal {

struct TextRow {
  int line = 0;  // 1-based
  std::vector<std::string> fields;
};

/// Rows of a file; `comma_separates` also splits on commas; `keep_blank` keeps blank lines as
/// rows without fields (COLMAP's images.txt). InputError when it cannot be read.
std::vector<TextRow> ReadTextRows(const std::string& path,
                                  bool comma_separates = true,
                                  bool keep_blank = false);

/// Field k as a number; InputError("FILE:LINE: ...") when absent or not a number.
double NumberField(const TextRow& row, size_t k, const std::string& file, const char* what);
/// Field k as a number within [lo, hi]; InputError naming the range otherwise.
double BoundedField(
    const TextRow& row, size_t k, const std::string& file, const char* what, double lo, double hi);
/// Field k as an integer within [lo, hi].
int IntegerField(
    const TextRow& row, size_t k, const std::string& file, const char* what, int lo, int hi);
/// Field k as a string; InputError when absent.
const std::string& StringField(const TextRow& row,
                               size_t k,
                               const std::string& file,
                               const char* what);

}  // namespace aerocal::triangulation::internal
