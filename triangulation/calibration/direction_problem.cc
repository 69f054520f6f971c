#include "triangulation/calibration/direction_problem.h"

#include "calib/core/error.h"
#include "calib/residuals/direction.h"

namespace aerocal::triangulation::internal {

std::string DirectionObservationText(size_t i,
                                     const DirectionObservation& o,
                                     const std::string& unit) {
  return (o.where.empty() ? "" : o.where + ": ") + (unit.empty() ? "" : "unit " + unit + ": ") +
         "direction observation " + std::to_string(i + 1) + " (target " + o.target +
         (o.setting.empty() ? "" : ", setting " + o.setting) + ")";
}

Eigen::Vector3d DirectionStartRay(const calib::Camera& start, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = start.frame().PhotoFromPixel(pixel);
  return Eigen::Vector3d(xy.x(), xy.y(), -start.c_mm()).normalized();
}

void FixInteriorEntries(const calib::Camera& camera,
                        const std::vector<std::string>& free,
                        calib::BlockId block,
                        calib::ProblemBuilder* builder) {
  std::vector<bool> is_free(camera.interior.size(), false);
  for (const auto& name : free) {
    const int index = camera.ParamIndex(name);
    if (index < 0)
      throw InputError("free_interior: '" + name + "' is not a parameter of the camera's model");
    is_free[index] = true;
  }
  std::vector<int> fixed;
  for (int i = 0; i < camera.interior.size(); ++i)
    if (!is_free[i]) fixed.push_back(i);
  if (static_cast<int>(fixed.size()) == camera.interior.size())
    builder->FixBlock(block);
  else if (!fixed.empty())
    builder->FixEntries(block, fixed);
}

std::string AddTargetBlocks(const std::vector<DirectionTarget>& targets,
                            calib::ProblemBuilder* builder,
                            std::deque<Eigen::Vector2d>* angles,
                            std::map<std::string, calib::BlockId>* target_block,
                            std::vector<calib::BlockId>* covariance_blocks) {
  bool all_known = true;
  for (const auto& t : targets) {
    if (target_block->count(t.id)) throw InputError("direction target " + t.id + ": given twice");
    angles->push_back(t.angles_rad);
    const calib::BlockId id = builder->AddBlock("target " + t.id,
                                                angles->back().data(),
                                                2,
                                                calib::BlockKind::kOther,
                                                {"azimuth", "elevation"});
    if (t.known)
      builder->FixBlock(id);
    else
      covariance_blocks->push_back(id);
    all_known = all_known && t.known;
    (*target_block)[t.id] = id;
  }
  return all_known ? "collimator array" : "goniometer";
}

Eigen::Matrix2d DirectionObservationCovariance(size_t index,
                                               const DirectionObservation& o,
                                               const std::string& unit,
                                               const Eigen::Vector2d& xy_mm,
                                               double c_mm,
                                               double pixel_size_mm) {
  if (!(o.sigma_px > 0.0) || !(o.sigma_rad >= 0.0))
    throw InputError(DirectionObservationText(index, o, unit) +
                     ": sigma_px must be > 0 and sigma_rad >= 0");
  return calib::DirectionCovarianceMm2(xy_mm, c_mm, o.sigma_px, pixel_size_mm, o.sigma_rad);
}

}  // namespace aerocal::triangulation::internal
