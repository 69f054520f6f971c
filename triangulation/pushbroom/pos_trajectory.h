// The POS trajectory of a line camera (FORMATS.md "Line camera": pos.csv), interpolated to the
// scan lines' times (CONVENTIONS.md "Line (pushbroom) cameras": body position O(t) and attitude
// R(t), body -> object).
//
//   pos.csv: line,time_s,X,Y,Z,omega,phi,kappa[,sX,sY,sZ,somega,sphi,skappa]
//
// - A row with a `line` value gives that scan line's time (and its pose); a row with `line` empty
//   is a POS epoch. Times strictly increase down the file, lines strictly increase among the rows
//   that have one; at least 4 rows, at least 2 with a line.
// - Line -> time: piecewise linear between the rows with a line (exact for a constant line rate),
//   extrapolated linearly half a line beyond the first and last.
// - Time -> pose: cubic Lagrange interpolation through the 4 nearest rows (in time) of position
//   and of each angle (the angles must be continuous: two neighbouring rows may not differ by
//   180 deg or more; unwrap before writing). It reproduces cubic motion exactly; a time outside
//   the rows' span is an error (no extrapolation of the attitude).
// - Sigmas (m, deg in the file; rad in memory) are optional; empty = not given.
#pragma once

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct PosRecord {
  std::optional<double> line;  // scan line this row belongs to, or an epoch
  double time_s = 0.0;
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();  // body position (m)
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();   // body attitude (rad)
  std::optional<Eigen::Vector3d> center_sigma_m, opk_sigma_rad;
  int source_line = 0;  // line in pos.csv
};

class PosTrajectory {
 public:
  /// Reads pos.csv; InputError("FILE:LINE: ...") on a bad row.
  static PosTrajectory Read(const std::string& path);
  /// From records (validated as the reader does; `file` names them in errors).
  static PosTrajectory FromRecords(std::vector<PosRecord> records, const std::string& file);

  const std::vector<PosRecord>& records() const { return records_; }
  /// Lines with a time: [first_line, last_line] (as read).
  double first_line() const { return line_of_[0]; }
  double last_line() const { return line_of_.back(); }
  /// Time of a (fractional) line; lines more than half a line outside [first, last] are refused
  /// (InputError naming the line).
  double LineTime(double line) const;
  bool CoversLine(double line) const;
  /// Pose at a time within the rows' span.
  void PoseAtTime(double time_s, Eigen::Vector3d* center_m, Eigen::Vector3d* opk_rad) const;
  void PoseAtLine(double line, Eigen::Vector3d* center_m, Eigen::Vector3d* opk_rad) const {
    PoseAtTime(LineTime(line), center_m, opk_rad);
  }
  /// The median a-priori sigmas of the rows that give them (nullopt when none does).
  std::optional<Eigen::Vector3d> MedianCenterSigma() const;
  std::optional<Eigen::Vector3d> MedianOpkSigma() const;

 private:
  std::string file_;
  std::vector<PosRecord> records_;
  std::vector<double> line_of_, time_of_line_;  // rows with a line
};

/// Writes pos.csv (full precision; sigmas when every record has them).
void WritePos(const std::string& path, const std::vector<PosRecord>& records);

}  // namespace aerocal::triangulation
