#include "triangulation/pushbroom/pos_trajectory.h"

#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "triangulation/block/value_bounds.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace aerocal::triangulation {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
// Bounds as the block files (block/value_bounds.h), plus the line number and time of a POS row.
using namespace bounds;
constexpr double kMaxLine = 1e9;
constexpr double kMaxTimeS = 1e10;

std::optional<Eigen::Vector3d> SigmaTriple(const CsvTable& t,
                                           const CsvTable::Row& row,
                                           const char* a,
                                           const char* b,
                                           const char* c,
                                           double hi) {
  const auto x = t.OptionalBounded(row, a, 0.0, hi), y = t.OptionalBounded(row, b, 0.0, hi),
             z = t.OptionalBounded(row, c, 0.0, hi);
  if (!x && !y && !z) return std::nullopt;
  if (!x || !y || !z || !(*x > 0 && *y > 0 && *z > 0))
    ThrowInputError(t.Where(row),
                    std::string(a) + ", " + b + ", " + c + " must be given together and be > 0");
  return Eigen::Vector3d(*x, *y, *z);
}

std::optional<Eigen::Vector3d> Median3(const std::vector<PosRecord>& records, bool center) {
  std::vector<double> v[3];
  for (const auto& r : records) {
    const auto& s = center ? r.center_sigma_m : r.opk_sigma_rad;
    if (s)
      for (int a = 0; a < 3; ++a) v[a].push_back((*s)[a]);
  }
  if (v[0].empty()) return std::nullopt;
  Eigen::Vector3d out;
  for (int a = 0; a < 3; ++a) {
    std::sort(v[a].begin(), v[a].end());
    out[a] = v[a][v[a].size() / 2];
  }
  return out;
}

}  // namespace

PosTrajectory PosTrajectory::Read(const std::string& path) {
  const CsvTable t = CsvTable::Read(path);
  t.RequireColumns({"line", "time_s", "X", "Y", "Z", "omega", "phi", "kappa"});
  t.RejectUnknownColumns({"line",
                          "time_s",
                          "X",
                          "Y",
                          "Z",
                          "omega",
                          "phi",
                          "kappa",
                          "sX",
                          "sY",
                          "sZ",
                          "somega",
                          "sphi",
                          "skappa"});
  std::vector<PosRecord> records;
  for (const auto& row : t.rows()) {
    PosRecord r;
    r.source_line = row.line;
    r.line = t.OptionalBounded(row, "line", -kMaxLine, kMaxLine);
    r.time_s = t.Bounded(row, "time_s", -kMaxTimeS, kMaxTimeS);
    r.center_m = {t.Bounded(row, "X", -kMaxCoordinateM, kMaxCoordinateM),
                  t.Bounded(row, "Y", -kMaxCoordinateM, kMaxCoordinateM),
                  t.Bounded(row, "Z", -kMaxCoordinateM, kMaxCoordinateM)};
    r.opk_rad = Eigen::Vector3d(t.Bounded(row, "omega", -kMaxAngleDeg, kMaxAngleDeg),
                                t.Bounded(row, "phi", -kMaxAngleDeg, kMaxAngleDeg),
                                t.Bounded(row, "kappa", -kMaxAngleDeg, kMaxAngleDeg)) *
                kDegToRad;
    r.center_sigma_m = SigmaTriple(t, row, "sX", "sY", "sZ", kMaxSigmaM);
    if (auto s = SigmaTriple(t, row, "somega", "sphi", "skappa", kMaxSigmaDeg))
      r.opk_sigma_rad = *s * kDegToRad;
    records.push_back(r);
  }
  return FromRecords(std::move(records), path);
}

PosTrajectory PosTrajectory::FromRecords(std::vector<PosRecord> records, const std::string& file) {
  if (records.size() < 4)
    ThrowInputError({file, records.empty() ? 0 : records.back().source_line},
                    "pos.csv needs at least 4 rows to interpolate (got " +
                        std::to_string(records.size()) + ")");
  PosTrajectory pos;
  pos.file_ = file;
  for (size_t k = 0; k < records.size(); ++k) {
    const PosRecord& r = records[k];
    const SourceRef where{file, r.source_line};
    if (k > 0) {
      const PosRecord& prev = records[k - 1];
      if (!(r.time_s > prev.time_s))
        ThrowInputError(where,
                        "time_s must increase strictly down the file (got " +
                            FormatNumber(r.time_s) + " after " + FormatNumber(prev.time_s) + ")");
      for (int a = 0; a < 3; ++a)
        if (std::abs(r.opk_rad[a] - prev.opk_rad[a]) >= M_PI)
          ThrowInputError(where,
                          "the attitude jumps by 180 deg or more from the row before "
                          "(unwrap the angles: they are interpolated as they are)");
    }
    if (r.line) {
      if (!pos.line_of_.empty() && !(*r.line > pos.line_of_.back()))
        ThrowInputError(where,
                        "line must increase strictly among the rows that have one (got " +
                            FormatNumber(*r.line) + " after " + FormatNumber(pos.line_of_.back()) +
                            ")");
      pos.line_of_.push_back(*r.line);
      pos.time_of_line_.push_back(r.time_s);
    }
  }
  if (pos.line_of_.size() < 2)
    ThrowInputError({file, records.back().source_line},
                    "pos.csv needs at least 2 rows with a line value (the line times)");
  pos.records_ = std::move(records);
  return pos;
}

