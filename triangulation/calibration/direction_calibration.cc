#include "triangulation/calibration/direction_calibration.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/direction.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <algorithm>
#include <deque>
#include <set>

namespace aerocal::triangulation {
namespace {

std::string ObservationText(size_t i, const DirectionObservation& o) {
  return (o.where.empty() ? "" : o.where + ": ") + "direction observation " +
         std::to_string(i + 1) + " (target " + o.target +
         (o.setting.empty() ? "" : ", setting " + o.setting) + ")";
}

// The start camera's ray of a pixel (camera frame; principal point at the format centre, no
// distortion): a start value only.
Eigen::Vector3d StartRay(const calib::Camera& start, const Eigen::Vector2d& pixel) {
  const Eigen::Vector2d xy = start.frame().PhotoFromPixel(pixel);
  return Eigen::Vector3d(xy.x(), xy.y(), -start.c_mm()).normalized();
}

// Fixes the interior entries not named in `free` (all of them: the whole block).
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
  const calib::BlockId interior = builder.AddBlock("interior",
                                                   out.camera.interior.data(),
                                                   out.camera.interior.size(),
                                                   calib::BlockKind::kInterior,
                                                   names);
  FixInteriorEntries(start, options.free_interior, interior, &builder);
  Eigen::Vector4d quaternion = calib::QuaternionFromOpk(start_opk_rad);
  const calib::BlockId rotation =
      builder.AddRotationBlock("instrument_from_camera", quaternion.data());

  std::deque<Eigen::Vector2d> angles;  // stable addresses for the builder
  std::map<std::string, calib::BlockId> target_block;
  std::vector<calib::BlockId> covariance_blocks = {interior, rotation};
  bool all_known = true;
  for (const auto& t : targets) {
    if (target_block.count(t.id)) throw InputError("direction target " + t.id + ": given twice");
    angles.push_back(t.angles_rad);
    const calib::BlockId id = builder.AddBlock("target " + t.id,
                                               angles.back().data(),
                                               2,
                                               calib::BlockKind::kOther,
                                               {"azimuth", "elevation"});
    if (t.known)
      builder.FixBlock(id);
    else
      covariance_blocks.push_back(id);
    all_known = all_known && t.known;
    target_block[t.id] = id;
  }
  out.method = all_known ? "collimator array" : "goniometer";

  const calib::PixelFrame frame = start.frame();
  const double c_mm = start.c_mm();
  std::vector<Eigen::Matrix2d> factors;  // L of C = L L^T per observation: v = L r
  std::vector<calib::ResidualId> ids;
  for (size_t i = 0; i < observations.size(); ++i) {
    const DirectionObservation& o = observations[i];
    const auto it = target_block.find(o.target);
    if (it == target_block.end()) throw InputError(ObservationText(i, o) + ": no such target");
    if (!(o.sigma_px > 0.0) || !(o.sigma_rad >= 0.0))
      throw InputError(ObservationText(i, o) + ": sigma_px must be > 0 and sigma_rad >= 0");
    const Eigen::Matrix2d covariance = calib::DirectionCovarianceMm2(
        frame.PhotoFromPixel(o.pixel), c_mm, o.sigma_px, frame.pixel_size_mm, o.sigma_rad);
    ids.push_back(
        builder.AddResidual(kGroupDirection,
                            calib::MakeDirectionResidual(
                                start.model, frame, o.instrument_rotation, o.pixel, covariance),
                            {interior, rotation, it->second},
                            ObservationText(i, o)));
    factors.push_back(covariance.llt().matrixL());
    out.apriori_sigma_px.push_back(std::sqrt(0.5 * covariance.trace()) / frame.pixel_size_mm);
  }
  out.report = builder.Solve(options.solver);
  quaternion.normalize();
  out.opk_rad = calib::OpkFromQuaternion(quaternion);
  for (const auto& t : targets)
    if (!t.known) out.target_angles_rad[t.id] = angles[std::distance(targets.data(), &t)];
  for (size_t i = 0; i < ids.size(); ++i) {
    const std::vector<double> r = builder.EvaluateResidual(ids[i]);
    const Eigen::Vector2d v_mm = factors[i] * Eigen::Vector2d(r[0], r[1]);
    out.residual_px.emplace_back(v_mm.x() / frame.pixel_size_mm, -v_mm.y() / frame.pixel_size_mm);
  }

  const calib::CovarianceReport cov =
      builder.EstimateCovariance(covariance_blocks, out.report.sigma0);
  out.covariance_ok = cov.ok;
  out.undetermined = cov.undetermined;
  out.high_correlations = cov.high_correlations;
  out.interior_sigma.assign(out.camera.interior.size(), 0.0);
  if (cov.ok) {
    out.interior_covariance = cov.BlockCovariance(interior, out.camera.interior.size());
    const Eigen::VectorXd s = cov.BlockSigma(interior, out.camera.interior.size());
    for (int i = 0; i < s.size(); ++i) out.interior_sigma[i] = s[i];
    out.opk_sigma_rad = cov.BlockSigma(rotation, 3);
    for (const auto& t : targets)
      if (!t.known) out.target_sigma_rad[t.id] = cov.BlockSigma(target_block[t.id], 2);
  }
  return out;
}

Eigen::Vector3d StartRotationFromDirections(const calib::Camera& start,
                                            const std::vector<DirectionTarget>& targets,
                                            const std::vector<DirectionObservation>& observations) {
  std::map<std::string, const DirectionTarget*> known;
  for (const auto& t : targets)
    if (t.known) known[t.id] = &t;
  Eigen::Matrix3d b = Eigen::Matrix3d::Zero();  // sum of (G^T t) u^T
  std::set<std::string> used;
  for (const auto& o : observations) {
    const auto it = known.find(o.target);
    if (it == known.end()) continue;
    Eigen::Vector3d t;
    calib::DirectionFromAngles(it->second->angles_rad.data(), t.data());
    b += (o.instrument_rotation.transpose() * t) * StartRay(start, o.pixel).transpose();
    used.insert(o.target);
  }
  if (used.size() < 2) return Eigen::Vector3d::Zero();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(b, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
  d(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return calib::OpkFromRotation(svd.matrixU() * d * svd.matrixV().transpose());
}

void StartUnknownTargets(const calib::Camera& start,
                         const Eigen::Vector3d& start_opk_rad,
                         const std::vector<DirectionObservation>& observations,
                         std::vector<DirectionTarget>* targets) {
  const Eigen::Matrix3d r = calib::RotationFromOpk(start_opk_rad);
  for (auto& t : *targets) {
    if (t.known) continue;
    const auto o = std::find_if(observations.begin(),
                                observations.end(),
                                [&](const DirectionObservation& x) { return x.target == t.id; });
    if (o == observations.end()) continue;
    const Eigen::Vector3d d = o->instrument_rotation * r * StartRay(start, o->pixel);
    t.angles_rad =
        Eigen::Vector2d(std::atan2(d.x(), -d.z()), std::asin(std::clamp(d.y(), -1.0, 1.0)));
  }
}

}  // namespace aerocal::triangulation
