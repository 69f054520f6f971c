#include "tools/observation_tables.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/file_digest.h"
#include "calib/core/string_printf.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iterator>
#include <optional>
#include <set>

namespace aerocal::tools {
namespace {

enum class Cell { kString, kNumber, kBool, kInteger };

// One CSV column: the JSON key of a residual entry and, for the two-element arrays of the test
// (r, w_xy, mdb_sigma, mdb_px), which element. `tested`: the key exists only for a tested
// observation (AddTest in adjustment_result.cc), so an empty cell there is a null, not an absence.
struct Column {
  const char* name;
  const char* key;
  int element;  // -1: the key's value itself; 0 / 1: photo x / y of a pair
  Cell cell;
  bool tested;
  bool null_if_empty = false;  // the key is always there: an empty cell is its null
};

// An adjustment's residual table (residuals_<adjustment>.csv).
constexpr Column kColumns[] = {{"image", "image", -1, Cell::kString, false},
                               {"point", "point", -1, Cell::kString, false},
                               {"col", "col", -1, Cell::kNumber, false},
                               {"row", "row", -1, Cell::kNumber, false},
                               {"v_col_px", "v_col_px", -1, Cell::kNumber, false},
                               {"v_row_px", "v_row_px", -1, Cell::kNumber, false},
                               {"sigma_px", "sigma_px", -1, Cell::kNumber, false},
                               {"used", "used", -1, Cell::kBool, false},
                               {"subimage", "subimage", -1, Cell::kString, false},
                               {"u", "u", -1, Cell::kNumber, false},
                               {"v", "v", -1, Cell::kNumber, false},
                               {"head", "head", -1, Cell::kString, false},
                               {"group_size", "group_size", -1, Cell::kInteger, true},
                               {"verdict", "verdict", -1, Cell::kString, true},
                               {"r_x", "r", 0, Cell::kNumber, true},
                               {"r_y", "r", 1, Cell::kNumber, true},
                               {"w_x", "w_xy", 0, Cell::kNumber, true},
                               {"w_y", "w_xy", 1, Cell::kNumber, true},
                               {"mdb_sigma_x", "mdb_sigma", 0, Cell::kNumber, true},
                               {"mdb_sigma_y", "mdb_sigma", 1, Cell::kNumber, true},
                               {"mdb_px_x", "mdb_px", 0, Cell::kNumber, true},
                               {"mdb_px_y", "mdb_px", 1, Cell::kNumber, true},
                               {"reason", "reason", -1, Cell::kString, false}};

// The stitching frames' residual table (residuals_stitching.csv): every frame's `residuals`
// entries (stitch_result_json.cc, FrameResultToJson) in the frames' order, each row with its
// frame's id; every key is always written, sigma_px may be null.
constexpr Column kStitchingColumns[] = {{"frame", "frame", -1, Cell::kString, false},
                                        {"point", "point", -1, Cell::kString, false},
                                        {"subimage", "subimage", -1, Cell::kString, false},
                                        {"kind", "kind", -1, Cell::kString, false},
                                        {"vU_px", "vU_px", -1, Cell::kNumber, false},
                                        {"vV_px", "vV_px", -1, Cell::kNumber, false},
                                        {"sigma_px", "sigma_px", -1, Cell::kNumber, false, true}};

// A table: its columns and the column whose empty cell marks an untested row (-1: none).
struct Table {
  const Column* begin;
  const Column* end;
  int tested_marker;
  size_t size() const { return static_cast<size_t>(end - begin); }
};

constexpr Table kAdjustmentTable = {std::begin(kColumns), std::end(kColumns), 12};  // group_size
constexpr Table kStitchingTable = {std::begin(kStitchingColumns), std::end(kStitchingColumns), -1};

constexpr const char* kStitchingTableFile = "residuals_stitching.csv";

// RFC 4180: a field with a separator, a quote or a line break is quoted, quotes doubled.
std::string Quoted(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string CellText(const nlohmann::json& value, Cell cell) {
  if (value.is_null()) return "";
  switch (cell) {
    case Cell::kString:
      return Quoted(value.get<std::string>());
    case Cell::kBool:
      return value.get<bool>() ? "true" : "false";
    case Cell::kInteger:
      return std::to_string(value.get<long long>());
    case Cell::kNumber:
      return StringPrintf("%.17g", value.get<double>());
  }
  return "";
}

// The records of a CSV text (RFC 4180 quoting), each with the line it starts on.
std::vector<std::pair<int, std::vector<std::string>>> Records(const std::string& text,
                                                              const std::string& file) {
  std::vector<std::pair<int, std::vector<std::string>>> out;
  std::vector<std::string> fields(1);
  bool quoted = false, any = false;
  int line = 1, start = 1;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        if (c == '\n') ++line;
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = any = true;
    } else if (c == ',') {
      fields.emplace_back();
      any = true;
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      if (any || !fields[0].empty()) out.push_back({start, fields});
      fields.assign(1, "");
      any = false;
      start = ++line;
    } else {
      fields.back() += c;
      any = true;
    }
  }
  if (quoted)
    throw InputError(StringPrintf("%s:%d: a quoted field is not closed", file.c_str(), start));
  if (any || !fields[0].empty()) out.push_back({start, fields});
  return out;
}

nlohmann::json ParseCell(const std::string& text, Cell cell, const std::string& where) {
  if (cell == Cell::kString) return text;
  if (cell == Cell::kBool) {
    if (text == "true" || text == "false") return text == "true";
    throw InputError(where + ": expected true or false (got '" + text + "')");
  }
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(x))
    throw InputError(where + ": expected a finite number (got '" + text + "')");
  if (cell == Cell::kInteger) return static_cast<long long>(x);
  return x;
}

