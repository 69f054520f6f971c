// The rig-head camera: a sensor kind (imaging_model.h) for the heads of a multi-head rig
// (CONVENTIONS.md "Multi-head rigs", FORMATS.md "Multi-head rig"), and the rig bundle adjustment
// built on it (AdjustRig).
//
// Observations are head pixels (col, row) of head k in one rig exposure (observations.csv `head`
// column). The exposure's pose is the platform's (the rig's virtual centre O and attitude R,
// PoseBlocks); head k sees the object through
//   R_k = R M_k E_k,   O_k = O + R t_k + v dT_k
// (calib/camera/rig.h HeadPose) and obeys the one collinearity of aerocal with its own interior in
// its own registered model (calib::MakeRigHeadCollinearityResidual, group kGroupImage; the heads
// of one rig may differ in model).
//
// Blocks the kind owns, per head k (entries in table units, rad, m, s):
//   "camera ID"                    interior of the REFERENCE head: the frame camera's block of
//                                  the rig's camera id (Project::cameras holds the reference head)
//   "rig ID head K interior"       interior of every other head (free entries:
//                                  AdjustOptions::free_interior, as the frame camera)
//   "rig ID head K mount"          M_k omega, phi, kappa (rad)
//   "rig ID head K lever arm"      t_k tx, ty, tz in the rig frame (m)
//   "rig ID head K time offset"    dT_k (s), one per head for the flight
//   "rig ID image I head K increment"  E_k domega, dphi, dkappa (rad), per exposure and head
// Datum of the rig: the reference head's mount, lever arm, increments and time offset are fixed
// (at the file's values, E = 0, dT = 0); the other heads are relative to it. Each group of the
// other heads' parameters is fixed, free or weighted (RigAdjustOptions): weighted mounts and lever
// arms use the rig file's a-priori sigmas around the file's values, weighted increments and time
// offsets a sigma around zero (group rig_prior, calib/problem/mounted_block.h).
//
// Determinability: AdjustRig estimates the covariance of the rig's blocks with every exposure's
// pose and names each rig parameter whose strongest correlation exceeds the threshold (a lever arm
// seen from a high flight is barely separable from the mount angles: said with the correlation,
// never a fake sigma); a rank defect (e.g. free increments of every exposure with a free mount)
// makes the result not valid (exit 3 in the CLI).
#pragma once

#include "calib/camera/rig.h"
#include "calib/problem/mounted_block.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/sensor/imaging_model.h"

#include <nlohmann/json.hpp>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

/// Owner of the rig's mounted blocks: their priors are in group calib::PriorGroup(kRigOwner),
/// "rig_prior" (calib/problem/mounted_block.h).
inline constexpr const char* kRigOwner = "rig";

/// What the rig bundle estimates besides the block (which parameters; the data is the rig file).
struct RigAdjustOptions {
  calib::BlockMode mounts = calib::BlockMode::kFree;       // M_k of the non-reference heads;
                                                           // weighted: the file's mount_sigma_deg
  calib::BlockMode lever_arms = calib::BlockMode::kFree;   // t_k; weighted: lever_arm_sigma_m
  calib::BlockMode increments = calib::BlockMode::kFixed;  // E_k per exposure and head (= 0 fixed)
  double increment_sigma_rad = 0.0;  // weighted increments: sigma of each angle around 0, rad > 0
  calib::BlockMode time_offsets = calib::BlockMode::kFixed;  // dT_k per head (= 0 fixed); free or
                                                             // weighted needs the velocity columns
  double time_offset_sigma_s = 0.0;  // weighted time offsets: sigma around 0, s > 0
  /// ConfigError naming the option: a weighted mode without its sigma, a sigma <= 0.
  void Validate() const;
};

/// One head after the rig bundle. Sigmas are null (nullopt) when the covariance is not known,
/// 0 for a fixed parameter.
struct RigHeadEstimate {
  std::string id;
  bool reference = false;
  calib::CameraModelId model = calib::CameraModelId::kBrownFraser10;  // the head's camera model
  calib::InteriorParams interior{};        // in the head's model, table order and units
  calib::InteriorSigmas interior_sigma{};  // the same size
  Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero(), lever_arm_m = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> mount_sigma_rad, lever_arm_sigma_m;
  double time_offset_s = 0.0;
  std::optional<double> time_offset_sigma_s;
};

/// The attitude increment and time offset of one non-reference head in one exposure.
struct RigExposureEstimate {
  std::string image, head;
  Eigen::Vector3d increment_rad = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> increment_sigma_rad;
  double time_offset_s = 0.0;
  std::optional<double> time_offset_sigma_s;
};

struct RigAdjustmentResult {
  AdjustmentResult adjustment;  // the block: exposures are the rig's virtual poses
  std::string camera;           // the rig's camera id in the project
  std::string reference_head;
  RigAdjustOptions options;
  std::vector<RigHeadEstimate> heads;          // rig file order
  std::vector<RigExposureEstimate> exposures;  // non-reference heads, exposures in file order
  Determinability determinability;             // of the rig's parameters ("rig ..." names)
};

