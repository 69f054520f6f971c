// The steps of the self-calibrating rig stitching (SelfCalibrateRigStitching, self_calibration.h),
// each a function of the run's state, in the order the driver calls them:
//   set-up  (self_calibration_setup.cc): the held blocks of the ground calibration and the POS,
//           the increments and time offsets by mode with their priors, the tie points and their
//           observations, each tie's standard position;
//   solve   (self_calibration_solve.cc): the solve with data snooping and its standard-position
//           veto, the covariance of the increments and offsets, the stop's effect, the dT
//           correlations, the per-head results and the rules that make the run not valid;
//   figures (self_calibration_rms.cc): the stitching RMS before and after, the standard
//           positions' ties, the relief displacement and sigma0 in px.
// Internal to stitch/rig: the public interface is self_calibration.h.
#pragma once

#include "calib/problem/problem_builder.h"
#include "stitch/rig/self_calibration.h"

#include <Eigen/Core>

#include <deque>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::stitch::internal {

using TieKey = std::pair<int, int>;  // (exposure, tie)

/// The rectification plane of the level virtual image at an exposure: Z = z_ref.
RectificationPlane LevelPlane(double z_ref_m);

/// The state of one run. Not copyable: the problem's blocks point into it.
struct RigStitchProblem {
  RigStitchProblem(const calib::Rig& rig,
                   const std::vector<RigStitchExposure>& exposures,
                   const std::vector<RigStitchTie>& ties,
                   const std::vector<RigStitchObservation>& observations,
                   const std::vector<StandardPosition>& positions,
                   const RigStitchOptions& options);
  RigStitchProblem(const RigStitchProblem&) = delete;
  RigStitchProblem& operator=(const RigStitchProblem&) = delete;

  const calib::Rig& rig;
  const std::vector<RigStitchExposure>& exposures;
  const std::vector<RigStitchTie>& ties;
  const std::vector<RigStitchObservation>& observations;
  const std::vector<StandardPosition>& positions;
  const RigStitchOptions& options;
  const int n_heads, n_exposures, reference;
  std::map<TieKey, std::vector<int>> tie_observations;  // observations of each (exposure, tie)

  // Parameter storage (stable addresses) and the problem.
  std::deque<Eigen::Vector3d> vectors;
  std::deque<double> scalars;
  calib::ProblemBuilder builder;
  std::vector<calib::RigHead> heads;                       // owned copies the blocks point into
  std::vector<calib::BlockId> interior, mount, lever;      // per head, held
  calib::BlockId zero_increment = -1, zero_dt = -1;        // the reference head's
  std::vector<calib::BlockId> rig_opk, rig_center;         // per exposure, held
  std::vector<std::vector<calib::BlockId>> increment, dt;  // [exposure][head]
  std::vector<calib::BlockId> line_dt;                     // per head (line mode)
  std::vector<RigExposure> poses;                          // POS, E = I, dT = 0
  std::vector<Eigen::Vector4d> rig_quaternion;             // sized once: blocks point into it

  // The fitted ties.
  std::map<TieKey, int> position_of;  // tie -> standard position index
  std::map<std::pair<int, int>, std::vector<TieKey>> position_ties;  // (exposure, position)
  std::map<int, TieKey> tie_of_residual;
  std::map<TieKey, std::vector<calib::ResidualId>> residuals_of_tie;

  calib::CovarianceReport cov;               // of the increments and offsets
  std::set<calib::BlockId> undetermined_dt;  // dT blocks correlated beyond the threshold
  RigStitchResult result;
};

/// The names of an increment's entries.
extern const std::vector<std::string> kIncrementAngleNames;

// ---- set-up (self_calibration_setup.cc) ----
/// The heads' interiors, mounts and lever arms, held; the reference head's E = I and dT = 0.
void AddHeadBlocks(RigStitchProblem& p);
/// Whether the time offsets are held (angles mode, no velocity, held heads); warns without a
/// velocity.
void DecideTimeOffsets(RigStitchProblem& p);
/// The POS of every exposure (held) and the increments and time offsets by mode, with priors.
void AddExposureBlocks(RigStitchProblem& p);
/// Every fitted tie seen by two heads or more: a ground point on its plane (Z held) and the head
/// residuals of its observations; its standard position.
void AddTies(RigStitchProblem& p);

// ---- solve (self_calibration_solve.cc) ----
/// A tie survives a removal when two or more of its observations stay.
bool TieAlive(const RigStitchProblem& p,
              const TieKey& key,
              const std::set<calib::ResidualId>& removed);
/// Solves, with data snooping of the ties when asked; the ties kept against the test (vetoed
/// removals) are returned.
std::vector<calib::ResidualId> SolveWithSnooping(RigStitchProblem& p);
/// Covariance of the increments and offsets, the stop's effect, the dT correlations.
void EstimatePrecision(RigStitchProblem& p, const std::vector<calib::ResidualId>& kept);
/// The increments and offsets of every exposure and head; the refined poses.
std::vector<RigExposure> CollectHeads(RigStitchProblem& p);
/// What makes the run untrustworthy, by name (RigStitchResult::failures), and the stop warnings.
void JudgeRun(RigStitchProblem& p);

// ---- figures (self_calibration_rms.cc) ----
/// The stitching RMS before (ground calibration) and after (`refined`), fitted and check ties.
void StitchingRms(RigStitchProblem& p, const std::vector<RigExposure>& refined);
/// Fitted ties per standard position before and after the snooping.
void CountStandardPositions(RigStitchProblem& p);
/// The mean flying height and the plane model's displacement for the relief (CONVENTIONS.md).
void ReliefDisplacement(RigStitchProblem& p);
/// sigma0 x the median a-priori sigma of the fitted tie observations.
void Sigma0InPixels(RigStitchProblem& p);

}  // namespace aerocal::stitch::internal
