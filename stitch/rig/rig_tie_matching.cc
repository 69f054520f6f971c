#include "stitch/rig/rig_tie_matching.h"

#include "calib/core/error.h"
#include "stitch/rig/head_window.h"
#include "stitch/rig/rig_convert.h"
#include "stitch/rig/rig_design.h"
#include "stitch/rig/stitched_image.h"

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>

namespace aerocal::stitch {

void RigTieMatchOptions::Validate() const {
  if (!(cell_px >= 8))
    throw ConfigError("tie matching: cell_px must be >= 8 (got " + std::to_string(cell_px) + ")");
  if (!(target_ties >= 0 && target_ties <= 1e7))
    throw ConfigError("tie matching: target_ties must be within 0..1e7 (got " +
                      std::to_string(target_ties) + ")");
  if (!(min_sigma_px > 0)) throw ConfigError("tie matching: min_sigma_px must be > 0");
  if (!(prefilter_sigma_px == 0 || (prefilter_sigma_px >= 0.3 && prefilter_sigma_px <= 5)))
    throw ConfigError("tie matching: prefilter_sigma_px must be 0 or within 0.3..5 (got " +
                      std::to_string(prefilter_sigma_px) + ")");
  lsm.Validate();
  wallis.Validate();
  foerstner.Validate();
}

double TieCellPx(const RigTieMatchOptions& options, double zone_pixels) {
  if (!(options.target_ties > 0) || !(zone_pixels > 0)) return options.cell_px;
  const double side = std::sqrt(zone_pixels / options.target_ties);
  return std::max(options.cell_px, 8.0 * std::ceil(side / 8.0));
}

namespace {

// Head px per virtual px at a virtual pixel: the larger singular value of the conversion's
// Jacobian (central differences of 1 px); 0 when the conversion is undefined there.
double HeadScale(const RigConverter& converter, int head, const Eigen::Vector2d& virtual_px) {
  Eigen::Matrix2d j;
  for (int a = 0; a < 2; ++a) {
    const Eigen::Vector2d d = Eigen::Vector2d::Unit(a);
    const auto plus = converter.HeadFromVirtual(head, virtual_px + d);
    const auto minus = converter.HeadFromVirtual(head, virtual_px - d);
    if (!plus || !minus) return 0.0;
    j.col(a) = 0.5 * (*plus - *minus);
  }
  return Eigen::JacobiSVD<Eigen::Matrix2d>(j).singularValues()(0);
}

// One tie: the first head's point `p` (virtual px) and, per other member head, LSM's match from
// `match(k)` (virtual px); appended to `out` when at least two heads remain (header comment).
template <typename MatchFn>
void AppendTie(const RigConverter& converter,
               const RigTieMatchOptions& options,
               const std::vector<int>& members,
               const Eigen::Vector2d& p,
               int exposure_index,
               MatchFn match,
               RigZoneMatchReport* report,
               RigTieMatches* out) {
  struct Row {
    int head;
    Eigen::Vector2d pixel;
    double sigma_px;  // head px
  };
  std::vector<Row> rows;
  double largest = 0.0;
  const int first = members.front();
  for (size_t m = 1; m < members.size(); ++m) {
    const int k = members[m];
    ++report->lsm_tried;
    const LsmResult lsm = match(k);
    const auto raw = lsm.ok() ? converter.HeadFromVirtual(k, lsm.position_in_b) : std::nullopt;
    const double head_scale = raw ? HeadScale(converter, k, lsm.position_in_b) : 0.0;
    if (!raw || !converter.InHeadFormat(k, *raw) || !(head_scale > 0)) {
      ++report->lsm_failed;
      continue;
    }
    const double sigma = std::max(options.min_sigma_px, lsm.SigmaMaxPx() / std::sqrt(2.0));
    largest = std::max(largest, sigma);
    rows.push_back({k, *raw, sigma * head_scale});
  }
  const auto raw_first = converter.HeadFromVirtual(first, p);
  const double first_scale = HeadScale(converter, first, p);
  if (rows.empty() || !raw_first || !converter.InHeadFormat(first, *raw_first) ||
      !(first_scale > 0))
    return;
  rows.insert(rows.begin(), Row{first, *raw_first, largest * first_scale});
  const int tie = static_cast<int>(out->ties.size());
  out->lsm_sigma_px.push_back(largest * std::sqrt(2.0));
  out->ties.push_back(
      {report->image + "/" + report->zone + "-" + std::to_string(report->ties + 1), false});
  const calib::Rig& rig = converter.rig();
  for (const Row& row : rows)
    out->observations.push_back({exposure_index,
                                 row.head,
                                 tie,
                                 row.pixel,
                                 row.sigma_px,
                                 "matched " + out->ties.back().id + "@" + rig.heads[row.head].id});
  ++report->ties;
}

// The exposure's tie cell from its zones' pixels (zone -> pixels), in either path.
double CellOfZones(const RigTieMatchOptions& options, const std::map<unsigned, long>& pixels) {
  double all = 0;
  for (const auto& zone : pixels) all += zone.second;
  return TieCellPx(options, all);
}

// One exposure's inputs to either path.
struct ExposureToMatch {
  const RigConverter& converter;
  const HeadMapCorrections& grids;
  const RigStitchExposure& exposure;
  int exposure_index;
  const std::vector<GrayImage>& heads;
};

// A zone pixel lies this far inside each of its heads' coverage: the template half size plus
// the LSM shift bound and 2 px (the interpolation support).
int ZoneMarginPx(const RigTieMatchOptions& options) {
  return options.lsm.half_size_px + static_cast<int>(std::ceil(options.lsm.max_shift_px)) + 2;
}

std::vector<int> Members(unsigned mask, int n_heads) {
  std::vector<int> members;
  for (int k = 0; k < n_heads; ++k)
    if (mask & (1u << k)) members.push_back(k);
  return members;
}

// The former path's heads (RigTieMatchOptions::whole_projections): every head once on the whole
// virtual grid (float grey values), its low-passed copy for LSM, and per virtual pixel the bits
// of the heads whose coverage, shrunk by the zone margin, holds it.
struct WholeProjections {
  std::vector<GrayImage> projected, smoothed;
  cv::Mat zone_mask;  // CV_8UC1, bit k: head k
};

// The low-pass copy for LSM: a normalised convolution over the head's coverage (blur of the
// covered values / blur of the coverage), so the fill outside does not leak in at the border.
GrayImage SmoothedOverCoverage(const GrayImage& projected, const cv::Mat& inside, double sigma) {
  GrayImage smoothed = projected;
  if (!(sigma > 0)) return smoothed;
  const int height = static_cast<int>(projected.rows()), width = static_cast<int>(projected.cols());
  cv::Mat weight;
  inside.convertTo(weight, CV_32F, 1.0 / 255.0);
  cv::Mat values = cv::Mat(height, width, CV_32F, const_cast<float*>(projected.data())).mul(weight);
  cv::GaussianBlur(values, values, cv::Size(0, 0), sigma);
  cv::GaussianBlur(weight, weight, cv::Size(0, 0), sigma);
  cv::Mat out(height, width, CV_32F, smoothed.data());
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const float w = weight.at<float>(r, c);
      out.at<float>(r, c) = w > 1e-3f ? values.at<float>(r, c) / w : 0.0f;
    }
  return smoothed;
}

WholeProjections ProjectWholeHeads(const ExposureToMatch& in, const RigTieMatchOptions& options) {
  const calib::Rig& rig = in.converter.rig();
  const int n_heads = static_cast<int>(rig.heads.size());
  const int width = rig.virtual_camera.camera.width_px,
            height = rig.virtual_camera.camera.height_px;
  // The coverage shrunk by the template half size plus the LSM shift bound and 2 px (the
  // interpolation support).
  const int margin = ZoneMarginPx(options);
  WholeProjections out{
      std::vector<GrayImage>(n_heads), {}, cv::Mat(height, width, CV_8UC1, cv::Scalar(0))};
  for (int k = 0; k < n_heads; ++k) {
    const GrayImage& head = in.heads[k];
    float top = 0.0f;
    for (int r = 0; r < head.rows(); ++r)
      for (int c = 0; c < head.cols(); ++c) top = std::max(top, head(r, c));
    const double scale = top <= 255.0f ? 256.0 : 1.0;
    MemoryRaster source({static_cast<int>(head.cols()), static_cast<int>(head.rows()), 1, 16});
    for (int r = 0; r < head.rows(); ++r)
      for (int c = 0; c < head.cols(); ++c)
        source.Set(c, r, 0, std::clamp(head(r, c) * scale, 0.0, 65535.0));
    const HeadProjection p = ProjectHeadOntoVirtual(in.converter, k, in.grids.grids[k], &source);
    GrayImage& projected = out.projected[k];
    projected.resize(height, width);
    cv::Mat inside(height, width, CV_8UC1);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        projected(r, c) = static_cast<float>(p.values.At(c, r) / scale);
        inside.at<std::uint8_t>(r, c) = p.covered[static_cast<size_t>(r) * width + c];
      }
    out.smoothed.push_back(SmoothedOverCoverage(projected, inside, options.prefilter_sigma_px));
    cv::Mat distance;
    cv::distanceTransform(inside, distance, cv::DIST_L2, 3);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c)
        if (distance.at<float>(r, c) > margin) out.zone_mask.at<std::uint8_t>(r, c) |= 1u << k;
  }
  return out;
}