class RigHeadCamera final : public ImagingModel {
 public:
  explicit RigHeadCamera(const RigAdjustOptions& options);
  /// Head pixels (col, row).
  SensorKind Kind() const override { return SensorKind::kRigHead; }
  /// The project's one rig: heads' interiors (reference head: the frame camera's block), mounts,
  /// lever arms, time offsets, increments. ConfigError when the project has no rig or several,
  /// or a weighted mount / lever arm without the file's sigmas, or free / weighted time offsets
  /// without the exposures' velocity.
  void RegisterBlocks(const SensorContext& context) override;
  ImageRay StartingRay(const SensorContext& context,
                       const ImageObservation& observation) const override;
  /// Group kGroupImage; blocks interior, rotation, centre, mount, lever arm, increment, time
  /// offset, point (calib::MakeRigHeadCollinearityResidual in the head's model).
  ObservationTerm Observe(const SensorContext& context,
                          const ImageObservation& observation,
                          calib::BlockId point) override;
  /// Priors of weighted rig parameters (group rig_prior) and the non-reference heads' interior
  /// sigmas (kGroupInteriorPrior, with AdjustOptions::use_interior_sigma).
  void AddOwnResiduals(const SensorContext& context) override;
  /// "image 0012 head left point T442".
  std::string Describe(const ImageObservation& observation) const override;
  /// The head.
  void Annotate(const ImageObservation& observation, ObservationResidual* residual) const override;
  void Annotate(const ImageObservation& observation, RejectedObservation* rejected) const override;

  /// The rig's blocks whose covariance AdjustRig reports (fixed ones included).
  std::vector<calib::BlockId> Blocks() const;
  /// The current values with their sigmas from `covariance` (not ok: sigmas null).
  void Collect(const SensorContext& context,
               const calib::CovarianceReport& covariance,
               RigAdjustmentResult* result) const;

 private:
  struct Head {
    calib::InteriorParams interior{};  // non-reference heads (the reference's is the frame's)
    Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero(), lever_arm_m = Eigen::Vector3d::Zero();
    double time_offset_s = 0.0;
    calib::BlockId interior_block = -1, mount_block = -1, lever_arm_block = -1,
                   time_offset_block = -1;
  };
  struct Increment {
    Eigen::Vector3d rad = Eigen::Vector3d::Zero();
    calib::BlockId block = -1;
  };
  /// The head's current pose in one exposure at the starting values (object_from_head, centre).
  std::pair<Eigen::Matrix3d, Eigen::Vector3d> StartingHeadPose(const SensorContext& context,
                                                               const ObservationSite& site,
                                                               int head) const;
  calib::BlockId IncrementBlock(ExposureIndex exposure, int head) const;
  // RegisterBlocks' steps: one head's interior, mount, lever arm and time offset; the fixed zero
  // increment and time offset of the reference head; the per-exposure increments.
  void RegisterHead(const SensorContext& context, int k);
  void RegisterZeroBlocks(calib::ProblemBuilder& builder);
  void RegisterIncrements(const SensorContext& context);

  RigAdjustOptions options_;
  std::string camera_;  // the rig's camera id
  const calib::Rig* rig_ = nullptr;
  int reference_ = -1;
  std::vector<Head> heads_;  // sized once: the builder holds their addresses
  std::map<std::pair<ExposureIndex, int>, Increment> increments_;  // stable addresses
  Eigen::Vector3d zero_increment_ = Eigen::Vector3d::Zero();       // fixed: E = I
  double zero_time_offset_ = 0.0;                                  // fixed: dT = 0
  calib::BlockId zero_increment_block_ = -1, zero_time_offset_block_ = -1;
};

/// The rig bundle adjustment: the block adjustment (block_adjustment.h) with the rig-head camera,
/// then the covariance and determinability of the rig's parameters. Invalid (AdjustmentResult::
/// Invalidate) when a rig parameter is not determinable or its covariance cannot be computed.
RigAdjustmentResult AdjustRig(const Project& project,
                              const AdjustOptions& options,
                              const RigAdjustOptions& rig_options);

/// JSON of the rig part (FORMATS.md "Multi-head rig"): {"rig": {camera, reference_head, options,
/// heads: [...], determinability}, "rig_exposures": [...]}, degrees, metres, ms; merged into the
/// adjustment's JSON by the caller.
nlohmann::json RigResultToJson(const RigAdjustmentResult& result);

/// Text lines of the rig part for the terminal: each non-reference head's mount, lever arm (and
/// time offset) with sigmas, then the determinability warnings.
std::string FormatRigSummary(const RigAdjustmentResult& result);

/// The rig file for the next flight: `rig` with the estimated interiors, mounts and lever arms;
/// the estimated sigmas of free or weighted mounts and lever arms become their a-priori sigmas.
calib::Rig UpdatedRig(const calib::Rig& rig, const RigAdjustmentResult& result);

}  // namespace aerocal::triangulation
