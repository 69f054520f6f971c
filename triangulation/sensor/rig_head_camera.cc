#include "triangulation/sensor/rig_head_camera.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/residuals/collinearity.h"
#include "calib/residuals/prior.h"
#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/adjustment/determinability.h"
#include "triangulation/sensor/frame_camera.h"

#include <algorithm>
#include <cmath>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;

constexpr double kDegPerRad = 180.0 / M_PI;

const std::vector<std::string> kMountNames = {"omega", "phi", "kappa"};
const std::vector<std::string> kLeverArmNames = {"tx", "ty", "tz"};
const std::vector<std::string> kIncrementNames = {"domega", "dphi", "dkappa"};

// The one place that knows how the platform's rotation block is parameterised (omega, phi, kappa,
// calib/camera/rotation.h): the head's residual on the exposure's rotation block, and the
// exposure's starting rotation. A rotation manifold changes these two functions only.
std::unique_ptr<ceres::CostFunction> HeadCost(const calib::Camera& head,
                                              const ImageObservation& observation,
                                              const Eigen::Vector3d& velocity_mps) {
  return calib::MakeRigHeadCollinearityResidual(
      head.model, head.frame(), observation.pixel, observation.sigma_px, velocity_mps);
}
Eigen::Matrix3d ObjectFromRig(const Exposure& exposure) {
  return calib::RotationFromOpk(exposure.opk_rad);
}

Eigen::Vector3d VelocityOf(const Exposure& exposure) {
  return exposure.velocity_mps ? *exposure.velocity_mps : Eigen::Vector3d::Zero();
}

}  // namespace

void RigAdjustOptions::Validate() const {
  if (increments == calib::BlockMode::kWeighted && !(increment_sigma_rad > 0.0))
    throw ConfigError(
        "weighted rig increments need a sigma > 0 (--rig-increment-sigma-arcsec, "
        "got " +
        FormatNumber(increment_sigma_rad * kDegPerRad * 3600.0) + ")");
  if (time_offsets == calib::BlockMode::kWeighted && !(time_offset_sigma_s > 0.0))
    throw ConfigError(
        "weighted rig time offsets need a sigma > 0 (--rig-time-offset-sigma-ms, "
        "got " +
        FormatNumber(time_offset_sigma_s * 1e3) + ")");
}

RigHeadCamera::RigHeadCamera(const RigAdjustOptions& options) : options_(options) {
  options_.Validate();
}

std::string RigHeadCamera::Describe(const ImageObservation& observation) const {
  return "image " + observation.image + " head " + observation.head + " point " + observation.point;
}

void RigHeadCamera::Annotate(const ImageObservation& observation,
                             ObservationResidual* residual) const {
  residual->head = observation.head;
}

void RigHeadCamera::Annotate(const ImageObservation& observation,
                             RejectedObservation* rejected) const {
  rejected->head = observation.head;
}

void RigHeadCamera::RegisterBlocks(const SensorContext& context) {
  const Project& project = context.project;
  if (project.rigs.size() != 1)
    throw ConfigError(project.path + ": the rig bundle takes a project with one rig camera (got " +
                      std::to_string(project.rigs.size()) + ")");
  camera_ = project.rigs.begin()->first;
  rig_ = &project.rigs.begin()->second;
  reference_ = rig_->ReferenceIndex();
  const int n = static_cast<int>(rig_->heads.size());
  heads_.assign(n, Head{});
  for (int k = 0; k < n; ++k) RegisterHead(context, k);
  RegisterZeroBlocks(context.builder);
  RegisterIncrements(context);
}

