#include "stitch/rig/rig_tie_matching.h"

#include "calib/core/error.h"
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
  if (!(min_sigma_px > 0)) throw ConfigError("tie matching: min_sigma_px must be > 0");
  if (!(prefilter_sigma_px == 0 || (prefilter_sigma_px >= 0.3 && prefilter_sigma_px <= 5)))
    throw ConfigError("tie matching: prefilter_sigma_px must be 0 or within 0.3..5 (got " +
                      std::to_string(prefilter_sigma_px) + ")");
  lsm.Validate();
  wallis.Validate();
  foerstner.Validate();
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
  const calib::Camera& v = rig.virtual_camera.camera;
  const int width = v.width_px, height = v.height_px;

  // Every head once on the virtual grid (float grey values) with its coverage shrunk by the
  // template half size plus the LSM shift bound and 2 px (the interpolation support).
  const int margin =
      options.lsm.half_size_px + static_cast<int>(std::ceil(options.lsm.max_shift_px)) + 2;
  std::vector<GrayImage> projected(n_heads), smoothed(n_heads);
  cv::Mat zone_mask(height, width, CV_8UC1, cv::Scalar(0));
  for (int k = 0; k < n_heads; ++k) {
    float top = 0.0f;
    for (int r = 0; r < heads[k].rows(); ++r)
      for (int c = 0; c < heads[k].cols(); ++c) top = std::max(top, heads[k](r, c));
    const double scale = top <= 255.0f ? 256.0 : 1.0;
    MemoryRaster source(
        {static_cast<int>(heads[k].cols()), static_cast<int>(heads[k].rows()), 1, 16});
    for (int r = 0; r < heads[k].rows(); ++r)
      for (int c = 0; c < heads[k].cols(); ++c)
        source.Set(c, r, 0, std::clamp(heads[k](r, c) * scale, 0.0, 65535.0));
    const HeadProjection p = ProjectHeadOntoVirtual(converter, k, grids.grids[k], &source);
    projected[k].resize(height, width);
    cv::Mat inside(height, width, CV_8UC1);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c) {
        projected[k](r, c) = static_cast<float>(p.values.At(c, r) / scale);
        inside.at<std::uint8_t>(r, c) = p.covered[static_cast<size_t>(r) * width + c];
      }
    // The low-pass copy for LSM: a normalised convolution over the head's coverage (blur of the
    // covered values / blur of the coverage), so the fill outside does not leak in at the border.
    smoothed[k] = projected[k];
    if (options.prefilter_sigma_px > 0) {
      cv::Mat weight;
      inside.convertTo(weight, CV_32F, 1.0 / 255.0);
      cv::Mat values = cv::Mat(height, width, CV_32F, projected[k].data()).mul(weight);
      cv::GaussianBlur(values, values, cv::Size(0, 0), options.prefilter_sigma_px);
      cv::GaussianBlur(weight, weight, cv::Size(0, 0), options.prefilter_sigma_px);
      cv::Mat out(height, width, CV_32F, smoothed[k].data());
      for (int r = 0; r < height; ++r)
        for (int c = 0; c < width; ++c) {
          const float w = weight.at<float>(r, c);
          out.at<float>(r, c) = w > 1e-3f ? values.at<float>(r, c) / w : 0.0f;
        }
    }
    cv::Mat distance;
    cv::distanceTransform(inside, distance, cv::DIST_L2, 3);
    for (int r = 0; r < height; ++r)
      for (int c = 0; c < width; ++c)
        if (distance.at<float>(r, c) > margin) zone_mask.at<std::uint8_t>(r, c) |= 1u << k;
  }

  // Zones: the sets of two or more heads; per zone and cell the strongest Foerstner point of the
  // zone's first head.
  std::map<unsigned, cv::Rect> zone_box;
  std::map<unsigned, long> zone_pixels;
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      const unsigned m = zone_mask.at<std::uint8_t>(r, c);
      if (m == 0 || (m & (m - 1)) == 0) continue;
      cv::Rect& box = zone_box[m];
      box = box.area() == 0 ? cv::Rect(c, r, 1, 1) : (box | cv::Rect(c, r, 1, 1));
      ++zone_pixels[m];
    }
  for (const auto& [mask, box] : zone_box) {
    RigZoneMatchReport report;
    report.image = exposure.image;
    report.zone = ZoneName(rig, mask);
    report.pixels = zone_pixels[mask];
    std::vector<int> members;
    for (int k = 0; k < n_heads; ++k)
      if (mask & (1u << k)) members.push_back(k);
    const int first = members.front();
    const GrayImage crop = projected[first].block(box.y, box.x, box.height, box.width);
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
          zone_mask.at<std::uint8_t>(at.y(), at.x()) != mask)
        continue;
      best.try_emplace(
          {static_cast<int>(at.y() / options.cell_px), static_cast<int>(at.x() / options.cell_px)},
          at);
    }
    report.cells = static_cast<int>(best.size());
    for (const auto& [cell, at] : best) {
      const Eigen::Vector2d p(at.x(), at.y());
      struct Row {
        int head;
        Eigen::Vector2d pixel;
        double sigma_px;
      };  // sigma in head px
      std::vector<Row> rows;
      double largest = 0.0;
      for (size_t m = 1; m < members.size(); ++m) {
        const int k = members[m];
        ++report.lsm_tried;
        const LsmResult lsm = MatchLeastSquares(
            smoothed[first], at, smoothed[k], p, Eigen::Matrix2d::Identity(), options.lsm);
        const auto raw = lsm.ok() ? converter.HeadFromVirtual(k, lsm.position_in_b) : std::nullopt;
        if (!raw || !converter.InHeadFormat(k, *raw)) {
          ++report.lsm_failed;
          continue;
        }
        const double sigma = std::max(options.min_sigma_px, lsm.SigmaMaxPx() / std::sqrt(2.0));
        const double head_scale = HeadScale(converter, k, lsm.position_in_b);
        if (!(head_scale > 0)) {
          ++report.lsm_failed;
          continue;
        }
        largest = std::max(largest, sigma);
        rows.push_back({k, *raw, sigma * head_scale});
      }
      const auto raw_first = converter.HeadFromVirtual(first, p);
      const double first_scale = HeadScale(converter, first, p);
      if (rows.empty() || !raw_first || !converter.InHeadFormat(first, *raw_first) ||
          !(first_scale > 0))
        continue;
      rows.insert(rows.begin(), Row{first, *raw_first, largest * first_scale});
      const int tie = static_cast<int>(out->ties.size());
      out->lsm_sigma_px.push_back(largest * std::sqrt(2.0));
      out->ties.push_back(
          {exposure.image + "/" + report.zone + "-" + std::to_string(report.ties + 1), false});
      for (const Row& row : rows)
        out->observations.push_back(
            {exposure_index,
             row.head,
             tie,
             row.pixel,
             row.sigma_px,
             "matched " + out->ties.back().id + "@" + rig.heads[row.head].id});
      ++report.ties;
    }
    out->zones.push_back(report);
  }
}

}  // namespace aerocal::stitch
