#include "triangulation/calibration/direction_calibration.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/direction.h"
#include "triangulation/calibration/direction_problem.h"

#include <Eigen/Cholesky>
#include <Eigen/SVD>

#include <algorithm>
#include <deque>
#include <set>

namespace aerocal::triangulation {
namespace {

using internal::AddTargetBlocks;
using internal::DirectionObservationText;
using internal::DirectionStartRay;
using internal::FixInteriorEntries;

// One unit's blocks and residuals in the problem.
struct UnitProblem {
  calib::BlockId interior = -1, rotation = -1;
  Eigen::Vector4d quaternion = Eigen::Vector4d::Zero();
  std::vector<Eigen::Matrix2d> factors;  // L of C = L L^T per observation: v = L r
  std::vector<calib::ResidualId> ids;
};

// Adds the unit's interior (`out->camera`, free entries by options) and its rotation to the
// instrument. Block names carry the unit's id when there are several units ("interior II",
// "instrument_from_II").
void AddUnitBlocks(const DirectionUnit& unit,
                   bool several,
                   const DirectionCalibrationOptions& options,
                   calib::ProblemBuilder* builder,
                   DirectionCalibration* out,
                   UnitProblem* p) {
  std::vector<std::string> names;
  for (const auto& info : unit.start.Params()) names.emplace_back(info.name);
  p->interior = builder->AddBlock(several ? "interior " + unit.id : "interior",
                                  out->camera.interior.data(),
                                  out->camera.interior.size(),
                                  calib::BlockKind::kInterior,
                                  names);
  FixInteriorEntries(unit.start, options.free_interior, p->interior, builder);
  p->quaternion = calib::QuaternionFromOpk(unit.start_opk_rad);
  p->rotation = builder->AddRotationBlock(
      several ? "instrument_from_" + unit.id : "instrument_from_camera", p->quaternion.data());
}

// A direction residual per observation of the unit (`unit_name` in messages, "" for one unit).
void AddUnitResiduals(const DirectionUnit& unit,
                      const std::string& unit_name,
                      const std::map<std::string, calib::BlockId>& target_block,
                      calib::ProblemBuilder* builder,
                      DirectionCalibration* out,
                      UnitProblem* p) {
  const calib::PixelFrame frame = unit.start.frame();
  const double c_mm = unit.start.c_mm();
  for (size_t i = 0; i < unit.observations.size(); ++i) {
    const DirectionObservation& o = unit.observations[i];
    const auto it = target_block.find(o.target);
    if (it == target_block.end())
      throw InputError(DirectionObservationText(i, o, unit_name) + ": no such target");
    const Eigen::Matrix2d covariance = internal::DirectionObservationCovariance(
        i, o, unit_name, frame.PhotoFromPixel(o.pixel), c_mm, frame.pixel_size_mm);
    p->ids.push_back(builder->AddResidual(
        kGroupDirection,
        calib::MakeDirectionResidual(
            unit.start.model, frame, o.instrument_rotation, o.pixel, covariance),
        {p->interior, p->rotation, it->second},
        DirectionObservationText(i, o, unit_name)));
    p->factors.push_back(covariance.llt().matrixL());
    out->apriori_sigma_px.push_back(std::sqrt(0.5 * covariance.trace()) / frame.pixel_size_mm);
  }
}

// M = R_1^T R_k (reference_from_unit) as omega, phi, kappa from the two rotations' angles.
Eigen::Vector3d MountOpk(const Eigen::Vector3d& reference_opk, const Eigen::Vector3d& unit_opk) {
  return calib::OpkFromRotation(calib::RotationFromOpk(reference_opk).transpose() *
                                calib::RotationFromOpk(unit_opk));
}

// Sigma of the mount from the joint covariance of (R_1, R_k) (omega, phi, kappa each): J C J^T,
// J = d(mount)/d(R_1, R_k) by central differences (1e-7 rad; the map is smooth away from phi = 90
// deg).
Eigen::Vector3d MountSigma(const Eigen::Vector3d& reference_opk,
                           const Eigen::Vector3d& unit_opk,
                           const Eigen::Matrix<double, 6, 6>& joint) {
  constexpr double h = 1e-7;
  Eigen::Matrix<double, 3, 6> j;
  for (int i = 0; i < 6; ++i) {
    Eigen::Matrix<double, 6, 1> plus = Eigen::Matrix<double, 6, 1>::Zero(), minus;
    plus(i) = h;
    minus = -plus;
    j.col(i) = (MountOpk(reference_opk + plus.head<3>(), unit_opk + plus.tail<3>()) -
                MountOpk(reference_opk + minus.head<3>(), unit_opk + minus.tail<3>())) /
               (2.0 * h);
  }
  return (j * joint * j.transpose()).diagonal().cwiseMax(0.0).cwiseSqrt();
}

// After the solve: each unit's rotation, residuals, interior covariance; the mounts; the targets.
void CollectUnits(const std::vector<DirectionTarget>& targets,
                  const std::deque<Eigen::Vector2d>& angles,
                  const std::map<std::string, calib::BlockId>& target_block,
                  const std::vector<calib::BlockId>& covariance_blocks,
                  const calib::ProblemBuilder& builder,
                  std::vector<UnitProblem>* problems,
                  DirectionUnitsCalibration* out) {
  for (size_t t = 0; t < targets.size(); ++t)
    if (!targets[t].known) out->target_angles_rad[targets[t].id] = angles[t];
  const calib::CovarianceReport cov =
      builder.EstimateCovariance(covariance_blocks, out->report.sigma0);
  out->covariance_ok = cov.ok;
  if (cov.ok)
    for (const auto& t : targets)
      if (!t.known) out->target_sigma_rad[t.id] = cov.BlockSigma(target_block.at(t.id), 2);
  for (size_t k = 0; k < problems->size(); ++k) {
    UnitProblem& p = (*problems)[k];
    DirectionCalibration& u = out->units[k];
    const double pixel_size_mm = u.camera.pixel_size_mm;
    p.quaternion.normalize();
    u.opk_rad = calib::OpkFromQuaternion(p.quaternion);
    for (size_t i = 0; i < p.ids.size(); ++i) {
      const std::vector<double> r = builder.EvaluateResidual(p.ids[i]);
      const Eigen::Vector2d v_mm = p.factors[i] * Eigen::Vector2d(r[0], r[1]);
      u.residual_px.emplace_back(v_mm.x() / pixel_size_mm, -v_mm.y() / pixel_size_mm);
    }
    u.covariance_ok = cov.ok;
    u.undetermined = cov.undetermined;
    u.high_correlations = cov.high_correlations;
    u.interior_sigma.assign(u.camera.interior.size(), 0.0);
    out->mount_opk_rad.push_back(MountOpk(out->units[0].opk_rad, u.opk_rad));
    out->mount_sigma_rad.push_back(Eigen::Vector3d::Zero());
    if (!cov.ok) continue;
    u.interior_covariance = cov.BlockCovariance(p.interior, u.camera.interior.size());
    const Eigen::VectorXd s = cov.BlockSigma(p.interior, u.camera.interior.size());
    for (int i = 0; i < s.size(); ++i) u.interior_sigma[i] = s[i];
    u.opk_sigma_rad = cov.BlockSigma(p.rotation, 3);
    Eigen::MatrixXd cross;
    if (k > 0 && cov.CrossCovariance((*problems)[0].rotation, p.rotation, &cross)) {
      Eigen::Matrix<double, 6, 6> joint;
      joint << cov.BlockCovariance((*problems)[0].rotation, 3), cross, cross.transpose(),
          cov.BlockCovariance(p.rotation, 3);
      out->mount_sigma_rad.back() = MountSigma(out->units[0].opk_rad, u.opk_rad, joint);
    }
  }
}

}  // namespace

DirectionUnitsCalibration CalibrateUnitsFromDirections(const std::vector<DirectionUnit>& units,
                                                       const std::vector<DirectionTarget>& targets,
                                                       const DirectionCalibrationOptions& options) {
  AEROCAL_CHECK(!units.empty()) << "no units";
  DirectionUnitsCalibration out;
  calib::ProblemBuilder builder;
  const bool several = units.size() > 1;
  out.units.resize(units.size());  // the interiors' addresses stay fixed from here
  std::vector<UnitProblem> problems(units.size());
  std::vector<calib::BlockId> covariance_blocks;
  for (size_t k = 0; k < units.size(); ++k) {
    out.units[k].camera = units[k].start;
    AddUnitBlocks(units[k], several, options, &builder, &out.units[k], &problems[k]);
    covariance_blocks.push_back(problems[k].interior);
    covariance_blocks.push_back(problems[k].rotation);
  }
  std::deque<Eigen::Vector2d> angles;  // stable addresses for the builder
  std::map<std::string, calib::BlockId> target_block;
  out.method = AddTargetBlocks(targets, &builder, &angles, &target_block, &covariance_blocks);
  for (size_t k = 0; k < units.size(); ++k)
    AddUnitResiduals(
        units[k], several ? units[k].id : "", target_block, &builder, &out.units[k], &problems[k]);
  out.report = builder.Solve(options.solver);
  CollectUnits(targets, angles, target_block, covariance_blocks, builder, &problems, &out);
  for (DirectionCalibration& u : out.units) {
    u.report = out.report;
    u.method = out.method;
    u.target_angles_rad = out.target_angles_rad;
    u.target_sigma_rad = out.target_sigma_rad;
  }
  return out;
}

DirectionCalibration CalibrateFromDirections(const calib::Camera& start,
                                             const Eigen::Vector3d& start_opk_rad,
                                             const std::vector<DirectionTarget>& targets,
                                             const std::vector<DirectionObservation>& observations,
                                             const DirectionCalibrationOptions& options) {
  return CalibrateUnitsFromDirections({{"", start, start_opk_rad, observations}}, targets, options)
      .units.front();
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
    b += (o.instrument_rotation.transpose() * t) * DirectionStartRay(start, o.pixel).transpose();
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
    const Eigen::Vector3d d = o->instrument_rotation * r * DirectionStartRay(start, o->pixel);
    t.angles_rad =
        Eigen::Vector2d(std::atan2(d.x(), -d.z()), std::asin(std::clamp(d.y(), -1.0, 1.0)));
  }
}

}  // namespace aerocal::triangulation