void RigHeadCamera::RegisterHead(const SensorContext& context, int k) {
  calib::ProblemBuilder& builder = context.builder;
  const calib::RigHead& head = rig_->heads[k];
  Head& h = heads_[k];
  h.mount_rad = head.mount_rad;
  h.lever_arm_m = head.lever_arm_m;
  const std::string name = "rig " + camera_ + " head " + head.id;
  if (k == reference_) {
    h.interior_block = context.frame.InteriorBlock(context.index.Camera(camera_));
  } else {
    // Free interior entries as the frame camera's, named by the head's own model.
    const InteriorLayout layout =
        InteriorLayoutOf(head.camera, context.options.free_interior, name);
    h.interior = head.camera.interior;
    h.interior_block = builder.AddBlock(name + " interior",
                                        h.interior.data(),
                                        h.interior.size(),
                                        calib::BlockKind::kInterior,
                                        layout.names);
    builder.FixEntries(h.interior_block, layout.fixed);
  }
  h.mount_block = builder.AddBlock(
      name + " mount", h.mount_rad.data(), 3, calib::BlockKind::kOther, kMountNames);
  h.lever_arm_block = builder.AddBlock(
      name + " lever arm", h.lever_arm_m.data(), 3, calib::BlockKind::kOther, kLeverArmNames);
  if (k == reference_) {
    builder.FixBlock(h.mount_block);  // the rig's datum: the reference head
    builder.FixBlock(h.lever_arm_block);
    return;
  }
  calib::ApplyBlockMode(builder, h.mount_block, options_.mounts);
  calib::ApplyBlockMode(builder, h.lever_arm_block, options_.lever_arms);
  const auto weighted_needs = [&](bool has, const char* what, const char* key) {
    if (!has)
      throw ConfigError(context.project.camera_files.at(camera_) + ": head " + head.id + ": " +
                        what + " weighted needs the head's " + key);
  };
  if (options_.mounts == calib::BlockMode::kWeighted)
    weighted_needs(head.mount_sigma_rad.has_value(), "--rig-mounts", "mount_sigma_deg");
  if (options_.lever_arms == calib::BlockMode::kWeighted)
    weighted_needs(head.lever_arm_sigma_m.has_value(), "--rig-lever-arms", "lever_arm_sigma_m");
  if (options_.time_offsets != calib::BlockMode::kFixed)
    h.time_offset_block = builder.AddBlock(
        name + " time offset", &h.time_offset_s, 1, calib::BlockKind::kOther, {"dT"});
}

void RigHeadCamera::RegisterZeroBlocks(calib::ProblemBuilder& builder) {
  zero_increment_block_ = builder.AddBlock("rig " + camera_ + " zero increment",
                                           zero_increment_.data(),
                                           3,
                                           calib::BlockKind::kOther,
                                           kIncrementNames);
  builder.FixBlock(zero_increment_block_);
  zero_time_offset_block_ = builder.AddBlock("rig " + camera_ + " zero time offset",
                                             &zero_time_offset_,
                                             1,
                                             calib::BlockKind::kOther,
                                             {"dT"});
  builder.FixBlock(zero_time_offset_block_);
}

// Exposures of the rig: per-head increments; velocity where the time offsets are estimated.
void RigHeadCamera::RegisterIncrements(const SensorContext& context) {
  const Project& project = context.project;
  const int n = static_cast<int>(rig_->heads.size());
  for (ExposureIndex e = 0; e < context.index.NumExposures(); ++e) {
    const Exposure& exposure = project.exposures[e];
    if (exposure.camera != camera_) continue;
    if (options_.time_offsets != calib::BlockMode::kFixed && n > 1 && !exposure.velocity_mps)
      ThrowInputError({project.exposures_file, exposure.line},
                      "image " + exposure.image +
                          ": estimating rig time offsets needs the platform velocity (columns "
                          "vX,vY,vZ)");
    if (options_.increments == calib::BlockMode::kFixed) continue;
    for (int k = 0; k < n; ++k) {
      if (k == reference_) continue;
      Increment& increment = increments_[{e, k}];
      increment.block = context.builder.AddBlock("rig " + camera_ + " image " + exposure.image +
                                                     " head " + rig_->heads[k].id + " increment",
                                                 increment.rad.data(),
                                                 3,
                                                 calib::BlockKind::kOther,
                                                 kIncrementNames);
    }
  }
}

BlockId RigHeadCamera::IncrementBlock(ExposureIndex exposure, int head) const {
  const auto it = increments_.find({exposure, head});
  return it == increments_.end() ? zero_increment_block_ : it->second.block;
}

