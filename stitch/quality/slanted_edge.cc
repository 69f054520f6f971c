#include "stitch/quality/slanted_edge.h"

#include "calib/core/error.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <limits>
#include <random>

namespace aerocal::stitch {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kCurveStep = 1.0 / 64.0;  // cycles/px between the reported curve's samples
constexpr double kMaxFrequency = 1.0;      // cycles/px: the curve and the crossings end here
constexpr int kMinRegionPx = 16;

using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

double Sinc(double x) { return std::abs(x) < 1e-12 ? 1.0 : std::sin(kPi * x) / (kPi * x); }

double Hamming(double x, double half_width) {  // 1 at 0, 0.08 at +-half_width, 0 beyond
  return std::abs(x) > half_width ? 0.0 : 0.54 + 0.46 * std::cos(kPi * x / half_width);
}

std::string RegionText(const PixelRegion& r) {
  return "region (" + std::to_string(r.col) + ", " + std::to_string(r.row) + ", " +
         std::to_string(r.width) + ", " + std::to_string(r.height) + ")";
}

// The region's linearised values, transposed when the edge is nearer horizontal, so that the edge
// always runs along the rows of the returned matrix and its ESF runs across the columns.
Matrix OrientedRegion(const GrayImage& image,
                      const PixelRegion& region,
                      double gamma,
                      MtfAxis* axis) {
  Matrix m(region.height, region.width);
  for (int r = 0; r < region.height; ++r)
    for (int c = 0; c < region.width; ++c) {
      const double dn = std::max(0.0, static_cast<double>(image(region.row + r, region.col + c)));
      m(r, c) = gamma == 1.0 ? dn : std::pow(dn, gamma);
    }
  double gx = 0.0, gy = 0.0;
  for (int r = 0; r + 1 < m.rows(); ++r)
    for (int c = 0; c + 1 < m.cols(); ++c) {
      gx += std::abs(m(r, c + 1) - m(r, c));
      gy += std::abs(m(r + 1, c) - m(r, c));
    }
  *axis = gx >= gy ? MtfAxis::kX : MtfAxis::kY;
  if (*axis == MtfAxis::kY) return m.transpose();
  return m;
}

struct EdgeLine {
  double a = 0.0;  // col of the edge at the mean row
  double b = 0.0;  // slope, col per row
  double row_mean = 0.0;
  double slope_sigma = 0.0;
  double Col(double row) const { return a + b * (row - row_mean); }
};

// Per row, the centroid (col) of the centred derivative; with `window` the derivative is weighted
// by a Hamming window of `half_width` px about the window line's col. NaN where the row holds too
// little of the edge (its derivative sum below half the median row's).
std::vector<double> RowCentroids(const Matrix& m, const EdgeLine* window, double half_width) {
  const int rows = static_cast<int>(m.rows()), cols = static_cast<int>(m.cols());
  std::vector<double> sums(rows, 0.0), centroid(rows, kNaN);
  std::vector<double> moments(rows, 0.0);
  for (int r = 0; r < rows; ++r)
    for (int c = 1; c + 1 < cols; ++c) {
      const double w = window == nullptr ? 1.0 : Hamming(c - window->Col(r), half_width);
      const double d = 0.5 * (m(r, c + 1) - m(r, c - 1)) * w;
      sums[r] += d;
      moments[r] += d * c;
    }
  std::vector<double> abs_sums(rows);
  for (int r = 0; r < rows; ++r) abs_sums[r] = std::abs(sums[r]);
  std::nth_element(abs_sums.begin(), abs_sums.begin() + rows / 2, abs_sums.end());
  const double median = abs_sums[rows / 2];
  for (int r = 0; r < rows; ++r)
    if (median > 0.0 && std::abs(sums[r]) >= 0.5 * median) centroid[r] = moments[r] / sums[r];
  return centroid;
}

// Least-squares line col = a + b (row - mean row) through the rows' centroids.
EdgeLine FitLine(const std::vector<double>& centroid, const PixelRegion& region) {
  double n = 0.0, sr = 0.0, sc = 0.0;
  for (size_t r = 0; r < centroid.size(); ++r)
    if (std::isfinite(centroid[r])) n += 1.0, sr += r, sc += centroid[r];
  if (n < 0.5 * centroid.size() || n < 8)
    throw InputError(RegionText(region) + ": no edge across the region (an edge found in " +
                     std::to_string(static_cast<int>(n)) + " of " +
                     std::to_string(centroid.size()) + " lines)");
  EdgeLine line;
  line.row_mean = sr / n;
  const double col_mean = sc / n;
  double srr = 0.0, src = 0.0;
  for (size_t r = 0; r < centroid.size(); ++r)
    if (std::isfinite(centroid[r])) {
      srr += (r - line.row_mean) * (r - line.row_mean);
      src += (r - line.row_mean) * (centroid[r] - col_mean);
    }
  line.b = src / srr;
  line.a = col_mean;
  double vv = 0.0;
  for (size_t r = 0; r < centroid.size(); ++r)
    if (std::isfinite(centroid[r])) {
      const double v = centroid[r] - line.Col(r);
      vv += v * v;
    }
  line.slope_sigma = std::sqrt(vv / (n - 2.0) / srr);
  return line;
}

// The oversampled ESF: pixel values averaged in bins of `bin_px` along the edge normal, bin
// centres at (j + phase) bin_px; only the distance range every row covers.
struct Esf {
  double bin_px = 0.25;
  std::vector<double> x, value, sum_squares;
  std::vector<int> count;
  int empty = 0;
};

Esf BinEsf(const Matrix& m, const EdgeLine& line, double slope, int oversampling, double phase) {
  const int rows = static_cast<int>(m.rows()), cols = static_cast<int>(m.cols());
  const double cos_t = 1.0 / std::sqrt(1.0 + slope * slope);
  double lo = -1e300, hi = 1e300;
  for (int r = 0; r < rows; ++r) {
    const double edge = line.a + slope * (r - line.row_mean);
    lo = std::max(lo, (0.0 - edge) * cos_t);
    hi = std::min(hi, (cols - 1.0 - edge) * cos_t);
  }
  Esf esf;
  esf.bin_px = 1.0 / oversampling;
  const int first = static_cast<int>(std::ceil(lo / esf.bin_px - phase));
  const int last = static_cast<int>(std::floor(hi / esf.bin_px - phase));
  const int n = std::max(0, last - first + 1);
  std::vector<double> sum(n, 0.0);
  esf.sum_squares.assign(n, 0.0);
  esf.count.assign(n, 0);
  for (int r = 0; r < rows; ++r) {
    const double edge = line.a + slope * (r - line.row_mean);
    for (int c = 0; c < cols; ++c) {
      const double d = (c - edge) * cos_t;
      const int k = static_cast<int>(std::floor(d / esf.bin_px - phase + 0.5)) - first;
      if (k < 0 || k >= n) continue;
      sum[k] += m(r, c);
      esf.sum_squares[k] += m(r, c) * m(r, c);
      ++esf.count[k];
    }
  }
  esf.x.resize(n);
  esf.value.assign(n, kNaN);
  for (int k = 0; k < n; ++k) {
    esf.x[k] = (first + k + phase) * esf.bin_px;
    if (esf.count[k] > 0) esf.value[k] = sum[k] / esf.count[k];
  }
  // Empty bins: linear interpolation between the nearest filled ones (ends: the nearest value).
  for (int k = 0; k < n; ++k) {
    if (esf.count[k] > 0) continue;
    ++esf.empty;
    int left = k - 1, right = k + 1;
    while (left >= 0 && esf.count[left] == 0) --left;
    while (right < n && esf.count[right] == 0) ++right;
    if (left < 0 && right >= n) continue;
    if (left < 0)
      esf.value[k] = esf.value[right];
    else if (right >= n)
      esf.value[k] = esf.value[left];
    else
      esf.value[k] =
          esf.value[left] + (esf.value[right] - esf.value[left]) * (k - left) / (right - left);
  }
  return esf;
}

// The windowed LSF of an ESF and its corrected MTF anywhere.
struct Lsf {
  double bin_px = 0.25;
  std::vector<double> x, value;
  double dc = 0.0;
};

Lsf MakeLsf(const Esf& esf, const std::vector<double>& values) {
  Lsf lsf;
  lsf.bin_px = esf.bin_px;
  const int n = static_cast<int>(values.size());
  if (n < 5) return lsf;
  const double half_width = std::min(-esf.x[1], esf.x[n - 2]);
  for (int k = 1; k + 1 < n; ++k) {
    const double w = Hamming(esf.x[k], half_width);  // > 0 on one contiguous run of bins
    if (w == 0.0) continue;
    lsf.x.push_back(esf.x[k]);
    lsf.value.push_back(0.5 * (values[k + 1] - values[k - 1]) * w);
    lsf.dc += lsf.value.back();
  }
  return lsf;
}

double MtfAt(const Lsf& lsf, double f) {
  // The LSF samples are equally spaced: the phasor advances by a constant factor per bin.
  std::complex<double> sum = 0.0;
  if (lsf.x.empty()) return kNaN;
  std::complex<double> phasor = std::polar(1.0, -2.0 * kPi * f * lsf.x.front());
  const std::complex<double> step = std::polar(1.0, -2.0 * kPi * f * lsf.bin_px);
  for (size_t k = 0; k < lsf.x.size(); ++k, phasor *= step) sum += lsf.value[k] * phasor;
  const double correction = Sinc(2.0 * f * lsf.bin_px) * Sinc(f * lsf.bin_px);
  return std::abs(sum) / std::abs(lsf.dc) / correction;
}

double CrossingFrequency(const Lsf& lsf, double level) {
  if (lsf.x.empty() || lsf.dc == 0.0) return kNaN;
  return FirstCrossingFrequency([&lsf](double f) { return MtfAt(lsf, f); }, level);
}

double Mtf50(const Esf& esf) { return CrossingFrequency(MakeLsf(esf, esf.value), 0.5); }

// Levels and pixel noise of the two flat sides: the bins beyond `flat_from_px` of the edge.
struct Sides {
  double left = 0.0, right = 0.0;  // mean ESF level on either side of the edge (col order)
  double noise_left = 0.0, noise_right = 0.0;  // pooled within-bin sigma of the pixels
};

Sides FlatSides(const Esf& esf, double flat_from_px) {
  double s[2] = {0, 0}, n[2] = {0, 0}, ss[2] = {0, 0}, dof[2] = {0, 0};
  for (size_t k = 0; k < esf.x.size(); ++k) {
    if (std::abs(esf.x[k]) < flat_from_px || esf.count[k] == 0) continue;
    const int side = esf.x[k] > 0 ? 1 : 0;
    const double sum = esf.value[k] * esf.count[k];
    s[side] += sum;
    n[side] += esf.count[k];
    ss[side] += esf.sum_squares[k] - sum * sum / esf.count[k];
    dof[side] += esf.count[k] - 1;
  }
  Sides sides;
  sides.left = n[0] > 0 ? s[0] / n[0] : kNaN;
  sides.right = n[1] > 0 ? s[1] / n[1] : kNaN;
  sides.noise_left = dof[0] > 0 ? std::sqrt(std::max(0.0, ss[0]) / dof[0]) : 0.0;
  sides.noise_right = dof[1] > 0 ? std::sqrt(std::max(0.0, ss[1]) / dof[1]) : 0.0;
  return sides;
}

// Distance (px) between the 10 % and 90 % points of the ESF between the two levels.
double RiseDistance(const Esf& esf, const Sides& sides) {
  double x10 = kNaN, x90 = kNaN;
  for (size_t k = 0; k < esf.x.size(); ++k) {
    const double level = (esf.value[k] - sides.left) / (sides.right - sides.left);
    if (std::isnan(x10) && level >= 0.1) x10 = esf.x[k];
    if (level >= 0.9) x90 = esf.x[k];
    if (!std::isnan(x90)) break;
  }
  return std::isnan(x10) || std::isnan(x90) ? 0.0 : std::abs(x90 - x10);
}

// Standard uncertainty of MTF50 from the pixel noise: the ESF bins perturbed by their standard
// errors (sigma of the side they are nearer in level / sqrt(pixels in the bin)), `samples` times.
double NoiseUncertainty(const Esf& esf, const Sides& sides, int samples) {
  if (sides.noise_left == 0.0 && sides.noise_right == 0.0) return 0.0;
  std::mt19937_64 rng(0x5eed12233ULL);  // fixed: the same image gives the same budget
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> sigma(esf.value.size());
  for (size_t k = 0; k < sigma.size(); ++k) {
    const double level =
        std::clamp((esf.value[k] - sides.left) / (sides.right - sides.left), 0.0, 1.0);
    const double noise = sides.noise_left + level * (sides.noise_right - sides.noise_left);
    sigma[k] = noise / std::sqrt(std::max(1, esf.count[k]));
  }
  double s = 0.0, ss = 0.0;
  int n = 0;
  std::vector<double> values(esf.value.size());
  for (int i = 0; i < samples; ++i) {
    for (size_t k = 0; k < values.size(); ++k) values[k] = esf.value[k] + sigma[k] * normal(rng);
    const double f = CrossingFrequency(MakeLsf(esf, values), 0.5);
    if (!std::isfinite(f)) continue;
    s += f, ss += f * f, ++n;
  }
  if (n < 2) return 0.0;
  return std::sqrt(std::max(0.0, (ss - s * s / n) / (n - 1)));
}

void ComputeBudget(const Matrix& m,
                   const EdgeLine& line,
                   const Esf& esf,
                   const Sides& sides,
                   const SlantedEdgeOptions& options,
                   SlantedEdgeResult* result) {
  const double f0 = result->mtf50_cy_px;
  auto& budget = result->budget;
  budget.push_back({"noise",
                    "B",
                    "normal (Monte-Carlo of the ESF bins)",
                    NoiseUncertainty(esf, sides, options.noise_samples)});
  // The edge angle: the slope +- its sigma. A wrong slope smears the ESF and lowers MTF50 either
  // way, so the mean of the two changes is the standard uncertainty (not their half difference).
  const double f_plus =
      Mtf50(BinEsf(m, line, line.b + line.slope_sigma, options.oversampling, 0.0));
  const double f_minus =
      Mtf50(BinEsf(m, line, line.b - line.slope_sigma, options.oversampling, 0.0));
  budget.push_back({"edge angle",
                    "B",
                    "normal (slope +- sigma)",
                    0.5 * (std::abs(f_plus - f0) + std::abs(f_minus - f0))});
  const double f_shifted = Mtf50(BinEsf(m, line, line.b, options.oversampling, 0.5));
  budget.push_back({"oversampling",
                    "B",
                    "rectangular (bins shifted by half a bin)",
                    std::abs(f_shifted - f0) / std::sqrt(3.0)});
  budget.push_back({"method",
                    "B",
                    "rectangular (validation on rendered edges)",
                    options.method_relative_half_width * f0 / std::sqrt(3.0)});
  double u2 = 0.0;
  for (const auto& component : budget)
    u2 += std::isfinite(component.u) ? component.u * component.u : 0.0;
  result->mtf50_u_cy_px = std::sqrt(u2);
  result->mtf50_expanded_cy_px = result->coverage_factor * result->mtf50_u_cy_px;
}

}  // namespace

