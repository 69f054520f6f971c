#include "stitch/rig/error_analysis.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/yaml_util.h"
#include "stitch/rig/rig_conversion.h"

#include <Eigen/Eigenvalues>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace aerocal::stitch {
namespace {

constexpr double kProbability = 0.9975;  // the bounds' coverage
constexpr int kMaxExhaustiveSources = 16;
constexpr double kRadPerArcsec = M_PI / (180.0 * 3600.0);
// Central-difference step as a fraction of a source's limit: the conversion is smooth at the
// scale of the limits (truncation ~1e-6 relative) and its Newton inverse is exact to 1e-10 px,
// so the quotient is good to ~1e-7 relative.
constexpr double kStepFraction = 1e-3;

double Quantile(std::vector<double> values, double probability) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank =
      static_cast<size_t>(std::ceil(probability * static_cast<double>(values.size())));
  return values[std::min(values.size(), std::max<size_t>(rank, 1)) - 1];
}

// P(|e| <= r) for e ~ N(0, diag(l1, l2)), l1 >= l2 > 0: in polar coordinates
// (1 / (2 pi sqrt(l1 l2))) * integral over theta of (1 - exp(-r^2 q / 2)) / q, q = cos^2/l1 +
// sin^2/l2 (trapezoid rule: the integrand is smooth and periodic, so it converges exponentially).
double RadialProbability(double l1, double l2, double r) {
  constexpr int kSteps = 2048;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double theta = 2.0 * M_PI * i / kSteps;
    const double q =
        std::cos(theta) * std::cos(theta) / l1 + std::sin(theta) * std::sin(theta) / l2;
    sum += -std::expm1(-0.5 * r * r * q) / q;
  }
  return sum * (2.0 * M_PI / kSteps) / (2.0 * M_PI * std::sqrt(l1 * l2));
}