// The former path: zones (the sets of two or more heads) from the whole projections; per zone
// and cell the strongest Foerstner point of the zone's first head over the zone's bounding box.
void MatchOnWholeProjections(const ExposureToMatch& in,
                             const RigTieMatchOptions& options,
                             RigTieMatches* out) {
  const auto& [converter, grids, exposure, exposure_index, heads] = in;
  const calib::Rig& rig = converter.rig();
  const int n_heads = static_cast<int>(rig.heads.size());
  const WholeProjections w = ProjectWholeHeads(in, options);
  const int width = w.zone_mask.cols, height = w.zone_mask.rows;
  std::map<unsigned, cv::Rect> zone_box;
  std::map<unsigned, long> zone_pixels;
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const unsigned m = w.zone_mask.at<std::uint8_t>(r, c);
      if (m == 0 || (m & (m - 1)) == 0) continue;
      cv::Rect& box = zone_box[m];
      box = box.area() == 0 ? cv::Rect(c, r, 1, 1) : (box | cv::Rect(c, r, 1, 1));
      ++zone_pixels[m];
    }
  const double cell_px = CellOfZones(options, zone_pixels);
  for (const auto& [mask, box] : zone_box) {
    RigZoneMatchReport report;
    report.image = exposure.image;
    report.zone = ZoneName(rig, mask);
    report.pixels = zone_pixels[mask];
    report.cell_px = cell_px;
    const std::vector<int> members = Members(mask, n_heads);
    const int first = members.front();
    const GrayImage crop = w.projected[first].block(box.y, box.x, box.height, box.width);
    FoerstnerOptions foerstner = options.foerstner;
    foerstner.max_points = std::max(foerstner.max_points, 100000);
    const std::vector<InterestPoint> points =
        DetectFoerstner(WallisFilter(crop, options.wallis), foerstner);
    // strongest first: the first point seen in a cell is its best
    std::map<std::pair<int, int>, Eigen::Vector2i> best;
    for (const InterestPoint& p : points) {
      const Eigen::Vector2i at(box.x + static_cast<int>(std::lround(p.position.x())),
                               box.y + static_cast<int>(std::lround(p.position.y())));
      if (at.x() < 0 || at.y() < 0 || at.x() >= width || at.y() >= height ||
          w.zone_mask.at<std::uint8_t>(at.y(), at.x()) != mask)
        continue;
      best.try_emplace({static_cast<int>(at.y() / cell_px), static_cast<int>(at.x() / cell_px)},
                       at);
    }
    report.cells = static_cast<int>(best.size());
    for (const auto& cell_point : best) {
      const Eigen::Vector2i at = cell_point.second;  // a copy: lambdas capture it
      const Eigen::Vector2d p(at.x(), at.y());
      const auto match = [&](int k) {
        return MatchLeastSquares(
            w.smoothed[first], at, w.smoothed[k], p, Eigen::Matrix2d::Identity(), options.lsm);
      };
      AppendTie(converter, options, members, p, exposure_index, match, &report, out);
    }
    out->zones.push_back(report);
  }
}

