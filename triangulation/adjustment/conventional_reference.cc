#include "triangulation/adjustment/conventional_reference.h"

#include "triangulation/adjustment/block_adjustment.h"

#include <limits>
#include <string>

namespace aerocal::triangulation {

AdjustmentResult AdjustConventionalReference(const Project& project,
                                             const AdjustOptions& options,
                                             const AdjustmentResult& self_calibration,
                                             Progress* progress) {
  // Rejections name the observation by image, point, sub-image and measured pixel.
  auto rejected = [&](const ImageObservation& o) {
    for (const auto& r : self_calibration.rejected)
      if (r.image == o.image && r.point == o.point && r.subimage == o.subimage &&
          r.measured_px == o.pixel)
        return true;
    return false;
  };
  Project clean = project;
  clean.observations.clear();
  for (const auto& o : project.observations)
    if (!rejected(o)) clean.observations.push_back(o);
  const size_t left_out = project.observations.size() - clean.observations.size();

  AdjustOptions conventional = options;
  conventional.free_interior.clear();
  conventional.data_snooping = false;
  conventional.robust_start = false;
  conventional.auto_robust_start = false;  // the self-calibrating run decided the gross errors
  // Its sigma0 shows the camera error the fixed interior cannot model: that is the finding of the
  // comparison, not a reason to call the run invalid (non-convergence and singularity still are).
  conventional.max_sigma0 = std::numeric_limits<double>::infinity();
  AdjustmentResult result = Adjust(clean, conventional, progress);
  result.rejected = self_calibration.rejected;
  result.notes.push_back(
      std::to_string(left_out) +
      " observation(s) rejected as gross errors by the self-calibrating run are left out; no "
      "data snooping here (the residuals carry the camera error the fixed interior cannot model)");
  return result;
}

}  // namespace aerocal::triangulation