double FirstCrossingFrequency(const std::function<double(double)>& mtf, double level) {
  constexpr double kScanStep = 1.0 / 256.0;
  double f0 = 0.0;
  for (double f1 = kScanStep; f1 <= kMaxFrequency + 1e-12; f1 += kScanStep) {
    if (mtf(f1) <= level) {
      for (int i = 0; i < 40 && f1 - f0 > 1e-7; ++i) {
        const double mid = 0.5 * (f0 + f1);
        (mtf(mid) > level ? f0 : f1) = mid;
      }
      return 0.5 * (f0 + f1);
    }
    f0 = f1;
  }
  return kNaN;
}

double EdgeMtfAt(const SlantedEdgeResult& edge, double f_cy_px) {
  Esf esf;
  esf.x = edge.esf_distance_px;
  esf.bin_px = esf.x.size() > 1 ? esf.x[1] - esf.x[0] : 0.25;
  return MtfAt(MakeLsf(esf, edge.esf), f_cy_px);
}

std::string_view MtfAxisName(MtfAxis axis) { return axis == MtfAxis::kX ? "x" : "y"; }

void SlantedEdgeOptions::Validate() const {
  if (!(gamma > 0.0 && gamma <= 10.0))
    throw ConfigError("gamma must be within (0, 10] (got " + std::to_string(gamma) + ")");
  if (oversampling < 2 || oversampling > 16)
    throw ConfigError("oversampling must be within 2..16 (got " + std::to_string(oversampling) +
                      ")");
  if (noise_samples < 8)
    throw ConfigError("noise_samples must be >= 8 (got " + std::to_string(noise_samples) + ")");
  if (!(min_angle_deg >= 0.0 && min_angle_deg < max_angle_deg && max_angle_deg <= 45.0))
    throw ConfigError("the angle range must satisfy 0 <= min_angle_deg < max_angle_deg <= 45");
  if (!(method_relative_half_width >= 0.0))
    throw ConfigError("method_relative_half_width must be >= 0");
}

