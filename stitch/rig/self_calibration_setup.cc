// Set-up of the self-calibrating rig stitching (self_calibration_problem.h): the held blocks, the
// increments and time offsets by mode with their priors, the ties and their standard positions.
#include "calib/camera/rotation.h"
#include "calib/problem/mounted_block.h"
#include "calib/residuals/collinearity.h"
#include "stitch/rig/self_calibration_problem.h"

#include <optional>

namespace aerocal::stitch::internal {

const std::vector<std::string> kIncrementAngleNames = {"domega", "dphi", "dkappa"};

RectificationPlane LevelPlane(double z_ref_m) { return {Eigen::Vector3d::UnitZ(), z_ref_m}; }

RigStitchProblem::RigStitchProblem(const calib::Rig& rig_in,
                                   const std::vector<RigStitchExposure>& exposures_in,
                                   const std::vector<RigStitchTie>& ties_in,
                                   const std::vector<RigStitchObservation>& observations_in,
                                   const std::vector<StandardPosition>& positions_in,
                                   const RigStitchOptions& options_in)
    : rig(rig_in),
      exposures(exposures_in),
      ties(ties_in),
      observations(observations_in),
      positions(positions_in),
      options(options_in),
      n_heads(static_cast<int>(rig_in.heads.size())),
      n_exposures(static_cast<int>(exposures_in.size())),
      reference(rig_in.ReferenceIndex()),
      heads(rig_in.heads),
      interior(n_heads),
      mount(n_heads),
      lever(n_heads),
      rig_opk(n_exposures),
      rig_center(n_exposures),
      increment(n_exposures, std::vector<calib::BlockId>(n_heads, -1)),
      dt(n_exposures, std::vector<calib::BlockId>(n_heads, -1)),
      line_dt(n_heads, -1),
      poses(n_exposures),
      rig_quaternion(n_exposures) {
  for (int o = 0; o < static_cast<int>(observations.size()); ++o)
    tie_observations[{observations[o].exposure, observations[o].tie}].push_back(o);
}

void AddHeadBlocks(RigStitchProblem& p) {
  auto& builder = p.builder;
  for (int k = 0; k < p.n_heads; ++k) {
    const std::string& id = p.heads[k].id;
    p.interior[k] = builder.AddBlock("interior[" + id + "]",
                                     p.heads[k].camera.interior.data(),
                                     p.heads[k].camera.interior.size(),
                                     calib::BlockKind::kInterior);
    p.mount[k] = builder.AddBlock(
        "mount[" + id + "]", p.heads[k].mount_rad.data(), 3, calib::BlockKind::kOther);
    p.lever[k] = builder.AddBlock(
        "lever_arm[" + id + "]", p.heads[k].lever_arm_m.data(), 3, calib::BlockKind::kOther);
    for (calib::BlockId b : {p.interior[k], p.mount[k], p.lever[k]}) builder.FixBlock(b);
  }
  p.zero_increment = builder.AddBlock("E[reference]",
                                      p.vectors.emplace_back(Eigen::Vector3d::Zero()).data(),
                                      3,
                                      calib::BlockKind::kOther);
  p.zero_dt =
      builder.AddBlock("dT[reference]", &p.scalars.emplace_back(0.0), 1, calib::BlockKind::kOther);
  builder.FixBlock(p.zero_increment);
  builder.FixBlock(p.zero_dt);
}

void DecideTimeOffsets(RigStitchProblem& p) {
  bool any_velocity = false;
  for (const auto& e : p.exposures) any_velocity |= e.pose.velocity_mps.norm() > 1e-9;
  const RigStitchMode mode = p.options.mode;
  p.result.dt_held = mode == RigStitchMode::kAngles || !any_velocity || p.options.hold_heads;
  if (!any_velocity && mode != RigStitchMode::kAngles)
    p.result.warnings.push_back(
        {"no_platform_velocity",
         "time offsets",
         NAN,
         NAN,
         "no platform velocity in the exposures: the time offsets move no head and are held at 0"});
}

namespace {

// The increment and time offset of a non-reference head at exposure i; weighted around zero
// (calib/problem/mounted_block.h, group rig_stitch_prior) where sigmas are given. A held
// increment keeps its prior, as it always has (it counts in the redundancy); a line-mode dT has
// its prior once (at the first exposure).
void AddHeadIncrement(RigStitchProblem& p, int i, int k) {
  auto& builder = p.builder;
  const auto& options = p.options;
  const std::string name = p.exposures[i].image + "/" + p.heads[k].id;
  p.increment[i][k] = builder.AddBlock("E[" + name + "]",
                                       p.vectors.emplace_back(Eigen::Vector3d::Zero()).data(),
                                       3,
                                       calib::BlockKind::kOther,
                                       kIncrementAngleNames);
  if (options.hold_heads) builder.FixBlock(p.increment[i][k]);
  if (options.mode == RigStitchMode::kLine) {
    p.dt[i][k] = p.line_dt[k];
  } else {
    p.dt[i][k] = builder.AddBlock(
        "dT[" + name + "]", &p.scalars.emplace_back(0.0), 1, calib::BlockKind::kOther, {"dT"});
    if (p.result.dt_held) builder.FixBlock(p.dt[i][k]);
  }
  if (options.increment_sigma_rad) {
    const double s = *options.increment_sigma_rad;
    calib::AddBlockPrior(builder,
                         p.increment[i][k],
                         calib::BlockMode::kWeighted,
                         {0, 0, 0},
                         {s, s, s},
                         kRigStitchOwner,
                         "prior E[" + name + "]");
  }
  if (options.dt_sigma_s && !p.result.dt_held &&
      (options.mode == RigStitchMode::kPerExposure || i == 0))
    calib::AddBlockPrior(builder,
                         p.dt[i][k],
                         calib::BlockMode::kWeighted,
                         {0},
                         {*options.dt_sigma_s},
                         kRigStitchOwner,
                         "prior " + builder.BlockName(p.dt[i][k]));
}

// The exposure's POS (held): its attitude as the quaternion block the head residual takes.
void AddExposurePose(RigStitchProblem& p, int i) {
  auto& builder = p.builder;
  const std::string& image = p.exposures[i].image;
  p.poses[i] = p.exposures[i].pose;
  p.poses[i].increment_rad.assign(p.n_heads, Eigen::Vector3d::Zero());
  p.poses[i].dt_s.assign(p.n_heads, 0.0);
  p.rig_quaternion[i] = calib::QuaternionFromOpk(p.poses[i].rig_opk_rad);
  p.rig_opk[i] = builder.AddRotationBlock("rig_opk[" + image + "]", p.rig_quaternion[i].data());
  p.rig_center[i] = builder.AddBlock(
      "rig_center[" + image + "]", p.poses[i].rig_center_m.data(), 3, calib::BlockKind::kOther);
  builder.FixBlock(p.rig_opk[i]);
  builder.FixBlock(p.rig_center[i]);
}

}  // namespace

void AddExposureBlocks(RigStitchProblem& p) {
  for (int k = 0; k < p.n_heads; ++k) {
    if (k == p.reference || p.options.mode != RigStitchMode::kLine) continue;
    p.line_dt[k] = p.builder.AddBlock("dT[" + p.heads[k].id + "]",
                                      &p.scalars.emplace_back(0.0),
                                      1,
                                      calib::BlockKind::kOther,
                                      {"dT"});
    if (p.result.dt_held) p.builder.FixBlock(p.line_dt[k]);
  }
  for (int i = 0; i < p.n_exposures; ++i) {
    AddExposurePose(p, i);
    for (int k = 0; k < p.n_heads; ++k) {
      if (k != p.reference) {
        AddHeadIncrement(p, i, k);
        continue;
      }
      p.increment[i][k] = p.zero_increment;
      p.dt[i][k] = p.zero_dt;
    }
  }
}

namespace {

// Where a tie starts and where it lies in the virtual image at the ground calibration.
struct TieStart {
  std::optional<Eigen::Vector3d> point;               // on the plane, from its first head pixel
  Eigen::Vector2d mean_px = Eigen::Vector2d::Zero();  // mean virtual pixel of its observations
  int n_virtual = 0;
  unsigned heads_mask = 0;
};
TieStart StartOfTie(const RigStitchProblem& p,
                    const RigConverter& converter,
                    const std::vector<int>& obs) {
  TieStart start;
  for (int o : obs) {
    const RigStitchObservation& ob = p.observations[o];
    if (!start.point) start.point = converter.PlanePointOfHeadPixel(ob.head, ob.pixel);
    if (const auto v = converter.VirtualFromHead(ob.head, ob.pixel)) {
      start.mean_px += *v;
      ++start.n_virtual;
    }
    start.heads_mask |= 1u << ob.head;
  }
  return start;
}

// The tie's standard position: the nearest one of its zone within the radius.
void AssignStandardPosition(RigStitchProblem& p, const TieKey& key, const TieStart& start) {
  if (start.n_virtual == 0) return;
  const Eigen::Vector2d mean_px = start.mean_px / start.n_virtual;
  const std::string zone = ZoneName(p.rig, start.heads_mask);
  int best = -1;
  double best_d = p.options.standard_radius_px;
  for (int s = 0; s < static_cast<int>(p.positions.size()); ++s) {
    const double d = (p.positions[s].virtual_px - mean_px).norm();
    if (p.positions[s].zone == zone && d <= best_d) {
      best = s;
      best_d = d;
    }
  }
  if (best < 0) return;
  p.position_of[key] = best;
  p.position_ties[{key.first, best}].push_back(key);
}

// The head residuals of the tie's observations (calib::MakeRigHeadCollinearityResidual in the
// head's own model), group kGroupRigStitchTie.
void AddTieResiduals(RigStitchProblem& p,
                     const TieKey& key,
                     const std::vector<int>& obs,
                     calib::BlockId point_block) {
  const int i = key.first;
  for (int o : obs) {
    const RigStitchObservation& ob = p.observations[o];
    const int k = ob.head;
    const calib::ResidualId id = p.builder.AddResidual(
        kGroupRigStitchTie,
        calib::MakeRigHeadCollinearityResidual(p.heads[k].camera.model,
                                               p.heads[k].camera.frame(),
                                               ob.pixel,
                                               ob.sigma_px,
                                               p.exposures[i].pose.velocity_mps),
        {p.interior[k],
         p.rig_opk[i],
         p.rig_center[i],
         p.mount[k],
         p.lever[k],
         p.increment[i][k],
         p.dt[i][k],
         point_block},
        ob.label.empty() ? p.ties[key.second].id + "@" + p.heads[k].id : ob.label);
    p.tie_of_residual[id] = key;
    p.residuals_of_tie[key].push_back(id);
  }
}

}  // namespace

void AddTies(RigStitchProblem& p) {
  // Ground calibration converters (E = I, dT = 0): tie starts, zones, standard positions.
  std::vector<RigConverter> ground_calibration;
  for (int i = 0; i < p.n_exposures; ++i)
    ground_calibration.emplace_back(p.rig, p.exposures[i].pose, LevelPlane(p.exposures[i].z_ref_m));
  for (const auto& [key, obs] : p.tie_observations) {
    const auto [i, t] = key;
    if (p.ties[t].check) continue;
    std::set<int> seen;
    for (int o : obs) seen.insert(p.observations[o].head);
    if (seen.size() < 2) {
      ++p.result.dropped_ties;
      continue;
    }
    const TieStart start = StartOfTie(p, ground_calibration[i], obs);
    if (!start.point) {
      ++p.result.dropped_ties;
      continue;
    }
    // A ground point on the plane, Z held.
    Eigen::Vector3d& point = p.vectors.emplace_back(*start.point);
    point.z() = p.exposures[i].z_ref_m;
    const calib::BlockId point_block =
        p.builder.AddBlock("tie[" + p.exposures[i].image + "/" + p.ties[t].id + "]",
                           point.data(),
                           3,
                           calib::BlockKind::kGroundPoint,
                           {"X", "Y", "Z"});
    p.builder.FixEntries(point_block, {2});
    AddTieResiduals(p, key, obs, point_block);
    AssignStandardPosition(p, key, start);
  }
}

}  // namespace aerocal::stitch::internal