// Zones on a coarse grid (every kCoarseStep virtual px): per head the coverage, its distance
// transform, and per zone the sample count above the margin (the zone's pixels, estimated), the
// exposure's tie cell from them, and the cells with a sample within the margin relaxed by two
// steps (candidates: the exact zone of a point is decided at the point).
constexpr int kCoarseStep = 4;

struct CoarseZones {
  std::map<unsigned, long> pixels;                     // zone -> estimated pixels
  double cell_px = 0;                                  // TieCellPx of the zones' pixels
  std::map<std::pair<int, int>, unsigned> cell_heads;  // (row, col) cell -> union of heads
};

CoarseZones FindCoarseZones(const std::vector<HeadWindowSampler>& samplers,
                            int width,
                            int height,
                            double margin,
                            const RigTieMatchOptions& options) {
  const int cols = (width + kCoarseStep - 1) / kCoarseStep;
  const int rows = (height + kCoarseStep - 1) / kCoarseStep;
  cv::Mat exact(rows, cols, CV_8UC1, cv::Scalar(0)), relaxed(rows, cols, CV_8UC1, cv::Scalar(0));
  for (size_t k = 0; k < samplers.size(); ++k) {
    cv::Mat covered(rows, cols, CV_8UC1);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c)
        covered.at<std::uint8_t>(r, c) =
            samplers[k].Covers(c * kCoarseStep, r * kCoarseStep) ? 255 : 0;
    cv::Mat distance;
    cv::distanceTransform(covered, distance, cv::DIST_L2, 3);
    for (int r = 0; r < rows; ++r)
      for (int c = 0; c < cols; ++c) {
        const double d = distance.at<float>(r, c) * kCoarseStep;
        if (d > margin) exact.at<std::uint8_t>(r, c) |= 1u << k;
        if (d > margin - 2 * kCoarseStep) relaxed.at<std::uint8_t>(r, c) |= 1u << k;
      }
  }
  CoarseZones out;
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const unsigned m = exact.at<std::uint8_t>(r, c);
      if (m & (m - 1)) out.pixels[m] += kCoarseStep * kCoarseStep;
    }
  out.cell_px = CellOfZones(options, out.pixels);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) {
      const unsigned m_relaxed = relaxed.at<std::uint8_t>(r, c);
      if ((m_relaxed & (m_relaxed - 1)) == 0) continue;
      const std::pair<int, int> cell(static_cast<int>(r * kCoarseStep / out.cell_px),
                                     static_cast<int>(c * kCoarseStep / out.cell_px));
      out.cell_heads[cell] |= m_relaxed;
    }
  return out;
}

