// Unknown CSV columns (issue 12): a misspelt optional column (`vY_` for `vY`) must be refused by
// name, never read as an absent one.
#pragma once

#include <string>
#include <vector>

#include "calib/core/csv.h"

namespace aerocal {

/// Throws InputError("FILE:LINE: unknown column 'NAME' (known: ...)") for a column of `table`'s
/// header that is not in `known`. LINE is the header's line in table.file() (the first line that
/// is neither blank nor a '#' comment, as CsvTable::Parse reads it), found on the error path only.
void RejectUnknownColumns(const CsvTable& table, const std::vector<std::string>& known);

}  // namespace aerocal