std::pair<Eigen::Matrix3d, Eigen::Vector3d> RigHeadCamera::StartingHeadPose(
    const SensorContext& context, const ObservationSite& site, int head) const {
  (void)context;
  const Head& h = heads_[head];
  const auto increment = increments_.find({site.index, head});
  const Eigen::Vector3d e =
      increment == increments_.end() ? Eigen::Vector3d::Zero() : increment->second.rad;
  const Eigen::Matrix3d r = ObjectFromRig(*site.exposure);
  const Eigen::Matrix3d object_from_head =
      r * calib::RotationFromOpk(h.mount_rad) * calib::RotationFromOpk(e);
  const Eigen::Vector3d center =
      site.exposure->center_m + r * h.lever_arm_m + VelocityOf(*site.exposure) * h.time_offset_s;
  return {object_from_head, center};
}

ImageRay RigHeadCamera::StartingRay(const SensorContext& context,
                                    const ImageObservation& observation) const {
  const ObservationSite site = context.Site(observation);
  const int k = rig_->HeadIndex(observation.head);
  const auto [object_from_head, center] = StartingHeadPose(context, site, k);
  return RayFromPixel(
      rig_->heads[k].camera, calib::OpkFromRotation(object_from_head), center, observation.pixel);
}

ObservationTerm RigHeadCamera::Observe(const SensorContext& context,
                                       const ImageObservation& observation,
                                       BlockId point) {
  const ObservationSite site = context.Site(observation);
  const int k = rig_->HeadIndex(observation.head);
  const Head& h = heads_[k];
  ObservationTerm term;
  term.group = calib::kGroupImage;
  term.cost = HeadCost(rig_->heads[k].camera, observation, VelocityOf(*site.exposure));
  term.blocks = {h.interior_block,
                 site.pose.rotation,
                 site.pose.center,
                 h.mount_block,
                 h.lever_arm_block,
                 IncrementBlock(site.index, k),
                 h.time_offset_block >= 0 ? h.time_offset_block : zero_time_offset_block_,
                 point};
  return term;
}

void RigHeadCamera::AddOwnResiduals(const SensorContext& context) {
  calib::ProblemBuilder& builder = context.builder;
  // A weighted rig block around `value` (calib/problem/mounted_block.h, group rig_prior).
  const auto prior3 = [&](BlockId block,
                          calib::BlockMode mode,
                          const Eigen::Vector3d& value,
                          const Eigen::Vector3d& sigma,
                          const std::string& label) {
    calib::AddBlockPrior(builder,
                         block,
                         mode,
                         {value.x(), value.y(), value.z()},
                         {sigma.x(), sigma.y(), sigma.z()},
                         kRigOwner,
                         label);
  };
  for (int k = 0; k < static_cast<int>(heads_.size()); ++k) {
    if (k == reference_) continue;
    const calib::RigHead& head = rig_->heads[k];
    const Head& h = heads_[k];
    const std::string name = "rig prior head " + head.id;
    if (options_.mounts == calib::BlockMode::kWeighted)
      prior3(
          h.mount_block, options_.mounts, head.mount_rad, *head.mount_sigma_rad, name + " mount");
    if (options_.lever_arms == calib::BlockMode::kWeighted)
      prior3(h.lever_arm_block,
             options_.lever_arms,
             head.lever_arm_m,
             *head.lever_arm_sigma_m,
             name + " lever arm");
    calib::AddBlockPrior(builder,
                         h.time_offset_block,
                         options_.time_offsets,
                         {0.0},
                         {options_.time_offset_sigma_s},
                         kRigOwner,
                         name + " time offset");
    if (!context.options.use_interior_sigma) continue;
    if (auto prior = InteriorPriorOf(head.camera, context.options.free_interior))
      builder.AddResidual(calib::kGroupInteriorPrior,
                          std::move(prior),
                          {h.interior_block},
                          "interior prior " + camera_ + " head " + head.id);
  }
  if (options_.increments == calib::BlockMode::kWeighted) {
    const double s = options_.increment_sigma_rad;
    for (const auto& [key, increment] : increments_)
      prior3(increment.block,
             options_.increments,
             Eigen::Vector3d::Zero(),
             Eigen::Vector3d::Constant(s),
             "rig prior image " + context.project.exposures[key.first].image + " head " +
                 rig_->heads[key.second].id + " increment");
  }
}

