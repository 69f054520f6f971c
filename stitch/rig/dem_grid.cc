#include "stitch/rig/dem_grid.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace aerocal::stitch {

std::optional<double> DemGrid::HeightAt(double x_m, double y_m) const {
  const double gx = (x_m - x0_m) / cell_m, gy = (y_m - y0_m) / cell_m;
  if (!(gx >= 0 && gy >= 0 && gx <= cols - 1 && gy <= rows - 1)) return std::nullopt;
  const int i = std::min(static_cast<int>(gx), cols - 2),
            j = std::min(static_cast<int>(gy), rows - 2);
  const double fx = gx - i, fy = gy - j;
  const double* south = height.data() + static_cast<size_t>(j) * cols + i;
  const double* north = south + cols;
  const double h =
      (1 - fy) * ((1 - fx) * south[0] + fx * south[1]) + fy * ((1 - fx) * north[0] + fx * north[1]);
  if (!std::isfinite(h)) return std::nullopt;
  return h;
}

double DemGrid::MeanHeight() const {
  double sum = 0.0;
  long n = 0;
  for (double h : height)
    if (std::isfinite(h)) sum += h, ++n;
  return n > 0 ? sum / n : std::numeric_limits<double>::quiet_NaN();
}

namespace {

// An ESRI ASCII grid's header: lower-case key -> (value, line), where the heights begin.
struct AsciiHeader {
  std::map<std::string, std::pair<double, int>> values;
  std::streampos data_start;
  int lines = 0;  // the header's lines (the heights start on the next)
};

std::string Where(const std::string& path, int at) {
  return path + ":" + std::to_string(at) + ": ";
}

// Keys with one number each, up to the first line that starts with a number.
AsciiHeader ReadAsciiHeader(std::istream& in, const std::string& path) {
  AsciiHeader header;
  std::string line;
  int line_no = 0;
  while (true) {
    header.data_start = in.tellg();
    if (!std::getline(in, line)) break;
    ++line_no;
    std::istringstream fields(line);
    std::string key;
    if (!(fields >> key)) continue;
    if (!std::isalpha(static_cast<unsigned char>(key[0]))) break;  // the first row of heights
    for (auto& ch : key) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    double value = 0;
    std::string rest;
    if (!(fields >> value) || (fields >> rest))
      throw InputError(Where(path, line_no) + "header '" + key + "' needs one number");
    if (!header.values.emplace(key, std::make_pair(value, line_no)).second)
      throw InputError(Where(path, line_no) + "duplicate header '" + key + "'");
  }
  header.lines = line_no - (in ? 1 : 0);
  return header;
}

// The grid's size, cell and origin (a corner moved to the first cell's centre); unknown keys
// refused.
void SetGeometry(const AsciiHeader& header, const std::string& path, DemGrid* dem) {
  const auto& values = header.values;
  auto need = [&](const std::string& a, const std::string& b) -> std::pair<double, int> {
    if (values.count(a)) return values.at(a);
    if (!b.empty() && values.count(b)) return values.at(b);
    throw InputError(Where(path, header.lines + 1) + "missing header '" + a + "'" +
                     (b.empty() ? "" : " or '" + b + "'"));
  };
  const auto [cols, cols_line] = need("ncols", "");
  const auto [rows, rows_line] = need("nrows", "");
  if (!(cols >= 2 && cols <= 1e6 && cols == std::floor(cols)))
    throw InputError(Where(path, cols_line) + "ncols must be an integer 2..1e6 (got " +
                     FormatNumber(cols) + ")");
  if (!(rows >= 2 && rows <= 1e6 && rows == std::floor(rows)))
    throw InputError(Where(path, rows_line) + "nrows must be an integer 2..1e6 (got " +
                     FormatNumber(rows) + ")");
  dem->cols = static_cast<int>(cols);
  dem->rows = static_cast<int>(rows);
  const auto [cell, cell_line] = need("cellsize", "");
  if (!(cell > 0 && std::isfinite(cell)))
    throw InputError(Where(path, cell_line) + "cellsize must be > 0 m (got " + FormatNumber(cell) +
                     ")");
  dem->cell_m = cell;
  const bool corner = values.count("xllcorner") > 0;
  dem->x0_m = need("xllcorner", "xllcenter").first + (corner ? 0.5 * cell : 0.0);
  dem->y0_m = need("yllcorner", "yllcenter").first + (values.count("yllcorner") ? 0.5 * cell : 0.0);
  for (const auto& [key, value] : values)
    if (key != "ncols" && key != "nrows" && key != "cellsize" && key != "xllcorner" &&
        key != "xllcenter" && key != "yllcorner" && key != "yllcenter" && key != "nodata_value")
      throw InputError(Where(path, value.second) + "unknown header '" + key + "'");
}

// Every height takes at least two bytes ("0 "): a header that declares more heights than the
// rest of the file can hold is refused before the grid is allocated (1e6 x 1e6 would be 8 TB).
void CheckDeclaredSize(std::istream& in,
                       const AsciiHeader& header,
                       const std::string& path,
                       const DemGrid& dem) {
  in.clear();
  in.seekg(0, std::ios::end);
  const double data_bytes = static_cast<double>(in.tellg() - header.data_start);
  const double declared = static_cast<double>(dem.cols) * dem.rows;
  if (declared > data_bytes / 2.0 + 1.0)
    throw InputError(Where(path, header.values.at("nrows").second) + "ncols x nrows = " +
                     FormatNumber(declared) + " heights, more than the file's " +
                     FormatNumber(data_bytes) + " bytes of data can hold");
}

// Heights: rows north to south in the file, stored south to north; NODATA_value -> NaN.
void ReadHeights(std::istream& in,
                 const AsciiHeader& header,
                 const std::string& path,
                 DemGrid* dem) {
  const bool has_nodata = header.values.count("nodata_value") > 0;
  const double nodata = has_nodata ? header.values.at("nodata_value").first : 0.0;
  dem->height.assign(static_cast<size_t>(dem->cols) * dem->rows, 0.0);
  in.seekg(header.data_start);
  int line_no = header.lines;
  int valid = 0;
  std::string line;
  for (int r = 0; r < dem->rows; ++r) {
    if (!std::getline(in, line))
      throw InputError(Where(path, line_no + 1) + "expected " + std::to_string(dem->rows) +
                       " rows of heights, got " + std::to_string(r));
    ++line_no;
    std::istringstream fields(line);
    const size_t row_start = static_cast<size_t>(dem->rows - 1 - r) * dem->cols;
    for (int c = 0; c < dem->cols; ++c) {
      double h = 0;
      if (!(fields >> h))
        throw InputError(Where(path, line_no) + "expected " + std::to_string(dem->cols) +
                         " heights, got " + std::to_string(c));
      if (has_nodata && h == nodata)
        h = std::numeric_limits<double>::quiet_NaN();
      else if (!(std::abs(h) <= 1e5))
        throw InputError(Where(path, line_no) + "height out of range (got " + FormatNumber(h) +
                         ")");
      else
        ++valid;
      dem->height[row_start + c] = h;
    }
    std::string rest;
    if (fields >> rest)
      throw InputError(Where(path, line_no) + "more than " + std::to_string(dem->cols) +
                       " heights");
  }
  if (valid == 0) throw InputError(path + ": the DEM has no valid height");
}

}  // namespace

DemGrid ReadDemAscii(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the DEM");
  const AsciiHeader header = ReadAsciiHeader(in, path);
  DemGrid dem;
  SetGeometry(header, path, &dem);
  CheckDeclaredSize(in, header, path, dem);
  ReadHeights(in, header, path, &dem);
  return dem;
}

std::optional<Eigen::Vector3d> IntersectDem(const DemGrid& dem,
                                            const Eigen::Vector3d& origin,
                                            const Eigen::Vector3d& direction) {
  if (!(std::abs(direction.z()) > 1e-12)) return std::nullopt;
  double z = dem.MeanHeight();
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double s = (z - origin.z()) / direction.z();
    if (!(s > 0)) return std::nullopt;
    const Eigen::Vector3d p = origin + s * direction;
    const auto h = dem.HeightAt(p.x(), p.y());
    if (!h) return std::nullopt;
    if (std::abs(*h - z) < 1e-6) return Eigen::Vector3d(p.x(), p.y(), *h);
    z = *h;
  }
  return std::nullopt;
}

}  // namespace aerocal::stitch
