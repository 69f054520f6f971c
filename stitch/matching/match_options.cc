#include "stitch/matching/match_options.h"

#include "calib/core/error.h"

namespace aerocal::stitch {

Detector ParseDetector(const std::string& name) {
  if (name == "sift") return Detector::kSift;
  if (name == "foerstner") return Detector::kFoerstner;
  throw ConfigError("detector must be sift or foerstner (got " + name + ")");
}

Search ParseSearch(const std::string& name) {
  if (name == "descriptors") return Search::kDescriptors;
  if (name == "predicted") return Search::kPredicted;
  throw ConfigError("search must be descriptors or predicted (got " + name + ")");
}

void MatchOptions::Validate() const {
  if (!(margin_px >= 0)) throw ConfigError("margin_px must be >= 0");
  if (search == Search::kPredicted && !(margin_px >= 2))
    throw ConfigError(
        "margin_px must be >= 2 for the predicted search (the correlation peak "
        "needs a neighbour on each side)");
  if (!(min_strip_width_px > 0)) throw ConfigError("min_strip_width_px must be > 0");
  if (!(sift_contrast > 0)) throw ConfigError("sift_contrast must be > 0");
  if (max_keypoints <= 0) throw ConfigError("max_keypoints must be > 0");
  if (!(ratio > 0 && ratio <= 1)) throw ConfigError("ratio must be in (0, 1]");
  if (!(cell_px > 0)) throw ConfigError("cell_px must be > 0");
  if (points_per_cell < 1) throw ConfigError("points_per_cell must be >= 1");
  if (candidates_per_cell < 1) throw ConfigError("candidates_per_cell must be >= 1");
  if (!(min_ncc > 0 && min_ncc <= 1)) throw ConfigError("min_ncc must be in (0, 1]");
  if (!(sigma_px > 0)) throw ConfigError("sigma_px must be > 0");
  if (!(min_sigma_px > 0)) throw ConfigError("min_sigma_px must be > 0");
  if (descriptor_size_px < 4) throw ConfigError("descriptor_size_px must be >= 4");
  if (!(ransac.threshold_px > 0) || ransac.iterations < 1 || ransac.min_inliers < 3)
    throw ConfigError("ransac: threshold_px > 0, iterations >= 1, min_inliers >= 3 required");
  lsm.Validate();
  wallis.Validate();
  foerstner.Validate();
}

}  // namespace aerocal::stitch