std::vector<BlockId> RigHeadCamera::Blocks() const {
  std::vector<BlockId> blocks;
  for (const Head& h : heads_) {
    blocks.push_back(h.interior_block);
    blocks.push_back(h.mount_block);
    blocks.push_back(h.lever_arm_block);
    if (h.time_offset_block >= 0) blocks.push_back(h.time_offset_block);
  }
  for (const auto& [key, increment] : increments_) blocks.push_back(increment.block);
  return blocks;
}

void RigHeadCamera::Collect(const SensorContext& context,
                            const calib::CovarianceReport& cov,
                            RigAdjustmentResult* result) const {
  result->camera = camera_;
  result->reference_head = rig_->reference_head;
  result->options = options_;
  const auto sigma3 = [&](BlockId block) -> std::optional<Eigen::Vector3d> {
    if (!cov.ok) return std::nullopt;
    return Eigen::Vector3d(cov.BlockSigma(block, 3));
  };
  for (int k = 0; k < static_cast<int>(heads_.size()); ++k) {
    const Head& h = heads_[k];
    RigHeadEstimate e;
    e.id = rig_->heads[k].id;
    e.reference = k == reference_;
    e.interior = e.reference ? context.frame.Interior(context.index.Camera(camera_)) : h.interior;
    e.model = rig_->heads[k].camera.model;
    e.interior_sigma = calib::InteriorSigmas::ForModel(e.model);
    if (cov.ok) {
      const Eigen::VectorXd s = cov.BlockSigma(h.interior_block, e.interior.size());
      for (int i = 0; i < e.interior.size(); ++i) e.interior_sigma[i] = s(i);
    }
    e.mount_rad = h.mount_rad;
    e.lever_arm_m = h.lever_arm_m;
    e.mount_sigma_rad = sigma3(h.mount_block);
    e.lever_arm_sigma_m = sigma3(h.lever_arm_block);
    e.time_offset_s = h.time_offset_s;
    if (h.time_offset_block < 0)
      e.time_offset_sigma_s = 0.0;
    else if (cov.ok)
      e.time_offset_sigma_s = cov.BlockSigma(h.time_offset_block, 1)(0);
    result->heads.push_back(e);
  }
  for (ExposureIndex x = 0; x < context.index.NumExposures(); ++x) {
    const Exposure& exposure = context.project.exposures[x];
    if (exposure.camera != camera_) continue;
    for (int k = 0; k < static_cast<int>(heads_.size()); ++k) {
      if (k == reference_) continue;
      RigExposureEstimate e;
      e.image = exposure.image;
      e.head = rig_->heads[k].id;
      const auto it = increments_.find({x, k});
      if (it == increments_.end()) {
        e.increment_sigma_rad = Eigen::Vector3d::Zero();
      } else {
        e.increment_rad = it->second.rad;
        e.increment_sigma_rad = sigma3(it->second.block);
      }
      e.time_offset_s = result->heads[k].time_offset_s;
      e.time_offset_sigma_s = result->heads[k].time_offset_sigma_s;
      result->exposures.push_back(e);
    }
  }
}