bool PosTrajectory::CoversLine(double line) const {
  if (!(line >= line_of_.front() - 0.5 && line <= line_of_.back() + 0.5)) return false;
  double t = 0;
  const size_t n = line_of_.size();
  size_t k = std::upper_bound(line_of_.begin(), line_of_.end(), line) - line_of_.begin();
  k = std::min(std::max<size_t>(k, 1), n - 1);
  const double w = (line - line_of_[k - 1]) / (line_of_[k] - line_of_[k - 1]);
  t = (1 - w) * time_of_line_[k - 1] + w * time_of_line_[k];
  return t >= records_.front().time_s && t <= records_.back().time_s;
}

double PosTrajectory::LineTime(double line) const {
  if (!CoversLine(line))
    throw InputError(file_ + ": line " + FormatNumber(line) +
                     " is outside the POS trajectory (lines " + FormatNumber(line_of_.front()) +
                     " .. " + FormatNumber(line_of_.back()) + ")");
  const size_t n = line_of_.size();
  size_t k = std::upper_bound(line_of_.begin(), line_of_.end(), line) - line_of_.begin();
  k = std::min(std::max<size_t>(k, 1), n - 1);
  const double w = (line - line_of_[k - 1]) / (line_of_[k] - line_of_[k - 1]);
  return (1 - w) * time_of_line_[k - 1] + w * time_of_line_[k];
}

void PosTrajectory::PoseAtTime(double time_s,
                               Eigen::Vector3d* center_m,
                               Eigen::Vector3d* opk_rad) const {
  const size_t n = records_.size();
  if (!(time_s >= records_.front().time_s && time_s <= records_.back().time_s))
    throw InputError(file_ + ": time " + FormatNumber(time_s) + " s is outside the POS rows (" +
                     FormatNumber(records_.front().time_s) + " .. " +
                     FormatNumber(records_.back().time_s) + " s)");
  const auto it =
      std::upper_bound(records_.begin(), records_.end(), time_s, [](double t, const PosRecord& r) {
        return t < r.time_s;
      });
  // Interval [k, k+1] holds time_s; the 4 rows k-1 .. k+2, shifted inside the table.
  long k = long(it - records_.begin()) - 1;
  long first = std::min(std::max(k - 1, 0L), long(n) - 4);
  double t[4];
  for (int m = 0; m < 4; ++m) t[m] = records_[first + m].time_s;
  center_m->setZero();
  opk_rad->setZero();
  for (int m = 0; m < 4; ++m) {
    double w = 1.0;
    for (int j = 0; j < 4; ++j)
      if (j != m) w *= (time_s - t[j]) / (t[m] - t[j]);
    *center_m += w * records_[first + m].center_m;
    *opk_rad += w * records_[first + m].opk_rad;
  }
}

std::optional<Eigen::Vector3d> PosTrajectory::MedianCenterSigma() const {
  return Median3(records_, true);
}
std::optional<Eigen::Vector3d> PosTrajectory::MedianOpkSigma() const {
  return Median3(records_, false);
}

void WritePos(const std::string& path, const std::vector<PosRecord>& records) {
  bool sigmas = !records.empty();
  for (const auto& r : records)
    sigmas &= r.center_sigma_m.has_value() && r.opk_sigma_rad.has_value();
  std::ostringstream out;
  out << "line,time_s,X,Y,Z,omega,phi,kappa";
  if (sigmas) out << ",sX,sY,sZ,somega,sphi,skappa";
  out << "\n";
  const double deg = 180.0 / M_PI;
  for (const auto& r : records) {
    out << (r.line ? FormatNumber(*r.line, 17) : "") << "," << FormatNumber(r.time_s, 17);
    for (int a = 0; a < 3; ++a) out << "," << FormatNumber(r.center_m[a], 17);
    for (int a = 0; a < 3; ++a) out << "," << FormatNumber(r.opk_rad[a] * deg, 17);
    if (sigmas) {
      for (int a = 0; a < 3; ++a) out << "," << FormatNumber((*r.center_sigma_m)[a], 17);
      for (int a = 0; a < 3; ++a) out << "," << FormatNumber((*r.opk_sigma_rad)[a] * deg, 17);
    }
    out << "\n";
  }
  WriteFileAtomically(path, out.str());
}

}  // namespace aerocal::triangulation
