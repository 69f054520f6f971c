#include "stitch/matching/overlap_matcher.h"

#include "calib/core/error.h"
#include "stitch/matching/overlap_strips.h"
#include "stitch/matching/strip_candidates.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <sys/stat.h>
#include <tuple>

namespace aerocal::stitch {
namespace {

struct Candidate {
  int cell = 0;
  double score = 0;  // lower is better (StripCandidates::score)
  Eigen::Vector2d uv_a, uv_b;
};

StitchObservation Row(const std::string& frame,
                      const std::string& point,
                      const std::string& sub,
                      const Eigen::Vector2d& uv,
                      double sigma_px) {
  return {frame, point, sub, uv.x(), uv.y(), sigma_px};
}

// Everything for one strip; appends rows and fills the report.
void MatchStrip(const calib::Camera& camera,
                const std::vector<GrayImage>& images,
                const OverlapStrip& strip,
                const std::string& frame,
                const MatchOptions& options,
                std::vector<StitchObservation>* rows,
                StripReport* report) {
  const calib::SubimageMapping& sa = camera.subimages[strip.a];
  const calib::SubimageMapping& sb = camera.subimages[strip.b];
  report->name = strip.name;
  const Eigen::Vector2d size = strip.in_virtual.sizes();
  const int nx = std::max(1, static_cast<int>(std::ceil(size.x() / options.cell_px)));
  const int ny = std::max(1, static_cast<int>(std::ceil(size.y() / options.cell_px)));
  report->cells = nx * ny;

  const StripCandidates found = options.search == Search::kPredicted
                                    ? PredictedCandidates(camera, images, strip, options)
                                    : DescriptorCandidates(camera, images, strip, options);
  report->keypoints_a = found.keypoints_a;
  report->keypoints_b = found.keypoints_b;
  report->ratio_matches = static_cast<int>(found.in_a.size());
  const std::vector<Eigen::Vector2d>& from = found.in_a;
  const std::vector<Eigen::Vector2d>& to = found.in_b;
  const RansacResult ransac = RansacAffine(from, to, options.ransac);
  if (!ransac.ok) return;
  report->ransac_inliers = static_cast<int>(ransac.inliers.size());

  std::vector<Candidate> candidates;
  for (int i : ransac.inliers) {
    const Eigen::Vector2d cell_xy =
        (sa.VirtualFromSub(from[i]) - strip.in_virtual.min()) / options.cell_px;
    const int cx = std::clamp(static_cast<int>(std::floor(cell_xy.x())), 0, nx - 1);
    const int cy = std::clamp(static_cast<int>(std::floor(cell_xy.y())), 0, ny - 1);
    candidates.push_back({cy * nx + cx, found.score[i], from[i], to[i]});
  }
  std::stable_sort(
      candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
        return std::tie(x.cell, x.score) < std::tie(y.cell, y.score);
      });

  const int h = options.lsm.half_size_px;
  const GrayImage& image_a = images[strip.a];
  int point_number = 0, accepted_in_cell = 0, current_cell = -1;
  std::set<std::pair<long, long>> used_a;  // one tie per template pixel
  for (const Candidate& c : candidates) {
    if (c.cell != current_cell) {
      current_cell = c.cell;
      accepted_in_cell = 0;
    }
    if (accepted_in_cell >= options.points_per_cell) continue;
    Eigen::Vector2d uv_a = c.uv_a, uv_b = c.uv_b;
    double sigma = options.sigma_px;
    if (options.use_lsm) {
      const Eigen::Vector2i p_a(static_cast<int>(std::lround(c.uv_a.x())),
                                static_cast<int>(std::lround(c.uv_a.y())));
      if (p_a.x() < h || p_a.y() < h || p_a.x() + h >= image_a.cols() ||
          p_a.y() + h >= image_a.rows())
        continue;  // template would leave sub-image a: not a candidate for LSM
      if (!used_a.insert({p_a.x(), p_a.y()}).second) continue;
      ++report->lsm_tried;
      const LsmResult lsm = MatchLeastSquares(image_a,
                                              p_a,
                                              images[strip.b],
                                              ransac.mapping.Apply(p_a.cast<double>()),
                                              ransac.mapping.linear,
                                              options.lsm);
      if (lsm.status == LsmStatus::kLowCorrelation || lsm.status == LsmStatus::kPoorPrecision) {
        ++report->lsm_poor_precision;
        continue;
      }
      if (!lsm.ok()) {
        ++report->lsm_not_converged;
        continue;
      }
      uv_a = p_a.cast<double>();
      uv_b = lsm.position_in_b;
      sigma = std::max(options.min_sigma_px, lsm.SigmaMaxPx() / std::sqrt(2.0));
    }
    const std::string id = strip.name + "_" + std::to_string(point_number++);
    rows->push_back(Row(frame, id, sa.id, uv_a, sigma));
    rows->push_back(Row(frame, id, sb.id, uv_b, sigma));
    if (accepted_in_cell++ == 0) ++report->covered_cells;
  }
  report->points = point_number;
}

}  // namespace

FrameMatches MatchFrame(const calib::Camera& camera,
                        const std::vector<GrayImage>& images,
                        const std::string& frame,
                        const MatchOptions& options) {
  options.Validate();
  AEROCAL_CHECK(images.size() == camera.subimages.size()) << "one image per sub-image";
  for (std::size_t k = 0; k < images.size(); ++k) {
    AEROCAL_CHECK(images[k].cols() == camera.subimages[k].width_px &&
                  images[k].rows() == camera.subimages[k].height_px)
        << "image of sub-image " << camera.subimages[k].id << " has the wrong format";
  }
  const std::vector<OverlapStrip> strips =
      PredictOverlapStrips(camera, options.margin_px, options.min_strip_width_px);
  std::vector<std::vector<StitchObservation>> rows(strips.size());
  FrameMatches out;
  out.strips.resize(strips.size());
  tbb::parallel_for(std::size_t{0}, strips.size(), [&](std::size_t s) {
    MatchStrip(camera, images, strips[s], frame, options, &rows[s], &out.strips[s]);
  });
  for (const auto& strip_rows : rows)
    out.observations.insert(out.observations.end(), strip_rows.begin(), strip_rows.end());
  return out;
}

void WriteMatchedObservations(const std::string& path,
                              const std::vector<StitchObservation>& observations,
                              bool append,
                              double default_sigma_px) {
  std::vector<StitchObservation> all;
  struct stat info {};
  if (append && ::stat(path.c_str(), &info) == 0) {
    all = ReadStitchObservations(path, default_sigma_px);
    std::set<std::string> existing;
    for (const StitchObservation& o : all) existing.insert(o.frame);
    for (const StitchObservation& o : observations)
      if (existing.count(o.frame))
        ThrowInputError({path, 0}, "frame " + o.frame + " is already in the file");
  }
  all.insert(all.end(), observations.begin(), observations.end());
  WriteStitchObservations(path, all);
}

}  // namespace aerocal::stitch
