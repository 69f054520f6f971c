#include "triangulation/calibration/direction_calibration.h"

#include <algorithm>
#include <deque>

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/direction.h"

namespace aerocal::triangulation {
namespace {

std::string ObservationText(size_t i, const DirectionObservation& o) {
  return "direction observation " + std::to_string(i + 1) + " (target " + o.target +
         (o.setting.empty() ? "" : ", setting " + o.setting) + ")";
}

// Fixes the interior entries not named in `free` (all of them: the whole block).
void FixInteriorEntries(const calib::Camera& camera, const std::vector<std::string>& free,
                        calib::BlockId block, calib::ProblemBuilder* builder) {
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
  if (static_cast<int>(fixed.size()) == camera.interior.size()) builder->FixBlock(block);
  else if (!fixed.empty()) builder->FixEntries(block, fixed);
}

}  // namespace

DirectionCalibration CalibrateFromDirections(const calib::Camera& start,
                                             const Eigen::Vector3d& start_opk_rad,
                                             const std::vector<DirectionTarget>& targets,
                                             const std::vector<DirectionObservation>& observations,
                                             const DirectionCalibrationOptions& options) {
  DirectionCalibration out;
  out.camera = start;
  calib::ProblemBuilder builder;
  std::vector<std::string> names;
  for (const auto& p : start.Params()) names.emplace_back(p.name);
  const calib::BlockId interior = builder.AddBlock("interior", out.camera.interior.data(),
                                                   out.camera.interior.size(), calib::BlockKind::kInterior, names);
  FixInteriorEntries(start, options.free_interior, interior, &builder);
  Eigen::Vector4d quaternion = calib::QuaternionFromOpk(start_opk_rad);
  const calib::BlockId rotation = builder.AddRotationBlock("instrument_from_camera", quaternion.data());

  std::deque<Eigen::Vector2d> angles;  // stable addresses for the builder
  std::map<std::string, calib::BlockId> target_block;
  std::vector<calib::BlockId> covariance_blocks = {interior, rotation};
  bool all_known = true;
  for (const auto& t : targets) {
    if (target_block.count(t.id)) throw InputError("direction target " + t.id + ": given twice");
    angles.push_back(t.angles_rad);
    const calib::BlockId id =
        builder.AddBlock("target " + t.id, angles.back().data(), 2, calib::BlockKind::kOther, {"azimuth", "elevation"});
    if (t.known) builder.FixBlock(id);
    else covariance_blocks.push_back(id);
    all_known = all_known && t.known;
    target_block[t.id] = id;
  }
  out.method = all_known ? "collimator array" : "goniometer";

  const calib::PixelFrame frame = start.frame();
  const double c_mm = start.c_mm();
  for (size_t i = 0; i < observations.size(); ++i) {
    const DirectionObservation& o = observations[i];
    const auto it = target_block.find(o.target);
    if (it == target_block.end()) throw InputError(ObservationText(i, o) + ": no such target");
    if (!(o.sigma_px > 0.0) || !(o.sigma_rad >= 0.0))
      throw InputError(ObservationText(i, o) + ": sigma_px must be > 0 and sigma_rad >= 0");
    const Eigen::Matrix2d covariance = calib::DirectionCovarianceMm2(
        frame.PhotoFromPixel(o.pixel), c_mm, o.sigma_px, frame.pixel_size_mm, o.sigma_rad);
    builder.AddResidual(kGroupDirection,
                        calib::MakeDirectionResidual(start.model, frame, o.instrument_rotation, o.pixel, covariance),
                        {interior, rotation, it->second}, ObservationText(i, o));
  }
  out.report = builder.Solve(options.solver);
  quaternion.normalize();
  out.opk_rad = calib::OpkFromQuaternion(quaternion);
  for (const auto& t : targets)
    if (!t.known) out.target_angles_rad[t.id] = angles[std::distance(targets.data(), &t)];

  const calib::CovarianceReport cov = builder.EstimateCovariance(covariance_blocks, out.report.sigma0);
  out.covariance_ok = cov.ok;
  out.interior_sigma.assign(out.camera.interior.size(), 0.0);
  if (cov.ok) {
    const Eigen::VectorXd s = cov.BlockSigma(interior, out.camera.interior.size());
    for (int i = 0; i < s.size(); ++i) out.interior_sigma[i] = s[i];
    out.opk_sigma_rad = cov.BlockSigma(rotation, 3);
    for (const auto& t : targets)
      if (!t.known) out.target_sigma_rad[t.id] = cov.BlockSigma(target_block[t.id], 2);
  }
  return out;
}

}  // namespace aerocal::triangulation
