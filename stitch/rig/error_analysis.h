// Conversion error analysis of a rig's virtual image (CONVENTIONS.md "Conversion error"): how far
// the head pixel that the conversion assigns to a fixed virtual pixel moves when the rig's
// parameters are in error by their limits.
//
// Error sources (in this order): the interior of every head (file order) as its model names it in
// the registry's table: the principal point's entries, then the principal distance's (x0, y0, c of
// brown_fraser_10; cx, cy, fx, fy of opencv; cx, cy, f of colmap_simple_pinhole ...), then omega,
// phi, kappa (the mount angles of the file) and tx, ty, tz (the lever arm) of every non-reference
// head, then the relative flying height H of the rectification plane. Names `x0:HEAD` (the table
// name) ... `tz:HEAD`, `height`.
//
// The virtual camera is realised by the reference head (the virtual image of a dual-lens camera is
// the reference image extended): a virtual pixel's ray is the reference head's ray through the
// reference-head pixel that the NOMINAL rig assigns to it. So an error of the reference head's
// interior turns every virtual ray and reaches the other heads with the opposite sign of their own
// interior errors, and the reference head itself carries no conversion error by definition.
//
// For a target (a head k and a virtual pixel P fixed by the nominal rig, at nominal height H):
//   a  = reference-head pixel of P (nominal rig), p0 = head-k pixel of P (nominal rig);
//   for deviations delta of the sources: G = plane point (height H + dH) on the reference ray of
//   `a` through the deviated reference interior; p = head-k pixel of G through the deviated head;
//   e = p - p0 in head-k pixels, ex = d(col), ey = -d(row) (photo axes, y up).
// The exposure is nadir (rig attitude identity, centre at the origin); orientation rig and level
// then coincide.
//
// Methods:
// - maximum error: each source at +limit and -limit alone (signed ex, ey); per group of sources
//   the worst corner of all sign combinations (exhaustive up to 16 sources) and the sum of the
//   single-source |e| per axis;
// - linear propagation: J = de/dsource by central differences, sigma_i = limit_i / sigmas,
//   Cov = J diag(sigma^2) J^T; sigma per axis, the 99.75 % bound z sigma (z = 3.023, two-sided
//   normal), the radial 99.75 % bound of the 2D normal, each source's share of each axis' variance;
// - Monte-Carlo: n samples of independent normal deviations (sigma_i), seeded (mt19937_64, Box-
//   Muller): sigma, mean, 99.75 % bound of |ex|, |ey| and the radial error, the largest errors.
#pragma once

#include "calib/camera/rig.h"