std::vector<std::string> Names(const Table& table) {
  std::vector<std::string> out;
  for (const Column* c = table.begin; c != table.end; ++c) out.emplace_back(c->name);
  return out;
}

std::string TableCsv(const Table& table, const nlohmann::json& entries) {
  std::string out;
  for (const Column* c = table.begin; c != table.end; ++c)
    out += std::string(out.empty() ? "" : ",") + c->name;
  out += "\n";
  for (const auto& entry : entries) {
    std::string line;
    for (const Column* c = table.begin; c != table.end; ++c) {
      if (c != table.begin) line += ",";
      const auto it = entry.find(c->key);
      if (it == entry.end()) continue;
      line += CellText(c->element < 0 ? *it : (*it)[c->element], c->cell);
    }
    out += line + "\n";
  }
  return out;
}

nlohmann::json TableFromCsv(const Table& table, const std::string& text, const std::string& file) {
  const auto records = Records(text, file);
  const std::vector<std::string> columns = Names(table);
  if (records.empty() || records[0].second != columns)
    throw InputError(file + ":1: not a residual table (expected the header " +
                     nlohmann::json(columns).dump() + ")");
  nlohmann::json out = nlohmann::json::array();
  for (size_t k = 1; k < records.size(); ++k) {
    const auto& [line, fields] = records[k];
    const std::string where = file + ":" + std::to_string(line);
    if (fields.size() != columns.size())
      throw InputError(where +
                       StringPrintf(": %zu fields (expected %zu)", fields.size(), columns.size()));
    nlohmann::json entry = nlohmann::json::object();
    // The test's keys are there when the marker column is filled.
    const bool tested = table.tested_marker >= 0 && !fields[table.tested_marker].empty();
    for (size_t i = 0; i < columns.size(); ++i) {
      const Column& c = table.begin[i];
      const std::string& f = fields[i];
      const std::string at = where + " (" + c.name + ")";
      if (c.tested && !tested) continue;
      if (c.element >= 0) {
        if (!entry.contains(c.key)) entry[c.key] = {nullptr, nullptr};
        if (!f.empty()) entry[c.key][c.element] = ParseCell(f, c.cell, at);
      } else if (f.empty() && c.null_if_empty) {
        entry[c.key] = nullptr;
      } else if (!f.empty() || (c.tested && c.cell == Cell::kString)) {
        entry[c.key] = ParseCell(f, c.cell, at);
      }
    }
    out.push_back(entry);
  }
  return out;
}

