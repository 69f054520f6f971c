// Per-observation tables of a flight result as CSV sidecars (issue 33 item 3): a 37-image flight's
// result.json holds about a hundred thousand residual entries per adjustment (23 MB), too much
// for an editor or a browser's JSON viewer. With `flight --residuals-csv` each adjustment's
// `residuals` array is written as `residuals_<adjustment>.csv` beside result.json, and the array
// is replaced by
//
//   "residuals_file": {"path": "residuals_joint.csv", "sha256": "...", "rows": 104512,
//                      "columns": ["image", "point", "col", ...]}
//
// The stitching frames' residuals (`stitching.frames[].residuals`, about 70k entries and 17 MB of
// the same flight's JSON) go the same way into one table, `residuals_stitching.csv`, with the
// frame's id in its first column; `stitching.residuals_file` names it and the frames lose their
// arrays.
//
// A table holds exactly what the arrays held (docs/formats.md "residuals_<adjustment>.csv"): one
// row per entry; numbers in the shortest text that reads back to the same double (%.17g), so
// reading the table back gives the same JSON; `r`, `w_xy`, `mdb_sigma`, `mdb_px` as two columns
// each (_x, _y; photo x, y); an empty cell is an absent key (subimage, u, v, head, reason, and the
// test's keys of an untested observation: `group_size` empty) or, within a tested row, a null
// (an untestable component's w); in the stitching table an empty sigma_px is a null. Text cells
// are quoted as RFC 4180 says where needed (a reason with commas). An array the table would not
// give back exactly (a key without a column, a value of another type) stays in the JSON. Every
// reader of result.json inflates the tables first (report_data.load in Python,
// InflateResidualTables here), checking the SHA-256.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aerocal::tools {

/// The table file of adjustment `adjustment`: residuals_<adjustment>.csv.
std::string ResidualTableFile(const std::string& adjustment);
/// The tables a flight can write (its adjustments' and residuals_stitching.csv) that are not
/// among `written`: a previous run's there would not describe this one (to be removed).
std::vector<std::string> ResidualTablesNotWritten(const std::vector<std::string>& written);
/// Writes every adjustment's `residuals` of `document` (a flight result: `adjustments[]`) to
/// `folder/residuals_<name>.csv` and the stitching frames' (`stitching.frames[].residuals`) to
/// `folder/residuals_stitching.csv` (atomically), replacing the arrays by `residuals_file` (of
/// the adjustment, of `stitching`). An array the table would not give back exactly keeps its
/// place (nothing is dropped); so do the frames' when two share an id. Returns the file names
/// written (relative to `folder`).
std::vector<std::string> SplitResidualTables(nlohmann::json* document, const std::string& folder);

/// The inverse for a reader: every `residuals_file` of `document`'s adjustments and of its
/// `stitching` read from the folder of `result_path` back into the `residuals` arrays (the same
/// JSON values). InputError naming the file when it is missing, its SHA-256 differs from the
/// result's, or a row is malformed or names no frame of the result (FILE:LINE).
void InflateResidualTables(nlohmann::json* document, const std::string& result_path);

/// The CSV text of one residual array and its inverse (for tests; FILE names messages).
std::string ResidualTableCsv(const nlohmann::json& residuals);
nlohmann::json ResidualTableFromCsv(const std::string& text, const std::string& file);
/// The table's columns, in order.
std::vector<std::string> ResidualTableColumns();

}  // namespace aerocal::tools
