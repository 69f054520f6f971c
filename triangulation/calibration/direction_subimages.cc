#include "triangulation/calibration/direction_subimages.h"

#include "calib/camera/rotation.h"
#include "calib/core/error.h"
#include "calib/residuals/direction.h"
#include "stitch/adjustment/mapping_param_names.h"
#include "triangulation/calibration/direction_problem.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>

#include <algorithm>
#include <cmath>
#include <deque>
#include <map>

namespace aerocal::triangulation {
namespace {

// One observed sub-image in the problem: its conditioned mapping (the block's values) and the
// observations on it.
struct SubimageBlock {
  int camera_index = -1;  // in start.subimages
  calib::MappingConditioning cond;
  std::vector<double> conditioned;
  calib::BlockId block = -1;
  std::vector<size_t> observations;  // indices into the observations
  std::vector<calib::ResidualId> residuals;
  std::vector<Eigen::Matrix2d> factors;  // L of C = L L^T per observation: v = L r
};

// The observed sub-images, the camera file's order, the reference first.
std::vector<SubimageBlock> ObservedSubimages(const calib::Camera& start,
                                             const std::vector<DirectionObservation>& observations,
                                             const std::vector<std::string>& subimage_of,
                                             std::string* reference) {
  AEROCAL_CHECK(subimage_of.size() == observations.size()) << "one sub-image per observation";
  std::vector<SubimageBlock> out(start.subimages.size());
  for (size_t i = 0; i < observations.size(); ++i) {
    const int k = start.SubimageIndex(subimage_of[i]);
    if (k < 0)
      throw InputError(internal::DirectionObservationText(i, observations[i], "") + ": sub-image " +
                       subimage_of[i] + " is not a sub-image of the camera");
    out[k].observations.push_back(i);
  }
  std::vector<SubimageBlock> observed;
  for (size_t k = 0; k < out.size(); ++k) {
    if (out[k].observations.empty()) continue;
    out[k].camera_index = static_cast<int>(k);
    const calib::SubimageMapping& m = start.subimages[k];
    const int n = static_cast<int>(out[k].observations.size());
    if (2 * n < calib::MappingParamCount(m.model))
      throw InputError(observations[out[k].observations.front()].where + ": sub-image " + m.id +
                       ": " + std::to_string(n) + " directions (" + std::to_string(2 * n) +
                       " scalar) cannot determine its " +
                       std::to_string(calib::MappingParamCount(m.model)) + " " +
                       std::string(calib::MappingModelName(m.model)) + " mapping parameters");
    if (reference->empty()) *reference = m.id;
    observed.push_back(std::move(out[k]));
  }
  AEROCAL_CHECK(!observed.empty()) << "no observations";
  const auto ref = std::find_if(observed.begin(), observed.end(), [&](const SubimageBlock& b) {
    return start.subimages[b.camera_index].id == *reference;
  });
  if (ref == observed.end())
    throw InputError("reference sub-image " + *reference +
                     ": not a sub-image of the camera with observations");
  std::rotate(observed.begin(), ref, ref + 1);
  return observed;
}

// The mapping blocks (conditioned parameters, named "mapping ID").
void AddMappingBlocks(const calib::Camera& start,
                      calib::ProblemBuilder* builder,
                      std::vector<SubimageBlock>* blocks) {
  for (SubimageBlock& b : *blocks) {
    const calib::SubimageMapping& m = start.subimages[b.camera_index];
    b.cond = m.Conditioning();
    b.conditioned = calib::ConditionedFromPlain(m.model, b.cond, m.params);
    b.block = builder->AddBlock("mapping " + m.id,
                                b.conditioned.data(),
                                static_cast<int>(b.conditioned.size()),
                                calib::BlockKind::kMapping,
                                stitch::MappingParamNames(m.model));
  }
}

// A direction residual per observation of each sub-image, weighted at its start virtual point.
void AddSubimageResiduals(const calib::Camera& start,
                          const std::vector<DirectionObservation>& observations,
                          const std::map<std::string, calib::BlockId>& target_block,
                          calib::BlockId interior,
                          calib::BlockId rotation,
                          calib::ProblemBuilder* builder,
                          std::vector<SubimageBlock>* blocks,
                          std::vector<double>* apriori_sigma_px) {
  const calib::PixelFrame frame = start.frame();
  apriori_sigma_px->assign(observations.size(), 0.0);
  for (SubimageBlock& b : *blocks) {
    const calib::SubimageMapping& m = start.subimages[b.camera_index];
    for (size_t i : b.observations) {
      const DirectionObservation& o = observations[i];
      const auto it = target_block.find(o.target);
      if (it == target_block.end())
        throw InputError(internal::DirectionObservationText(i, o, m.id) + ": no such target");
      const Eigen::Matrix2d covariance =
          internal::DirectionObservationCovariance(i,
                                                   o,
                                                   m.id,
                                                   frame.PhotoFromPixel(m.VirtualFromSub(o.pixel)),
                                                   start.c_mm(),
                                                   frame.pixel_size_mm);
      b.residuals.push_back(builder->AddResidual(
          kGroupDirection,
          calib::MakeSubimageDirectionResidual(
              start.model, m.model, frame, b.cond, o.pixel, o.instrument_rotation, covariance),
          {b.block, interior, rotation, it->second},
          internal::DirectionObservationText(i, o, m.id)));
      b.factors.push_back(covariance.llt().matrixL());
      (*apriori_sigma_px)[i] = std::sqrt(0.5 * covariance.trace()) / frame.pixel_size_mm;
    }
  }
}

// Sets the interior's radial, decentring and affinity terms to 0 (the gauge's design point).
void ZeroDistortion(calib::Camera* camera) {
  const auto table = camera->Params();
  for (size_t i = 0; i < table.size(); ++i)
    if (table[i].group == calib::ParamGroup::kRadial ||
        table[i].group == calib::ParamGroup::kDecentering ||
        table[i].group == calib::ParamGroup::kAffinity)
      camera->interior[i] = 0.0;
}

// One direction problem of a multi-CCD camera in its builder: the interior, R, the targets, the
// observed sub-images' mappings and a residual per observation, at `camera`'s values.
struct SubimageProblem {
  calib::ProblemBuilder builder;
  calib::Camera camera;  // the interior block's values (and the start mappings)
  Eigen::Vector4d quaternion = Eigen::Vector4d::Zero();
  std::deque<Eigen::Vector2d> angles;
  std::map<std::string, calib::BlockId> target_block;
  std::vector<SubimageBlock> blocks;  // the reference first
  calib::BlockId interior = -1, rotation = -1;
  std::vector<double> apriori_sigma_px;
  std::string method;
};

void BuildProblem(const calib::Camera& camera,
                  const Eigen::Vector3d& opk_rad,
                  const std::vector<DirectionTarget>& targets,
                  const std::vector<DirectionObservation>& observations,
                  const std::vector<std::string>& subimage_of,
                  std::string* reference,
                  const DirectionCalibrationOptions& options,
                  SubimageProblem* p) {
  p->camera = camera;
  p->blocks = ObservedSubimages(camera, observations, subimage_of, reference);
  std::vector<std::string> names;
  for (const auto& info : camera.Params()) names.emplace_back(info.name);
  p->interior = p->builder.AddBlock("interior",
                                    p->camera.interior.data(),
                                    p->camera.interior.size(),
                                    calib::BlockKind::kInterior,
                                    names);
  internal::FixInteriorEntries(camera, options.free_interior, p->interior, &p->builder);
  p->quaternion = calib::QuaternionFromOpk(opk_rad);
  p->rotation = p->builder.AddRotationBlock("instrument_from_camera", p->quaternion.data());
  std::vector<calib::BlockId> unused;
  p->method =
      internal::AddTargetBlocks(targets, &p->builder, &p->angles, &p->target_block, &unused);
  AddMappingBlocks(camera, &p->builder, &p->blocks);
  AddSubimageResiduals(camera,
                       observations,
                       p->target_block,
                       p->interior,
                       p->rotation,
                       &p->builder,
                       &p->blocks,
                       &p->apriori_sigma_px);
}

// The observations as the design camera (distortion-free) sees them exactly: each pixel replaced
// by the sub-image pixel of its target's (start) direction, so that the residuals are zero. At an
// exact fit a transformation the model undoes is an exact null direction of the normal matrix
// (elsewhere it changes the residuals in proportion to themselves: a scale scales them, a turn
// turns them, and the defect hides among eigenvalues of 1e-10).
std::vector<DirectionObservation> ExactObservations(
    const calib::Camera& design,
    const Eigen::Vector3d& opk_rad,
    const std::vector<DirectionTarget>& targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of) {
  std::map<std::string, Eigen::Vector2d> angles;
  for (const auto& t : targets) angles[t.id] = t.angles_rad;
  const Eigen::Matrix3d r = calib::RotationFromOpk(opk_rad);
  std::vector<DirectionObservation> out = observations;
  for (size_t i = 0; i < out.size(); ++i) {
    const auto a = angles.find(out[i].target);
    const int k = design.SubimageIndex(subimage_of[i]);
    if (a == angles.end() || k < 0) continue;  // named by the real problem
    Eigen::Vector3d t;
    calib::DirectionFromAngles(a->second.data(), t.data());
    const Eigen::Vector3d uvw = r.transpose() * out[i].instrument_rotation.transpose() * t;
    Eigen::Vector2d pixel;
    if (!(uvw.z() < 0) ||
        !design.PixelFromIdeal(
            Eigen::Vector2d(-design.c_mm() * uvw.x() / uvw.z(), -design.c_mm() * uvw.y() / uvw.z()),
            &pixel))
      continue;
    out[i].pixel = design.subimages[k].SubFromVirtual(pixel);
  }
  return out;
}

// The reference entries spanning the null space of `p` (column-pivoted QR of the null vectors'
// rows in the reference block): held in `p`; their indices.
std::vector<int> HoldSpanningEntries(const calib::NullSpaceReport& null_space, SubimageProblem* p) {
  std::vector<int> held;
  const SubimageBlock& reference = p->blocks.front();
  const auto it = null_space.scaled.find(reference.block);
  if (null_space.rank_defect == 0 || it == null_space.scaled.end()) return held;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(it->second.transpose());
  for (int j = 0; j < null_space.rank_defect && j < qr.rank(); ++j)
    held.push_back(qr.colsPermutation().indices()(j));
  std::sort(held.begin(), held.end());
  if (static_cast<int>(held.size()) == static_cast<int>(reference.conditioned.size()))
    p->builder.FixBlock(reference.block);
  else if (!held.empty())
    p->builder.FixEntries(reference.block, held);
  return held;
}

// The gauge of the header comment, derived on the design problem (the start with every radial,
// decentring and affinity term 0, the observations replaced by their exact images); returns it
// with the held entries' indices in the reference block.
SubimageDirectionGauge DeriveGauge(const calib::Camera& start,
                                   const Eigen::Vector3d& opk_rad,
                                   const std::vector<DirectionTarget>& targets,
                                   const std::vector<DirectionObservation>& observations,
                                   const std::vector<std::string>& subimage_of,
                                   std::string reference,
                                   const DirectionCalibrationOptions& options,
                                   std::vector<int>* held) {
  calib::Camera design = start;
  ZeroDistortion(&design);
  SubimageProblem p;
  BuildProblem(design,
               opk_rad,
               targets,
               ExactObservations(design, opk_rad, targets, observations, subimage_of),
               subimage_of,
               &reference,
               options,
               &p);
  SubimageDirectionGauge g;
  g.reference = reference;
  calib::SolverOptions setup;  // no step: Solve only sets up the manifolds
  setup.max_iterations = 0;
  p.builder.Solve(setup);
  const calib::NullSpaceReport without = p.builder.NullSpace(g.threshold);
  g.rank_defect = without.rank_defect;
  g.smallest_relative_eigenvalues = without.smallest_relative_eigenvalues;
  if (!without.ok) {
    g.message = "null space not computed: " + without.message;
    return g;
  }
  *held = HoldSpanningEntries(without, &p);
  const auto names =
      stitch::MappingParamNames(start.subimages[p.blocks.front().camera_index].model);
  for (int e : *held) g.held.push_back(names[e]);
  p.builder.Solve(setup);  // the held entries' manifold in place
  const calib::NullSpaceReport with = p.builder.NullSpace(g.threshold);
  g.rank_defect_with_gauge = with.rank_defect;
  g.smallest_relative_eigenvalues_with_gauge = with.smallest_relative_eigenvalues;
  g.ok = with.ok && with.rank_defect == 0;
  if (!g.ok)
    g.message = "the reference sub-image's mapping does not span the null space (rank defect " +
                std::to_string(with.rank_defect) + " with the gauge)";
  return g;
}

// The estimated mapping of a sub-image (plain), its sigmas (J C J^T of the conditioned
// covariance; none for held entries or without a covariance) and residuals.
SubimageDirectionMapping CollectMapping(const calib::Camera& start,
                                        const SubimageBlock& b,
                                        const calib::CovarianceReport& cov,
                                        const calib::ProblemBuilder& builder) {
  SubimageDirectionMapping out;
  out.mapping = start.subimages[b.camera_index];
  out.id = out.mapping.id;
  out.observations = static_cast<int>(b.observations.size());
  out.mapping.params = calib::PlainFromConditioned(out.mapping.model, b.cond, b.conditioned);
  const int n = static_cast<int>(b.conditioned.size());
  out.sigma.assign(n, std::nullopt);
  out.held.assign(n, builder.IsBlockFixed(b.block));
  if (!cov.ok) return out;
  const Eigen::MatrixXd c = cov.BlockCovariance(b.block, n);
  for (int e = 0; e < n; ++e) out.held[e] = out.held[e] || c(e, e) == 0.0;
  const Eigen::MatrixXd j =
      calib::PlainFromConditionedJacobian(out.mapping.model, b.cond, b.conditioned);
  const Eigen::MatrixXd plain = j * c * j.transpose();
  for (int e = 0; e < n; ++e)
    if (plain(e, e) > 0.0) out.sigma[e] = std::sqrt(plain(e, e));
  return out;
}

// After the solve: interior, R, residuals (sub-image px), targets, mappings.
void Collect(const calib::Camera& start,
             const std::vector<DirectionTarget>& targets,
             const std::deque<Eigen::Vector2d>& angles,
             const std::map<std::string, calib::BlockId>& target_block,
             calib::BlockId interior,
             calib::BlockId rotation,
             Eigen::Vector4d quaternion,
             const std::vector<SubimageBlock>& blocks,
             const calib::ProblemBuilder& builder,
             SubimageDirectionsCalibration* out) {
  DirectionCalibration& f = out->frame;
  std::vector<calib::BlockId> wanted = {interior, rotation};
  for (const auto& b : blocks) wanted.push_back(b.block);
  for (const auto& t : targets)
    if (!t.known) wanted.push_back(target_block.at(t.id));
  const calib::CovarianceReport cov = builder.EstimateCovariance(wanted, f.report.sigma0);
  f.covariance_ok = cov.ok;
  f.undetermined = cov.undetermined;
  f.high_correlations = cov.high_correlations;
  f.opk_rad = calib::OpkFromQuaternion(quaternion.normalized());
  const int n = f.camera.interior.size();
  f.interior_sigma.assign(n, 0.0);
  if (cov.ok) {
    f.interior_covariance = cov.BlockCovariance(interior, n);
    const Eigen::VectorXd s = cov.BlockSigma(interior, n);
    for (int i = 0; i < n; ++i) f.interior_sigma[i] = s[i];
    f.opk_sigma_rad = cov.BlockSigma(rotation, 3);
  }
  for (size_t t = 0; t < targets.size(); ++t) {
    if (targets[t].known) continue;
    f.target_angles_rad[targets[t].id] = angles[t];
    if (cov.ok)
      f.target_sigma_rad[targets[t].id] = cov.BlockSigma(target_block.at(targets[t].id), 2);
  }
  const double pixel_size_mm = start.pixel_size_mm;
  f.residual_px.assign(f.apriori_sigma_px.size(), Eigen::Vector2d::Zero());
  for (const SubimageBlock& b : blocks) {
    for (size_t i = 0; i < b.observations.size(); ++i) {
      const std::vector<double> r = builder.EvaluateResidual(b.residuals[i]);
      const Eigen::Vector2d v_mm = b.factors[i] * Eigen::Vector2d(r[0], r[1]);
      f.residual_px[b.observations[i]] = {v_mm.x() / pixel_size_mm, -v_mm.y() / pixel_size_mm};
    }
    out->subimages.push_back(CollectMapping(start, b, cov, builder));
    f.camera.subimages[b.camera_index] = out->subimages.back().mapping;
  }
}

}  // namespace

std::vector<DirectionObservation> VirtualObservations(
    const calib::Camera& start,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of_observation) {
  std::vector<DirectionObservation> out = observations;
  for (size_t i = 0; i < out.size() && i < subimage_of_observation.size(); ++i) {
    const int k = start.SubimageIndex(subimage_of_observation[i]);
    if (k >= 0) out[i].pixel = start.subimages[k].VirtualFromSub(observations[i].pixel);
  }
  return out;
}

SubimageDirectionsCalibration CalibrateSubimagesFromDirections(
    const calib::Camera& start,
    const Eigen::Vector3d& start_opk_rad,
    const std::vector<DirectionTarget>& targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of_observation,
    const std::string& reference,
    const DirectionCalibrationOptions& options) {
  SubimageDirectionsCalibration out;
  std::string reference_id = reference;
  SubimageProblem p;
  BuildProblem(start,
               start_opk_rad,
               targets,
               observations,
               subimage_of_observation,
               &reference_id,
               options,
               &p);
  std::vector<int> held;
  out.gauge = DeriveGauge(start,
                          start_opk_rad,
                          targets,
                          observations,
                          subimage_of_observation,
                          reference_id,
                          options,
                          &held);
  const SubimageBlock& ref = p.blocks.front();
  if (static_cast<int>(held.size()) == static_cast<int>(ref.conditioned.size()))
    p.builder.FixBlock(ref.block);
  else if (!held.empty())
    p.builder.FixEntries(ref.block, held);
  DirectionCalibration& f = out.frame;
  f.method = p.method;
  f.apriori_sigma_px = p.apriori_sigma_px;
  f.report = p.builder.Solve(options.solver);
  f.camera = p.camera;
  Collect(start,
          targets,
          p.angles,
          p.target_block,
          p.interior,
          p.rotation,
          p.quaternion,
          p.blocks,
          p.builder,
          &out);
  return out;
}

}  // namespace aerocal::triangulation
