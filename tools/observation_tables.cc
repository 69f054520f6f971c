#include "tools/observation_tables.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "calib/core/file_digest.h"
#include "calib/core/string_printf.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
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
};

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

// Whether every key of every entry has a column (else the table would drop it).
bool Representable(const nlohmann::json& residuals) {
  std::set<std::string> keys;
  for (const auto& c : kColumns) keys.insert(c.key);
  for (const auto& entry : residuals) {
    if (!entry.is_object()) return false;
    for (const auto& [key, value] : entry.items()) {
      if (!keys.count(key)) return false;
      const bool pair = key == "r" || key == "w_xy" || key == "mdb_sigma" || key == "mdb_px";
      if (pair && !(value.is_array() && value.size() == 2)) return false;
      if (!pair && value.is_structured()) return false;
    }
  }
  return true;
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

}  // namespace

std::vector<std::string> ResidualTableColumns() {
  std::vector<std::string> out;
  for (const auto& c : kColumns) out.emplace_back(c.name);
  return out;
}

std::string ResidualTableCsv(const nlohmann::json& residuals) {
  std::string out;
  for (const auto& c : kColumns) out += std::string(out.empty() ? "" : ",") + c.name;
  out += "\n";
  for (const auto& entry : residuals) {
    std::string line;
    bool first = true;
    for (const auto& c : kColumns) {
      if (!first) line += ",";
      first = false;
      const auto it = entry.find(c.key);
      if (it == entry.end()) continue;
      line += CellText(c.element < 0 ? *it : (*it)[c.element], c.cell);
    }
    out += line + "\n";
  }
  return out;
}

nlohmann::json ResidualTableFromCsv(const std::string& text, const std::string& file) {
  const auto records = Records(text, file);
  const std::vector<std::string> columns = ResidualTableColumns();
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
    const bool tested = !fields[12].empty();  // group_size: the test's keys are there
    for (size_t i = 0; i < columns.size(); ++i) {
      const Column& c = kColumns[i];
      const std::string& f = fields[i];
      const std::string at = where + " (" + c.name + ")";
      if (c.tested && !tested) continue;
      if (c.element >= 0) {
        if (!entry.contains(c.key)) entry[c.key] = {nullptr, nullptr};
        if (!f.empty()) entry[c.key][c.element] = ParseCell(f, c.cell, at);
      } else if (!f.empty() || (c.tested && c.cell == Cell::kString)) {
        entry[c.key] = ParseCell(f, c.cell, at);
      }
    }
    out.push_back(entry);
  }
  return out;
}

std::string ResidualTableFile(const std::string& adjustment) {
  return "residuals_" + adjustment + ".csv";
}

std::vector<std::string> ResidualTablesNotWritten(const std::vector<std::string>& written) {
  std::vector<std::string> out;
  for (const char* adjustment : {"conventional", "self_calibration", "joint"}) {
    const std::string file = ResidualTableFile(adjustment);
    if (std::find(written.begin(), written.end(), file) == written.end()) out.push_back(file);
  }
  return out;
}

std::vector<std::string> SplitResidualTables(nlohmann::json* document, const std::string& folder) {
  std::vector<std::string> written;
  if (!document->contains("adjustments")) return written;
  for (auto& a : (*document)["adjustments"]) {
    if (!a.contains("residuals") || !Representable(a["residuals"])) continue;
    const std::string name = ResidualTableFile(a.value("name", std::to_string(written.size())));
    const std::string text = ResidualTableCsv(a["residuals"]);
    WriteFileAtomically((std::filesystem::path(folder) / name).string(), text);
    a["residuals_file"] = {{"path", name},
                           {"sha256", Sha256Hex(text)},
                           {"rows", a["residuals"].size()},
                           {"columns", ResidualTableColumns()}};
    a.erase("residuals");
    written.push_back(name);
  }
  return written;
}

void InflateResidualTables(nlohmann::json* document, const std::string& result_path) {
  if (!document->contains("adjustments") || !(*document)["adjustments"].is_array()) return;
  const std::filesystem::path folder = std::filesystem::path(result_path).parent_path();
  for (auto& a : (*document)["adjustments"]) {
    if (!a.is_object() || !a.contains("residuals_file")) continue;
    const nlohmann::json& f = a["residuals_file"];
    if (!f.is_object() || !f.contains("path") || !f["path"].is_string() || !f.contains("sha256") ||
        !f["sha256"].is_string())
      throw InputError(result_path + ": residuals_file needs a path and a sha256");
    const std::string path = (folder / f["path"].get<std::string>()).string();
    const std::string text = ReadTextFile(path);
    if (Sha256Hex(text) != f["sha256"].get<std::string>())
      throw InputError(path + ": SHA-256 differs from the one " + result_path +
                       " states (the table was changed or belongs to another result)");
    a["residuals"] = ResidualTableFromCsv(text, path);
    a.erase("residuals_file");
  }
}

}  // namespace aerocal::tools