// The table's text of `entries` when it reads back to exactly them (every key has a column,
// every value its column's type and no null where an empty cell means an absent key); nullopt
// otherwise: such entries stay in the JSON, nothing is dropped.
std::optional<std::string> LosslessCsv(const Table& table, const nlohmann::json& entries) {
  try {
    std::string text = TableCsv(table, entries);
    if (TableFromCsv(table, text, "") == entries) return text;
  } catch (const nlohmann::json::exception&) {
  } catch (const InputError&) {
  }
  return std::nullopt;
}

// `text` written as `name` in `folder`, and the `residuals_file` that names it.
nlohmann::json WriteTable(const std::string& folder,
                          const std::string& name,
                          const std::string& text,
                          size_t rows,
                          const Table& table) {
  WriteFileAtomically((std::filesystem::path(folder) / name).string(), text);
  return {{"path", name}, {"sha256", Sha256Hex(text)}, {"rows", rows}, {"columns", Names(table)}};
}

// The text of the table `spec` (a `residuals_file`) names, beside `result_path`, checked against
// its SHA-256; `path` is set to the table's path for messages.
std::string ReadTable(const nlohmann::json& spec,
                      const std::string& result_path,
                      const std::string& key,
                      std::string* path) {
  if (!spec.is_object() || !spec.contains("path") || !spec["path"].is_string() ||
      !spec.contains("sha256") || !spec["sha256"].is_string())
    throw InputError(result_path + ": " + key + ".residuals_file needs a path and a sha256");
  *path =
      (std::filesystem::path(result_path).parent_path() / spec["path"].get<std::string>()).string();
  const std::string text = ReadTextFile(*path);
  if (Sha256Hex(text) != spec["sha256"].get<std::string>())
    throw InputError(*path + ": SHA-256 differs from the one " + result_path +
                     " states (the table was changed or belongs to another result)");
  return text;
}

// The stitching frames' residuals as one table (rows in frame order, each with its frame's id);
// nullopt when the flight has none, frame ids repeat (rows could not be given back) or the
// entries are not lossless in the table.
std::optional<std::string> StitchingTable(const nlohmann::json& frames, size_t* rows) {
  nlohmann::json all = nlohmann::json::array();
  std::set<std::string> ids;
  for (const auto& f : frames) {
    if (!f.is_object() || !f.contains("frame") || !f["frame"].is_string() ||
        !f.contains("residuals") || !f["residuals"].is_array() ||
        !ids.insert(f["frame"].get<std::string>()).second)
      return std::nullopt;
    for (const auto& r : f["residuals"]) {
      if (!r.is_object() || r.contains("frame")) return std::nullopt;
      all.push_back(r);
      all.back()["frame"] = f["frame"];
    }
  }
  *rows = all.size();
  if (ids.empty()) return std::nullopt;
  return LosslessCsv(kStitchingTable, all);
}

std::string SplitStitchingTable(nlohmann::json* document, const std::string& folder) {
  if (!document->contains("stitching") || !(*document)["stitching"].is_object()) return "";
  nlohmann::json& stitching = (*document)["stitching"];
  if (!stitching.contains("frames") || !stitching["frames"].is_array()) return "";
  size_t rows = 0;
  const auto text = StitchingTable(stitching["frames"], &rows);
  if (!text) return "";
  stitching["residuals_file"] =
      WriteTable(folder, kStitchingTableFile, *text, rows, kStitchingTable);
  for (auto& f : stitching["frames"]) f.erase("residuals");
  return kStitchingTableFile;
}