#include <Eigen/Core>
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::stitch {

/// The limits file: `limits: {principal_point_px, principal_distance_px, angles_arcsec,
/// lever_arm_mm, height_m}` (all required, >= 0) and `sigmas` (> 0, default 3: the limits are that
/// many standard deviations in the linear propagation and the Monte-Carlo).
struct ErrorLimits {
  double principal_point_px = 0.0;     // each principal-point entry of every head, in its pixels
  double principal_distance_px = 0.0;  // each principal-distance entry of every head, in its pixels
  double angles_arcsec = 0.0;          // omega, phi, kappa of the non-reference heads
  double lever_arm_mm = 0.0;           // tx, ty, tz of the non-reference heads
  double height_m = 0.0;               // relative flying height
  double sigmas = 3.0;
};
ErrorLimits ReadErrorLimits(const std::string& path);
ErrorLimits ParseErrorLimits(const YAML::Node& root, const std::string& file);

enum class ErrorSourceKind {
  kPrincipalPoint,     // an entry of the head's model table in that group
  kPrincipalDistance,  // ditto
  kOmega,
  kPhi,
  kKappa,
  kTx,
  kTy,
  kTz,
  kHeight
};

struct ErrorSource {
  std::string name;  // "x0:A", ..., "height"
  ErrorSourceKind kind;
  int head = -1;       // -1 for the height
  double limit = 0.0;  // in memory units: the table's (mm or px) for the interior, rad, m
  std::string unit;    // of `limit`
  int param = -1;      // the interior's entry in the head's model table
};

/// The sources of a rig (order in the header comment) with the limits converted to memory units.
std::vector<ErrorSource> MakeErrorSources(const calib::Rig& rig, const ErrorLimits& limits);

/// The conversion error at one target, as a function of the source deviations.
class ConversionErrorModel {
 public:
  /// `head`: the head in which the error is measured; `virtual_px`: the fixed virtual pixel;
  /// `height_m`: nominal relative flying height (> 0). Throws InputError when the nominal rig
  /// cannot carry the virtual pixel into the reference head or head k.
  ConversionErrorModel(const calib::Rig& rig,
                       double height_m,
                       std::vector<ErrorSource> sources,
                       int head,
                       const Eigen::Vector2d& virtual_px);

  /// e = (ex, ey) in head-k pixels for deviations `delta` (one per source, memory units);
  /// nullopt when the deviated conversion fails (ray parallel to the plane, point behind a head).
  std::optional<Eigen::Vector2d> Error(const Eigen::VectorXd& delta) const;

  const std::vector<ErrorSource>& sources() const { return sources_; }
  int head() const { return head_; }
  const Eigen::Vector2d& virtual_px() const { return virtual_px_; }
  const Eigen::Vector2d& head_px() const { return head_px_; }            // p0
  const Eigen::Vector2d& reference_px() const { return reference_px_; }  // a

 private:
  calib::Rig rig_;
  double height_m_;
  std::vector<ErrorSource> sources_;
  int head_;
  int reference_;
  Eigen::Vector2d virtual_px_, head_px_, reference_px_;
};

struct SourceErrorRow {
  std::string source;
  Eigen::Vector2d plus_px = Eigen::Vector2d::Zero();   // source at +limit alone
  Eigen::Vector2d minus_px = Eigen::Vector2d::Zero();  // source at -limit alone
};

struct WorstCase {
  std::string group;  // "interior:A", "angles:B", "lever_arm:B",
                      // "relative_orientation:B", "height", "all"
  std::vector<std::string> sources;
  bool exhaustive = true;                                // all 2^m sign corners evaluated (m <= 16)
  Eigen::Vector2d max_abs_px = Eigen::Vector2d::Zero();  // largest |ex|, |ey| over the corners
  double max_radial_px = 0.0;                            // largest |e| over the corners
  std::vector<int> signs;  // the corner of max_radial_px (+1 / -1 per source)
  Eigen::Vector2d sum_abs_px = Eigen::Vector2d::Zero();  // sum over sources of max(|plus|, |minus|)
};

struct LinearPropagation {
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // px^2
  Eigen::Vector2d sigma_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d bound_px = Eigen::Vector2d::Zero();  // z sigma, z for 99.75 % two-sided
  double bound_radial_px = 0.0;                        // 99.75 % of |e| under the 2D normal
  std::vector<Eigen::Vector2d> jacobian;               // de/dsource, px per memory unit
  std::vector<double> sigma;                           // sigma of each source, memory units
  /// Share of each source in each axis' variance (sums to 1 per axis); nullopt for an axis whose
  /// variance is zero (an unknown share is null, never 0).
  std::vector<std::optional<double>> share_x, share_y;
};

struct MonteCarloResult {
  int n = 0;
  std::uint64_t seed = 0;
  int failed = 0;                                      // samples whose conversion failed
  Eigen::Vector2d sigma_px = Eigen::Vector2d::Zero();  // sample standard deviation (n - 1)
  Eigen::Vector2d mean_px = Eigen::Vector2d::Zero();
  Eigen::Vector2d bound_px = Eigen::Vector2d::Zero();  // 99.75 % quantile of |ex|, |ey|
  double bound_radial_px = 0.0;                        // 99.75 % quantile of |e|
  Eigen::Vector2d max_abs_px = Eigen::Vector2d::Zero();
  double max_radial_px = 0.0;
  std::vector<Eigen::Vector2d> errors;  // every sample's e (for histograms)
};

struct TargetAnalysis {
  int head = -1;
  Eigen::Vector2d virtual_px, head_px, reference_px;
  std::vector<SourceErrorRow> per_source;
  std::vector<WorstCase> worst_cases;
  LinearPropagation linear;
  std::optional<MonteCarloResult> monte_carlo;  // absent when samples == 0
};

/// The 99.75 % two-sided quantile of the standard normal (3.0233).
double NormalBound99_75();

std::vector<SourceErrorRow> MaximumErrors(const ConversionErrorModel& model);
std::vector<WorstCase> WorstCases(const ConversionErrorModel& model,
                                  const calib::Rig& rig,
                                  const std::vector<SourceErrorRow>& rows);
LinearPropagation PropagateLinearly(const ConversionErrorModel& model, double sigmas);
/// `samples` >= 1; `keep_errors`: keep every sample's error (histograms).
MonteCarloResult RunMonteCarlo(const ConversionErrorModel& model,
                               double sigmas,
                               int samples,
                               std::uint64_t seed,
                               bool keep_errors);

/// All methods at one target (Monte-Carlo skipped when samples == 0).
TargetAnalysis AnalyseTarget(const calib::Rig& rig,
                             double height_m,
                             const ErrorLimits& limits,
                             int head,
                             const Eigen::Vector2d& virtual_px,
                             int samples,
                             std::uint64_t seed,
                             bool keep_errors);

/// Histogram of `values` in `bins` equal bins over [lo, hi] (values outside are clamped into the
/// end bins); counts.
std::vector<long> Histogram(const std::vector<double>& values, double lo, double hi, int bins);

}  // namespace aerocal::stitch