SlantedEdgeResult MeasureSlantedEdge(const GrayImage& image,
                                     const PixelRegion& region,
                                     const SlantedEdgeOptions& options) {
  options.Validate();
  if (region.col < 0 || region.row < 0 || region.width < kMinRegionPx ||
      region.height < kMinRegionPx || region.col + region.width > image.cols() ||
      region.row + region.height > image.rows())
    throw InputError(RegionText(region) + ": must lie inside the " + std::to_string(image.cols()) +
                     " x " + std::to_string(image.rows()) + " px image and be at least " +
                     std::to_string(kMinRegionPx) + " x " + std::to_string(kMinRegionPx) + " px");
  SlantedEdgeResult result;
  const Matrix m = OrientedRegion(image, region, options.gamma, &result.axis);

  // Pass 1: plain centroids; the ESF of that line gives the sides, the noise and the edge width.
  EdgeLine line = FitLine(RowCentroids(m, nullptr, 0.0), region);
  Esf esf = BinEsf(m, line, line.b, options.oversampling, 0.0);
  const double half_range = 0.5 * (esf.x.empty() ? 0.0 : esf.x.back() - esf.x.front());
  Sides sides = FlatSides(esf, 0.5 * half_range);
  const double rise = RiseDistance(esf, sides);
  // Pass 2: centroids within a Hamming window about the first line (ISO 12233 / sfrmat).
  line = FitLine(RowCentroids(m, &line, std::max(4.0, 2.0 * rise + 3.0)), region);
  esf = BinEsf(m, line, line.b, options.oversampling, 0.0);
  const double flat_from = std::min(0.5 * half_range, std::max(3.0, 1.5 * rise + 2.0));
  sides = FlatSides(esf, flat_from);

  result.angle_deg = std::atan(line.b) * 180.0 / kPi;
  result.edge_offset_px = line.a;
  result.slope_sigma = line.slope_sigma;
  result.contrast = std::abs(sides.right - sides.left);
  result.noise_sigma = std::sqrt(
      0.5 * (sides.noise_left * sides.noise_left + sides.noise_right * sides.noise_right));
  result.empty_bins = esf.empty;
  const double abs_angle = std::abs(result.angle_deg);
  if (!(result.contrast > 10.0 * result.noise_sigma) || !(result.contrast > 0.0))
    throw InputError(RegionText(region) + ": no edge (step " + std::to_string(result.contrast) +
                     " against a noise of " + std::to_string(result.noise_sigma) +
                     ", expected a step above 10 noise sigmas)");
  if (abs_angle < options.min_angle_deg || abs_angle > options.max_angle_deg)
    throw InputError(RegionText(region) + ": the edge is slanted by " + std::to_string(abs_angle) +
                     " deg to the pixel axis, expected " + std::to_string(options.min_angle_deg) +
                     " .. " + std::to_string(options.max_angle_deg) + " deg");
  if (esf.x.empty() || esf.x.front() > -3.0 || esf.x.back() < 3.0)
    throw InputError(RegionText(region) +
                     ": the edge is too near the region's border (at least 3 px "
                     "of both sides are needed along every line)");

  result.esf_distance_px = esf.x;
  result.esf = esf.value;
  const Lsf lsf = MakeLsf(esf, esf.value);
  for (double f = 0.0; f <= kMaxFrequency + 1e-12; f += kCurveStep) {
    result.frequency_cy_px.push_back(f);
    result.mtf.push_back(MtfAt(lsf, f));
  }
  result.mtf50_cy_px = CrossingFrequency(lsf, 0.5);
  result.mtf10_cy_px = CrossingFrequency(lsf, 0.1);
  result.mtf_nyquist = MtfAt(lsf, 0.5);
  if (std::isfinite(result.mtf50_cy_px)) ComputeBudget(m, line, esf, sides, options, &result);
  return result;
}