double RadialBound(const Eigen::Matrix2d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(covariance);
  const double l1 = std::max(eigen.eigenvalues()[1], 0.0);
  const double l2 = std::max(eigen.eigenvalues()[0], 0.0);
  if (l1 == 0.0) return 0.0;
  if (l2 < 1e-14 * l1) return NormalBound99_75() * std::sqrt(l1);  // one-dimensional
  double lo = 0.0, hi = 4.0 * std::sqrt(l1);                       // chi^2_2 bound: 3.46 sqrt(l1)
  for (int i = 0; i < 200 && hi - lo > 1e-13 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (RadialProbability(l1, l2, mid) < kProbability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

// Standard normal deviates from mt19937_64 by Box-Muller (the same numbers on every platform,
// unlike std::normal_distribution).
class NormalStream {
 public:
  explicit NormalStream(std::uint64_t seed) : rng_(seed) {}
  double Next() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    const double u1 = (static_cast<double>(rng_() >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
    const double u2 = static_cast<double>(rng_() >> 11) * 0x1.0p-53;          // [0, 1)
    const double radius = std::sqrt(-2.0 * std::log(u1));
    spare_ = radius * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return radius * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::mt19937_64 rng_;
  bool has_spare_ = false;
  double spare_ = 0.0;
};

double ReadLimit(const YAML::Node& map, const std::string& key, const std::string& file) {
  if (!map[key]) ThrowInputError(WhereIs(map, file), "limits: missing " + key);
  const double value = YamlDouble(map[key], file, "limits." + key);
  if (!(value >= 0))
    ThrowInputError(WhereIs(map[key], file),
                    "limits." + key + " must be >= 0 (got " + FormatNumber(value) + ")");
  return value;
}

}  // namespace

double NormalBound99_75() {
  static const double z = [] {
    double lo = 0.0, hi = 10.0;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (std::erfc(mid / std::sqrt(2.0)) > 1.0 - kProbability ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }();
  return z;
}

ErrorLimits ParseErrorLimits(const YAML::Node& root, const std::string& file) {
  if (!root.IsMap()) ThrowInputError({file, 1}, "a limits file is a YAML map");
  RejectUnknownKeys(root, {"limits", "sigmas"}, file);
  if (!root["limits"]) ThrowInputError({file, 1}, "missing limits");
  const YAML::Node& map = root["limits"];
  RejectUnknownKeys(
      map,
      {"principal_point_px", "principal_distance_px", "angles_arcsec", "lever_arm_mm", "height_m"},
      file);
  ErrorLimits limits;
  limits.principal_point_px = ReadLimit(map, "principal_point_px", file);
  limits.principal_distance_px = ReadLimit(map, "principal_distance_px", file);
  limits.angles_arcsec = ReadLimit(map, "angles_arcsec", file);
  limits.lever_arm_mm = ReadLimit(map, "lever_arm_mm", file);
  limits.height_m = ReadLimit(map, "height_m", file);
  if (root["sigmas"]) {
    limits.sigmas = YamlDouble(root["sigmas"], file, "sigmas");
    if (!(limits.sigmas > 0))
      ThrowInputError(WhereIs(root["sigmas"], file),
                      "sigmas must be > 0 (got " + FormatNumber(limits.sigmas) + ")");
  }
  return limits;
}

ErrorLimits ReadErrorLimits(const std::string& path) {
  return ParseErrorLimits(LoadYamlFile(path), path);
}

namespace {

// The interior sources of a head: the entries of its model's table in the principal-point group,
// then those in the principal-distance group (table order), their limits (given in pixels)
// converted to the table's unit, mm or px.
void AddInteriorSources(const calib::RigHead& head,
                        int h,
                        const ErrorLimits& limits,
                        std::vector<ErrorSource>* sources) {
  const calib::Camera& camera = head.camera;
  const std::vector<calib::ParamInfo> table = camera.Params();
  const std::string model(calib::CameraModelName(camera.model));
  const std::pair<calib::ParamGroup, ErrorSourceKind> groups[] = {
      {calib::ParamGroup::kPrincipalPoint, ErrorSourceKind::kPrincipalPoint},
      {calib::ParamGroup::kPrincipalDistance, ErrorSourceKind::kPrincipalDistance}};
  for (const auto& [group, kind] : groups) {
    const double limit_px = kind == ErrorSourceKind::kPrincipalPoint ? limits.principal_point_px
                                                                     : limits.principal_distance_px;
    bool any = false;
    for (int i = 0; i < static_cast<int>(table.size()); ++i) {
      if (table[i].group != group) continue;
      const std::string unit(table[i].unit);
      if (unit != "mm" && unit != "px")
        throw InputError("head " + head.id + " in model " + model + ": the error analysis " +
                         "perturbs the principal point and distance in mm or px, and " +
                         std::string(table[i].name) + " is in " + unit);
      const double limit = unit == "mm" ? limit_px * camera.pixel_size_mm : limit_px;
      sources->push_back({std::string(table[i].name) + ":" + head.id, kind, h, limit, unit, i});
      any = true;
    }
    if (!any)
      throw InputError(
          "head " + head.id + " in model " + model + ": no " +
          (kind == ErrorSourceKind::kPrincipalPoint ? "principal point" : "principal distance") +
          " in its table to perturb");
  }
}

}  // namespace

std::vector<ErrorSource> MakeErrorSources(const calib::Rig& rig, const ErrorLimits& limits) {
  std::vector<ErrorSource> sources;
  const int reference = rig.ReferenceIndex();
  for (int h = 0; h < static_cast<int>(rig.heads.size()); ++h) {
    AddInteriorSources(rig.heads[h], h, limits, &sources);
  }
  for (int h = 0; h < static_cast<int>(rig.heads.size()); ++h) {
    if (h == reference) continue;
    const std::string& id = rig.heads[h].id;
    const double angle = limits.angles_arcsec * kRadPerArcsec;
    const double lever = limits.lever_arm_mm * 1e-3;
    sources.push_back({"omega:" + id, ErrorSourceKind::kOmega, h, angle, "rad"});
    sources.push_back({"phi:" + id, ErrorSourceKind::kPhi, h, angle, "rad"});
    sources.push_back({"kappa:" + id, ErrorSourceKind::kKappa, h, angle, "rad"});
    sources.push_back({"tx:" + id, ErrorSourceKind::kTx, h, lever, "m"});
    sources.push_back({"ty:" + id, ErrorSourceKind::kTy, h, lever, "m"});
    sources.push_back({"tz:" + id, ErrorSourceKind::kTz, h, lever, "m"});
  }
  sources.push_back({"height", ErrorSourceKind::kHeight, -1, limits.height_m, "m"});
  return sources;
}

ConversionErrorModel::ConversionErrorModel(const calib::Rig& rig,
                                           double height_m,
                                           std::vector<ErrorSource> sources,
                                           int head,
                                           const Eigen::Vector2d& virtual_px)
    : rig_(rig),
      height_m_(height_m),
      sources_(std::move(sources)),
      head_(head),
      reference_(rig.ReferenceIndex()),
      virtual_px_(virtual_px) {
  AEROCAL_CHECK(head >= 0 && head < static_cast<int>(rig.heads.size())) << "head index " << head;
  AEROCAL_CHECK(height_m > 0) << "height " << height_m;
  const RigExposure nadir;
  const RigConverter nominal(rig_, nadir, MakeRectificationPlane(rig_, nadir, height_m_));
  const auto ground = nominal.PlanePointOfVirtualPixel(virtual_px_);
  const auto anchor = ground ? nominal.HeadPixelOfPoint(reference_, *ground) : std::nullopt;
  if (!anchor)
    throw InputError("virtual pixel (" + FormatNumber(virtual_px.x()) + ", " +
                     FormatNumber(virtual_px.y()) + ") cannot be carried into the reference head " +
                     rig.reference_head);
  reference_px_ = *anchor;
  // p0 by the very computation Error() makes, so that zero deviations give exactly zero.
  head_px_ = Eigen::Vector2d::Zero();
  const auto p0 = Error(Eigen::VectorXd::Zero(static_cast<int>(sources_.size())));
  if (!p0)
    throw InputError("virtual pixel (" + FormatNumber(virtual_px.x()) + ", " +
                     FormatNumber(virtual_px.y()) + ") cannot be carried into head " +
                     rig.heads[head].id);
  head_px_ = Eigen::Vector2d(p0->x(), -p0->y());
}

std::optional<Eigen::Vector2d> ConversionErrorModel::Error(const Eigen::VectorXd& delta) const {
  AEROCAL_CHECK(delta.size() == static_cast<int>(sources_.size())) << "one deviation per source";
  calib::Rig rig = rig_;
  double height = height_m_;
  for (size_t i = 0; i < sources_.size(); ++i) {
    const ErrorSource& s = sources_[i];
    const double d = delta[static_cast<int>(i)];
    if (d == 0.0) continue;
    switch (s.kind) {
      case ErrorSourceKind::kPrincipalPoint:
      case ErrorSourceKind::kPrincipalDistance:
        rig.heads[s.head].camera.interior[s.param] += d;
        break;
      case ErrorSourceKind::kOmega:
        rig.heads[s.head].mount_rad[0] += d;
        break;
      case ErrorSourceKind::kPhi:
        rig.heads[s.head].mount_rad[1] += d;
        break;
      case ErrorSourceKind::kKappa:
        rig.heads[s.head].mount_rad[2] += d;
        break;
      case ErrorSourceKind::kTx:
        rig.heads[s.head].lever_arm_m[0] += d;
        break;
      case ErrorSourceKind::kTy:
        rig.heads[s.head].lever_arm_m[1] += d;
        break;
      case ErrorSourceKind::kTz:
        rig.heads[s.head].lever_arm_m[2] += d;
        break;
      case ErrorSourceKind::kHeight:
        height += d;
        break;
    }
  }
  if (!(height > 0)) return std::nullopt;
  const RigExposure nadir;
  const RigConverter converter(rig, nadir, MakeRectificationPlane(rig, nadir, height));
  const auto ground = converter.PlanePointOfHeadPixel(reference_, reference_px_);
  if (!ground) return std::nullopt;
  const auto pixel = converter.HeadPixelOfPoint(head_, *ground);
  if (!pixel) return std::nullopt;
  return Eigen::Vector2d(pixel->x() - head_px_.x(), -(pixel->y() - head_px_.y()));
}

std::vector<SourceErrorRow> MaximumErrors(const ConversionErrorModel& model) {
  const int m = static_cast<int>(model.sources().size());
  std::vector<SourceErrorRow> rows;
  for (int i = 0; i < m; ++i) {
    SourceErrorRow row;
    row.source = model.sources()[i].name;
    for (const int sign : {+1, -1}) {
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(m);
      delta[i] = sign * model.sources()[i].limit;
      const auto e = model.Error(delta);
      if (!e) throw InputError("source " + row.source + " at its limit breaks the conversion");
      (sign > 0 ? row.plus_px : row.minus_px) = *e;
    }
    rows.push_back(row);
  }
  return rows;
}

std::vector<WorstCase> WorstCases(const ConversionErrorModel& model,
                                  const calib::Rig& rig,
                                  const std::vector<SourceErrorRow>& rows) {
  const auto& sources = model.sources();
  const int m = static_cast<int>(sources.size());
  // Groups of source indices.
  std::vector<std::pair<std::string, std::vector<int>>> groups;
  const auto members = [&](const std::string& head, std::initializer_list<ErrorSourceKind> kinds) {
    std::vector<int> out;
    for (int i = 0; i < m; ++i)
      if (sources[i].head >= 0 && rig.heads[sources[i].head].id == head &&
          std::find(kinds.begin(), kinds.end(), sources[i].kind) != kinds.end())
        out.push_back(i);
    return out;
  };
  using K = ErrorSourceKind;
  for (const calib::RigHead& head : rig.heads)
    groups.push_back(
        {"interior:" + head.id, members(head.id, {K::kPrincipalPoint, K::kPrincipalDistance})});
  for (const calib::RigHead& head : rig.heads) {
    if (head.id == rig.reference_head) continue;
    groups.push_back({"angles:" + head.id, members(head.id, {K::kOmega, K::kPhi, K::kKappa})});
    groups.push_back({"lever_arm:" + head.id, members(head.id, {K::kTx, K::kTy, K::kTz})});
    groups.push_back({"relative_orientation:" + head.id,
                      members(head.id, {K::kOmega, K::kPhi, K::kKappa, K::kTx, K::kTy, K::kTz})});
  }
  std::vector<int> all(m);
  for (int i = 0; i < m; ++i) all[i] = i;
  groups.push_back({"height", {m - 1}});
  groups.push_back({"all", all});

  std::vector<WorstCase> cases;
  for (const auto& [name, indices] : groups) {
    WorstCase worst;
    worst.group = name;
    const int g = static_cast<int>(indices.size());
    for (int i : indices) {
      worst.sources.push_back(sources[i].name);
      worst.sum_abs_px += rows[i].plus_px.cwiseAbs().cwiseMax(rows[i].minus_px.cwiseAbs());
    }
    // Sign corners: all of them, or for large groups those the single-source errors point to
    // (for 16 directions u, each source at the sign that moves e along u).
    std::vector<std::vector<int>> corners;
    worst.exhaustive = g <= kMaxExhaustiveSources;
    if (worst.exhaustive) {
      for (long mask = 0; mask < (1L << g); ++mask) {
        std::vector<int> signs(g);
        for (int j = 0; j < g; ++j) signs[j] = (mask >> j) & 1 ? -1 : +1;
        corners.push_back(signs);
      }
    } else {
      for (int d = 0; d < 16; ++d) {
        const Eigen::Vector2d u(std::cos(M_PI * d / 8), std::sin(M_PI * d / 8));
        std::vector<int> signs(g);
        for (int j = 0; j < g; ++j)
          signs[j] = u.dot(rows[indices[j]].plus_px - rows[indices[j]].minus_px) >= 0 ? +1 : -1;
        corners.push_back(signs);
      }
    }
    for (const auto& signs : corners) {
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(m);
      for (int j = 0; j < g; ++j) delta[indices[j]] = signs[j] * sources[indices[j]].limit;
      const auto e = model.Error(delta);
      if (!e) throw InputError("group " + name + " at its limits breaks the conversion");
      worst.max_abs_px = worst.max_abs_px.cwiseMax(e->cwiseAbs());
      if (worst.signs.empty() || e->norm() > worst.max_radial_px) {
        worst.max_radial_px = e->norm();
        worst.signs = signs;
      }
    }
    cases.push_back(worst);
  }
  return cases;
}

LinearPropagation PropagateLinearly(const ConversionErrorModel& model, double sigmas) {
  const int m = static_cast<int>(model.sources().size());
  LinearPropagation result;
  for (int i = 0; i < m; ++i) {
    const double limit = model.sources()[i].limit;
    const double sigma = limit / sigmas;
    Eigen::Vector2d jacobian = Eigen::Vector2d::Zero();
    if (limit > 0) {
      const double h = kStepFraction * limit;
      Eigen::VectorXd delta = Eigen::VectorXd::Zero(m);
      delta[i] = h;
      const auto plus = model.Error(delta);
      delta[i] = -h;
      const auto minus = model.Error(delta);
      if (!plus || !minus)
        throw InputError("source " + model.sources()[i].name + " breaks the conversion");
      jacobian = (*plus - *minus) / (2.0 * h);
    }
    result.jacobian.push_back(jacobian);
    result.sigma.push_back(sigma);
    result.covariance += sigma * sigma * jacobian * jacobian.transpose();
  }
  result.sigma_px = result.covariance.diagonal().cwiseSqrt();
  result.bound_px = NormalBound99_75() * result.sigma_px;
  result.bound_radial_px = RadialBound(result.covariance);
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2d part = (result.sigma[i] * result.jacobian[i]).cwiseAbs2();
    const auto share = [](double part_axis, double total) -> std::optional<double> {
      if (!(total > 0)) return std::nullopt;
      return part_axis / total;
    };
    result.share_x.push_back(share(part.x(), result.covariance(0, 0)));
    result.share_y.push_back(share(part.y(), result.covariance(1, 1)));
  }
  return result;
}

MonteCarloResult RunMonteCarlo(const ConversionErrorModel& model,
                               double sigmas,
                               int samples,
                               std::uint64_t seed,
                               bool keep_errors) {
  AEROCAL_CHECK(samples >= 1) << "samples " << samples;
  const int m = static_cast<int>(model.sources().size());
  // Deviations drawn in one sequence (sample-major), so the result does not depend on threads.
  Eigen::MatrixXd deltas(m, samples);
  NormalStream normal(seed);
  for (int s = 0; s < samples; ++s)
    for (int i = 0; i < m; ++i) deltas(i, s) = model.sources()[i].limit / sigmas * normal.Next();
  std::vector<Eigen::Vector2d> errors(samples);
  std::vector<char> ok(samples, 0);
  tbb::parallel_for(tbb::blocked_range<int>(0, samples, 256),
                    [&](const tbb::blocked_range<int>& r) {
                      for (int s = r.begin(); s < r.end(); ++s) {
                        const auto e = model.Error(deltas.col(s));
                        if (e) {
                          errors[s] = *e;
                          ok[s] = 1;
                        }
                      }
                    });
  MonteCarloResult result;
  result.n = samples;
  result.seed = seed;
  std::vector<Eigen::Vector2d> good;
  good.reserve(samples);
  for (int s = 0; s < samples; ++s)
    if (ok[s]) good.push_back(errors[s]);
  result.failed = samples - static_cast<int>(good.size());
  const int n = static_cast<int>(good.size());
  if (n == 0) return result;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& e : good) sum += e;
  result.mean_px = sum / n;
  Eigen::Vector2d squares = Eigen::Vector2d::Zero();
  std::vector<double> abs_x(n), abs_y(n), radial(n);
  for (int s = 0; s < n; ++s) {
    squares += (good[s] - result.mean_px).cwiseAbs2();
    abs_x[s] = std::abs(good[s].x());
    abs_y[s] = std::abs(good[s].y());
    radial[s] = good[s].norm();
    result.max_abs_px = result.max_abs_px.cwiseMax(good[s].cwiseAbs());
    result.max_radial_px = std::max(result.max_radial_px, radial[s]);
  }
  result.sigma_px =
      n > 1 ? Eigen::Vector2d((squares / (n - 1)).cwiseSqrt()) : Eigen::Vector2d::Zero();
  result.bound_px = {Quantile(abs_x, kProbability), Quantile(abs_y, kProbability)};
  result.bound_radial_px = Quantile(radial, kProbability);
  if (keep_errors) result.errors = std::move(good);
  return result;
}

TargetAnalysis AnalyseTarget(const calib::Rig& rig,
                             double height_m,
                             const ErrorLimits& limits,
                             int head,
                             const Eigen::Vector2d& virtual_px,
                             int samples,
                             std::uint64_t seed,
                             bool keep_errors) {
  const ConversionErrorModel model(rig, height_m, MakeErrorSources(rig, limits), head, virtual_px);
  TargetAnalysis analysis;
  analysis.head = head;
  analysis.virtual_px = virtual_px;
  analysis.head_px = model.head_px();
  analysis.reference_px = model.reference_px();
  analysis.per_source = MaximumErrors(model);
  analysis.worst_cases = WorstCases(model, rig, analysis.per_source);
  analysis.linear = PropagateLinearly(model, limits.sigmas);
  if (samples > 0)
    analysis.monte_carlo = RunMonteCarlo(model, limits.sigmas, samples, seed, keep_errors);
  return analysis;
}

std::vector<long> Histogram(const std::vector<double>& values, double lo, double hi, int bins) {
  AEROCAL_CHECK(bins >= 1) << "bins " << bins;
  std::vector<long> counts(bins, 0);
  const double width = (hi - lo) / bins;
  for (double v : values) {
    int b = width > 0 ? static_cast<int>(std::floor((v - lo) / width)) : 0;
    counts[std::clamp(b, 0, bins - 1)]++;
  }
  return counts;
}

}  // namespace aerocal::stitch
