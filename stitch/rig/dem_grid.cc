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

DemGrid ReadDemAscii(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the DEM");
  std::map<std::string, std::pair<double, int>> header;  // lower-case key -> value, line
  std::string line;
  int line_no = 0;
  auto where = [&](int at) { return path + ":" + std::to_string(at) + ": "; };
  std::streampos data_start = in.tellg();
  while (true) {
    data_start = in.tellg();
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
      throw InputError(where(line_no) + "header '" + key + "' needs one number");
    if (!header.emplace(key, std::make_pair(value, line_no)).second)
      throw InputError(where(line_no) + "duplicate header '" + key + "'");
  }
  const int header_lines = line_no - (in ? 1 : 0);
  auto need = [&](const std::string& a, const std::string& b) -> std::pair<double, int> {
    if (header.count(a)) return header.at(a);
    if (!b.empty() && header.count(b)) return header.at(b);
    throw InputError(where(header_lines + 1) + "missing header '" + a + "'" +
                     (b.empty() ? "" : " or '" + b + "'"));
  };
  DemGrid dem;
  const auto [cols, cols_line] = need("ncols", "");
  const auto [rows, rows_line] = need("nrows", "");
  if (!(cols >= 2 && cols <= 1e6 && cols == std::floor(cols)))
    throw InputError(where(cols_line) + "ncols must be an integer 2..1e6 (got " +
                     FormatNumber(cols) + ")");
  if (!(rows >= 2 && rows <= 1e6 && rows == std::floor(rows)))
    throw InputError(where(rows_line) + "nrows must be an integer 2..1e6 (got " +
                     FormatNumber(rows) + ")");
  dem.cols = static_cast<int>(cols);
  dem.rows = static_cast<int>(rows);
  const auto [cell, cell_line] = need("cellsize", "");
  if (!(cell > 0 && std::isfinite(cell)))
    throw InputError(where(cell_line) + "cellsize must be > 0 m (got " + FormatNumber(cell) + ")");
  dem.cell_m = cell;
  const bool corner = header.count("xllcorner") > 0;
  dem.x0_m = need("xllcorner", "xllcenter").first + (corner ? 0.5 * cell : 0.0);
  dem.y0_m = need("yllcorner", "yllcenter").first + (header.count("yllcorner") ? 0.5 * cell : 0.0);
  const bool has_nodata = header.count("nodata_value") > 0;
  const double nodata = has_nodata ? header.at("nodata_value").first : 0.0;
  for (const auto& [key, value] : header)
    if (key != "ncols" && key != "nrows" && key != "cellsize" && key != "xllcorner" &&
        key != "xllcenter" && key != "yllcorner" && key != "yllcenter" && key != "nodata_value")
      throw InputError(where(value.second) + "unknown header '" + key + "'");
  // Every height takes at least two bytes ("0 "): a header that declares more heights than the
  // rest of the file can hold is refused before the grid is allocated (1e6 x 1e6 would be 8 TB).
  in.clear();
  in.seekg(0, std::ios::end);
  const double data_bytes = static_cast<double>(in.tellg() - data_start);
  const double declared = static_cast<double>(dem.cols) * dem.rows;
  if (declared > data_bytes / 2.0 + 1.0)
    throw InputError(where(rows_line) + "ncols x nrows = " + FormatNumber(declared) +
                     " heights, more than the file's " + FormatNumber(data_bytes) +
                     " bytes of data can hold");
  // Heights: rows north to south in the file, stored south to north.
  dem.height.assign(static_cast<size_t>(dem.cols) * dem.rows, 0.0);
  in.seekg(data_start);
  line_no = header_lines;
  int valid = 0;
  for (int r = 0; r < dem.rows; ++r) {
    if (!std::getline(in, line))
      throw InputError(where(line_no + 1) + "expected " + std::to_string(dem.rows) +
                       " rows of heights, got " + std::to_string(r));
    ++line_no;
    std::istringstream fields(line);
    const size_t row_start = static_cast<size_t>(dem.rows - 1 - r) * dem.cols;
    for (int c = 0; c < dem.cols; ++c) {
      double h = 0;
      if (!(fields >> h))
        throw InputError(where(line_no) + "expected " + std::to_string(dem.cols) +
                         " heights, got " + std::to_string(c));
      if (has_nodata && h == nodata)
        h = std::numeric_limits<double>::quiet_NaN();
      else if (!(std::abs(h) <= 1e5))
        throw InputError(where(line_no) + "height out of range (got " + FormatNumber(h) + ")");
      else
        ++valid;
      dem.height[row_start + c] = h;
    }
    std::string rest;
    if (fields >> rest)
      throw InputError(where(line_no) + "more than " + std::to_string(dem.cols) + " heights");
  }
  if (valid == 0) throw InputError(path + ": the DEM has no valid height");
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