// The zone of a virtual pixel: the heads whose coverage holds the disc of `margin` around it.
unsigned ZoneAt(const std::vector<HeadWindowSampler>& samplers,
                const Eigen::Vector2i& at,
                double margin) {
  unsigned mask = 0;
  for (size_t k = 0; k < samplers.size(); ++k)
    if (samplers[k].CoversDisc(at.x(), at.y(), margin)) mask |= 1u << k;
  return mask;
}

// The rectangle [x0, x1) x [y0, y1) grown by `border` and clipped to the format.
cv::Rect Grown(int x0, int y0, int x1, int y1, int border, int width, int height) {
  const int left = std::max(0, x0 - border), top = std::max(0, y0 - border);
  return cv::Rect(
      left, top, std::min(width, x1 + border) - left, std::min(height, y1 + border) - top);
}

// Per zone and cell the strongest Foerstner point of the zone's first head whose zone is exactly
// that zone (the whole-projection path's rule), each head's window being its cell grown by the
// Wallis and Foerstner supports.
std::map<unsigned, std::map<std::pair<int, int>, Eigen::Vector2i>> BestPointsPerCell(
    const std::vector<HeadWindowSampler>& samplers,
    const CoarseZones& zones,
    int width,
    int height,
    double margin,
    const RigTieMatchOptions& options) {
  const int border = options.wallis.window_px / 2 + options.foerstner.window_px / 2 +
                     options.foerstner.suppression_px / 2 + 2;
  FoerstnerOptions foerstner = options.foerstner;
  foerstner.max_points = std::max(foerstner.max_points, 100000);
  std::map<unsigned, std::map<std::pair<int, int>, Eigen::Vector2i>> best;
  for (const auto& [cell, heads] : zones.cell_heads) {
    const int x0 = static_cast<int>(std::ceil(cell.second * zones.cell_px));
    const int y0 = static_cast<int>(std::ceil(cell.first * zones.cell_px));
    const int x1 = std::min(width, static_cast<int>(std::ceil((cell.second + 1) * zones.cell_px)));
    const int y1 = std::min(height, static_cast<int>(std::ceil((cell.first + 1) * zones.cell_px)));
    const cv::Rect box = Grown(x0, y0, x1, y1, border, width, height);
    for (size_t first = 0; first < samplers.size(); ++first) {
      // a first head: in the cell's union with a higher head after it
      if (!(heads & (1u << first)) || (heads >> (first + 1)) == 0) continue;
      const VirtualWindow w = samplers[first].Project(box.x, box.y, box.width, box.height);
      for (const InterestPoint& p :
           DetectFoerstner(WallisFilter(w.values, options.wallis), foerstner)) {
        const Eigen::Vector2i at(box.x + static_cast<int>(std::lround(p.position.x())),
                                 box.y + static_cast<int>(std::lround(p.position.y())));
        if (at.x() < x0 || at.y() < y0 || at.x() >= x1 || at.y() >= y1) continue;
        const unsigned mask = ZoneAt(samplers, at, margin);
        if ((mask & (mask - 1)) == 0 || !(mask & (1u << first)) || (mask & ((1u << first) - 1)))
          continue;  // not a zone, or first is not its first head
        const std::pair<int, int> key(static_cast<int>(at.y() / zones.cell_px),
                                      static_cast<int>(at.x() / zones.cell_px));
        best[mask].try_emplace(key, at);
      }
    }
  }
  return best;
}