EdgeMtfCombination CombineEdgeMeasurements(const std::vector<SlantedEdgeResult>& results) {
  AEROCAL_CHECK(results.size() >= 2) << "type A needs at least two repeats, got " << results.size();
  EdgeMtfCombination combination;
  combination.count = static_cast<int>(results.size());
  double s = 0.0, systematic2 = 0.0;
  for (const auto& r : results) {
    s += r.mtf50_cy_px;
    for (const auto& component : r.budget)
      if (component.name == "method" || component.name == "oversampling")
        systematic2 += component.u * component.u;
  }
  const double n = combination.count;
  combination.mtf50_cy_px = s / n;
  double ss = 0.0;
  for (const auto& r : results) ss += std::pow(r.mtf50_cy_px - combination.mtf50_cy_px, 2);
  combination.type_a_u_cy_px = std::sqrt(ss / (n - 1.0) / n);
  combination.type_b_u_cy_px = std::sqrt(systematic2 / n);
  combination.mtf50_u_cy_px = std::hypot(combination.type_a_u_cy_px, combination.type_b_u_cy_px);
  combination.mtf50_expanded_cy_px = 2.0 * combination.mtf50_u_cy_px;
  return combination;
}

GroundResolution ToGroundResolution(
    double f_cy_px, double u_f_cy_px, double pixel_size_mm, double gsd_m, double u_gsd_m) {
  AEROCAL_CHECK(f_cy_px > 0.0) << "frequency must be > 0 cycles/px, got " << f_cy_px;
  GroundResolution g;
  if (pixel_size_mm > 0.0) {
    g.lp_per_mm = f_cy_px / pixel_size_mm;
    g.lp_per_mm_u = u_f_cy_px / pixel_size_mm;
  }
  if (gsd_m > 0.0) {
    g.resolved_distance_m = gsd_m / (2.0 * f_cy_px);
    g.resolved_distance_u_m =
        g.resolved_distance_m * std::hypot(u_f_cy_px / f_cy_px, u_gsd_m / gsd_m);
  }
  return g;
}

}  // namespace aerocal::stitch