RigAdjustmentResult AdjustRig(const Project& project,
                              const AdjustOptions& options,
                              const RigAdjustOptions& rig_options) {
  auto sensor = std::make_unique<RigHeadCamera>(rig_options);
  const RigHeadCamera* rig = sensor.get();
  std::vector<std::unique_ptr<ImagingModel>> sensors;
  sensors.push_back(std::move(sensor));
  BlockAdjustment adjustment(project, options, std::move(sensors));
  RigAdjustmentResult result;
  result.adjustment = adjustment.Run();

  // Covariance of the rig's parameters with each other and with every exposure's pose.
  const SensorContext& context = adjustment.context();
  const std::vector<BlockId> rig_blocks = rig->Blocks();
  std::vector<BlockId> blocks = rig_blocks;
  for (const PoseBlocks& pose : context.poses) {
    blocks.push_back(pose.rotation);
    blocks.push_back(pose.center);
  }
  calib::CovarianceReport cov;
  const AdjustmentResult& a = result.adjustment;
  if (!options.estimate_covariance)
    cov.message = "covariance not estimated (option)";
  else if (a.solve.usable && a.solve.redundancy > 0)
    cov = adjustment.builder().EstimateCovariance(
        blocks, a.sigma0, options.correlation_threshold, rig_blocks);
  else
    cov.message = "no covariance: the adjustment has no usable solution or no redundancy";
  result.determinability = AssessDeterminability(cov, "rig ", options.correlation_threshold);
  rig->Collect(context, cov, &result);
  const auto& reasons = result.adjustment.invalid_reasons;
  const bool said = std::any_of(reasons.begin(), reasons.end(), [&](const std::string& reason) {
    return reason.find(cov.message) != std::string::npos;
  });
  if (options.estimate_covariance && !cov.ok && !said)  // not twice when the block's failed too
    result.adjustment.Invalidate("rig: no covariance of the rig parameters: " + cov.message);
  else if (!result.determinability.undetermined.empty())
    result.adjustment.Invalidate(
        "rig: " + std::to_string(result.determinability.undetermined.size()) +
        " rig parameter(s) not determinable (" + result.determinability.undetermined.front() +
        ", ...)");
  return result;
}

std::string FormatRigSummary(const RigAdjustmentResult& r) {
  std::string out = "rig " + r.camera + " (reference head " + r.reference_head + ")\n";
  const auto value_sigma = [](double value, const std::optional<double>& sigma, int digits) {
    return FormatNumber(value, digits) + " +- " + (sigma ? FormatNumber(*sigma, 2) : "?");
  };
  for (const RigHeadEstimate& h : r.heads) {
    if (h.reference) continue;
    out += "  head " + h.id + " mount (deg):";
    for (int i = 0; i < 3; ++i)
      out += " " + value_sigma(h.mount_rad(i) * kDegPerRad,
                               h.mount_sigma_rad
                                   ? std::optional<double>((*h.mount_sigma_rad)(i)*kDegPerRad)
                                   : std::nullopt,
                               8);
    out += "\n  head " + h.id + " lever arm (m):";
    for (int i = 0; i < 3; ++i)
      out +=
          " " + value_sigma(h.lever_arm_m(i),
                            h.lever_arm_sigma_m ? std::optional<double>((*h.lever_arm_sigma_m)(i))
                                                : std::nullopt,
                            6);
    out += "\n";
    if (r.options.time_offsets != calib::BlockMode::kFixed)
      out += "  head " + h.id + " dT (ms): " +
             value_sigma(h.time_offset_s * 1e3,
                         h.time_offset_sigma_s ? std::optional<double>(*h.time_offset_sigma_s * 1e3)
                                               : std::nullopt,
                         6) +
             "\n";
  }
  // Without a covariance the block's summary has said why already.
  if (r.determinability.covariance_ok)
    for (const auto& w : r.determinability.warnings) out += "warning: " + w + "\n";
  return out;
}

calib::Rig UpdatedRig(const calib::Rig& rig, const RigAdjustmentResult& result) {
  calib::Rig out = rig;
  for (const RigHeadEstimate& e : result.heads) {
    calib::RigHead& head = out.heads[out.HeadIndex(e.id)];
    head.camera.interior = e.interior;
    head.mount_rad = e.mount_rad;
    head.lever_arm_m = e.lever_arm_m;
    if (e.reference) continue;
    if (result.options.mounts != calib::BlockMode::kFixed && e.mount_sigma_rad)
      head.mount_sigma_rad = e.mount_sigma_rad;
    if (result.options.lever_arms != calib::BlockMode::kFixed && e.lever_arm_sigma_m)
      head.lever_arm_sigma_m = e.lever_arm_sigma_m;
  }
  return out;
}

}  // namespace aerocal::triangulation
