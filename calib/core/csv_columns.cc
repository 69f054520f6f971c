#include "calib/core/csv_columns.h"

#include <algorithm>

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"

namespace aerocal {
namespace {

// The header's 1-based line in `path` (1 when the file cannot be read again: a table parsed
// from text under a name that is not a path).
int HeaderLine(const std::string& path) {
  std::string text;
  try {
    text = ReadTextFile(path);
  } catch (const Error&) {
    return 1;
  }
  int line = 0;
  for (const std::string& l : SplitLines(text)) {
    ++line;
    if (l.find_first_not_of(" \t\r\n") == std::string::npos || l[0] == '#') continue;
    return line;
  }
  return 1;
}

}  // namespace

void RejectUnknownColumns(const CsvTable& table, const std::vector<std::string>& known) {
  for (const std::string& name : table.header()) {
    if (std::find(known.begin(), known.end(), name) != known.end()) continue;
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
    ThrowInputError({table.file(), HeaderLine(table.file())},
                    "unknown column '" + name + "' (known: " + list + ")");
  }
}

}  // namespace aerocal