// The rows of the stitching table handed back to their frames: in frame order, a frame's rows
// together (as StitchingTable wrote them).
void InflateStitchingTable(nlohmann::json* document, const std::string& result_path) {
  if (!document->contains("stitching") || !(*document)["stitching"].is_object()) return;
  nlohmann::json& stitching = (*document)["stitching"];
  if (!stitching.contains("residuals_file")) return;
  if (!stitching.contains("frames") || !stitching["frames"].is_array())
    throw InputError(result_path + ": stitching.residuals_file without stitching.frames");
  std::string path;
  const std::string text = ReadTable(stitching["residuals_file"], result_path, "stitching", &path);
  nlohmann::json& frames = stitching["frames"];
  for (auto& f : frames) f["residuals"] = nlohmann::json::array();
  size_t k = 0, row = 1;
  for (auto& entry : TableFromCsv(kStitchingTable, text, path)) {
    ++row;
    while (k < frames.size() && frames[k].value("frame", std::string()) != entry["frame"]) ++k;
    if (k == frames.size())
      throw InputError(path + StringPrintf(":%zu: frame '", row) +
                       entry["frame"].get<std::string>() + "' is not a frame of " + result_path +
                       " after the previous row's (rows are in the frames' order)");
    entry.erase("frame");
    frames[k]["residuals"].push_back(std::move(entry));
  }
  stitching.erase("residuals_file");
}

}  // namespace

std::vector<std::string> ResidualTableColumns() { return Names(kAdjustmentTable); }

std::string ResidualTableCsv(const nlohmann::json& residuals) {
  return TableCsv(kAdjustmentTable, residuals);
}

nlohmann::json ResidualTableFromCsv(const std::string& text, const std::string& file) {
  return TableFromCsv(kAdjustmentTable, text, file);
}

std::string ResidualTableFile(const std::string& adjustment) {
  return "residuals_" + adjustment + ".csv";
}

std::vector<std::string> ResidualTablesNotWritten(const std::vector<std::string>& written) {
  std::vector<std::string> out;
  for (const std::string& file : {ResidualTableFile("conventional"),
                                  ResidualTableFile("self_calibration"),
                                  ResidualTableFile("joint"),
                                  std::string(kStitchingTableFile)})
    if (std::find(written.begin(), written.end(), file) == written.end()) out.push_back(file);
  return out;
}

std::vector<std::string> SplitResidualTables(nlohmann::json* document, const std::string& folder) {
  std::vector<std::string> written;
  if (document->contains("adjustments") && (*document)["adjustments"].is_array())
    for (auto& a : (*document)["adjustments"]) {
      if (!a.is_object() || !a.contains("residuals")) continue;
      const auto text = LosslessCsv(kAdjustmentTable, a["residuals"]);
      if (!text) continue;
      const std::string name = ResidualTableFile(a.value("name", std::to_string(written.size())));
      a["residuals_file"] =
          WriteTable(folder, name, *text, a["residuals"].size(), kAdjustmentTable);
      a.erase("residuals");
      written.push_back(name);
    }
  const std::string stitching = SplitStitchingTable(document, folder);
  if (!stitching.empty()) written.push_back(stitching);
  return written;
}

void InflateResidualTables(nlohmann::json* document, const std::string& result_path) {
  if (document->contains("adjustments") && (*document)["adjustments"].is_array())
    for (auto& a : (*document)["adjustments"]) {
      if (!a.is_object() || !a.contains("residuals_file")) continue;
      std::string path;
      const std::string text =
          ReadTable(a["residuals_file"], result_path, a.value("name", "adjustment"), &path);
      a["residuals"] = ResidualTableFromCsv(text, path);
      a.erase("residuals_file");
    }
  InflateStitchingTable(document, result_path);
}

}  // namespace aerocal::tools