// The default path: zones on a coarse grid, Foerstner per cell window, LSM between small
// low-passed windows around the point (the head->virtual geometry of the ground calibration is
// good to a few px, so nothing else of the projections is needed).
void MatchInWindows(const ExposureToMatch& in,
                    const RigTieMatchOptions& options,
                    RigTieMatches* out) {
  const auto& [converter, grids, exposure, exposure_index, heads] = in;
  const calib::Rig& rig = converter.rig();
  std::vector<HeadWindowSampler> samplers;
  const int n_heads = static_cast<int>(heads.size());
  samplers.reserve(n_heads);
  for (int k = 0; k < n_heads; ++k) samplers.emplace_back(converter, k, heads[k], grids.grids[k]);
  const int width = rig.virtual_camera.camera.width_px;
  const int height = rig.virtual_camera.camera.height_px;
  const int margin = ZoneMarginPx(options);
  const CoarseZones zones = FindCoarseZones(samplers, width, height, margin, options);
  const auto best = BestPointsPerCell(samplers, zones, width, height, margin, options);
  // Window half sides: the template plus the prefilter's border; the search adds the shift bound,
  // an affine slack and the bicubic support.
  const int blur = PrefilterBorderPx(options.prefilter_sigma_px);
  const int half_a = options.lsm.half_size_px + 1 + blur;
  const int half_b =
      options.lsm.half_size_px + static_cast<int>(std::ceil(options.lsm.max_shift_px)) + 6 + blur;
  for (const auto& [mask, cells] : best) {
    RigZoneMatchReport report;
    report.image = exposure.image;
    report.zone = ZoneName(rig, mask);
    const auto pixels = zones.pixels.find(mask);
    report.pixels = pixels == zones.pixels.end() ? 0 : pixels->second;
    report.cell_px = zones.cell_px;
    report.cells = static_cast<int>(cells.size());
    const std::vector<int> members = Members(mask, n_heads);
    const int first = members.front();
    for (const auto& cell_point : cells) {
      const Eigen::Vector2i at = cell_point.second;  // a copy: lambdas capture it
      const Eigen::Vector2d p(at.x(), at.y());
      const cv::Rect box_a = Grown(at.x(), at.y(), at.x() + 1, at.y() + 1, half_a, width, height);
      const VirtualWindow a = samplers[first].ProjectSmoothed(
          box_a.x, box_a.y, box_a.width, box_a.height, options.prefilter_sigma_px);
      const Eigen::Vector2i at_a(at.x() - a.x0, at.y() - a.y0);
      const auto match = [&](int k) {
        const cv::Rect box_b = Grown(at.x(), at.y(), at.x() + 1, at.y() + 1, half_b, width, height);
        const VirtualWindow b = samplers[k].ProjectSmoothed(
            box_b.x, box_b.y, box_b.width, box_b.height, options.prefilter_sigma_px);
        const Eigen::Vector2d origin(b.x0, b.y0);
        LsmResult lsm = MatchLeastSquares(
            a.values, at_a, b.values, p - origin, Eigen::Matrix2d::Identity(), options.lsm);
        lsm.position_in_b += origin;
        return lsm;
      };
      AppendTie(converter, options, members, p, exposure_index, match, &report, out);
    }
    out->zones.push_back(report);
  }
}

}  // namespace

void MatchRigExposureTies(const calib::Rig& rig,
                          const RigStitchExposure& exposure,
                          int exposure_index,
                          const std::vector<GrayImage>& heads,
                          const RigTieMatchOptions& options,
                          RigTieMatches* out) {
  options.Validate();
  const int n_heads = static_cast<int>(rig.heads.size());
  AEROCAL_CHECK(static_cast<int>(heads.size()) == n_heads) << heads.size() << " head images";
  AEROCAL_CHECK(n_heads <= 8) << "at most 8 heads";
  for (int k = 0; k < n_heads; ++k)
    AEROCAL_CHECK(heads[k].cols() == rig.heads[k].camera.width_px &&
                  heads[k].rows() == rig.heads[k].camera.height_px)
        << "head " << rig.heads[k].id << ": image " << heads[k].cols() << " x " << heads[k].rows();
  // The ground calibration and the POS: no increments, no offsets.
  RigExposure pose = exposure.pose;
  pose.increment_rad.clear();
  pose.dt_s.clear();
  const RigConverter converter(
      rig, pose, RectificationPlane{Eigen::Vector3d::UnitZ(), exposure.z_ref_m});
  const HeadMapCorrections grids = MakeHeadMapCorrections(converter, 0.01);
  const ExposureToMatch in{converter, grids, exposure, exposure_index, heads};
  if (options.whole_projections)
    MatchOnWholeProjections(in, options, out);
  else
    MatchInWindows(in, options, out);
}

}  // namespace aerocal::stitch
