// Self-calibrating stitching of a multi-head rig (issue 16; Gui et al. 2014): the relative attitude
// of the heads is re-estimated at EVERY exposure from tie points in the overlap zones, so that the
// horizontal (level) virtual image is seamless although the mount flexes in flight and the
// shutters fire a few ms apart (CONVENTIONS.md "Multi-head rigs").
//
// Model, per exposure i and head k (calib::HeadPose): R_k = R M_k E_ik, O_k = O + R t_k + v dT_k,
// with the ground calibration (interiors, M_k, t_k) and the POS (R, O, v) held. Unknowns:
//   E_ik   attitude increments of the non-reference heads (3 angles each; E = I for the
//          reference head). Small angles (~0.025 deg), so this problem uses its own 3-vector
//          increment blocks Rx Ry Rz (no rotation manifold is needed near zero; the exposure
//          rotation blocks of the bundle adjustment are not used here);
//   dT_k   exposure-time offsets of the non-reference heads (s), by mode:
//          kLine (default): one per head for the whole flight (shutter lag is a property of the
//          camera), angles per exposure; kPerExposure: one per exposure and head -- nearly
//          inseparable from the rotation about the cross-track axis (|rho| ~ 0.98), so the
//          correlations are reported by name and a dT above the threshold is not reported as a
//          value; kAngles: held at zero;
//   tie points: one ground point per tie on the plane Z = z_ref of its exposure (X, Y free, Z
//          held: the plane model of the virtual image; relief leaves the CONVENTIONS residual
//          displacement, reported).
// Observations: the tie's measured head pixels, calib::MakeRigHeadCollinearityResidual in the
// head's own model (calib/residuals), whitened by their sigma_px, group kGroupRigStitchTie.
// Optional weighted priors (towards 0) on the increments and offsets where sigmas are given. One
// ProblemBuilder owns the problem.
//
// Gross errors: data snooping (calib/problem/data_snooping.h) on the tie observations, with a
// veto: a removal that would leave a standard position of an exposure (rig_design.h: two per
// two-fold zone, one per triple zone) without any tie is refused; the run then STOPS at that
// point and says so (the paper's rule against over-rejection), `stopped` with the reason. The
// stop is judged by its effect (issue 28 part 2): the ties kept against the test are left out, the
// increments and offsets re-estimated, and their change in their sigmas decides (stop_effect).
//
// Stitching RMS (virtual pixels of the level virtual image): each tie's head pixels are carried
// to the virtual image (RigConverter, plane Z = z_ref) and compared pairwise: per_coordinate =
// sqrt(sum (dx^2 + dy^2) / (2 n_pairs)), pair_2d = sqrt(sum (dx^2 + dy^2) / n_pairs) (the 2-D
// disagreement of a pair; sqrt(2) x per_coordinate). "before": ground calibration alone
// (E = I, dT = 0); "after": the estimates. For the fitted ties and for the check ties (measured,
// never adjusted), per zone, per exposure and over the flight.
#pragma once

#include "calib/camera/rig.h"
#include "calib/core/finding.h"
#include "calib/problem/problem_builder.h"
#include "calib/problem/suspect_effect.h"
#include "stitch/rig/rig_conversion.h"
#include "stitch/rig/rig_design.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::stitch {

inline constexpr const char* kGroupRigStitchTie = "rig_stitch_tie";
/// Owner of rig stitching's weighted increments and time offsets: their priors are in group
/// calib::PriorGroup(kRigStitchOwner), "rig_stitch_prior" (calib/problem/mounted_block.h).
inline constexpr const char* kRigStitchOwner = "rig_stitch";

enum class RigStitchMode { kLine, kPerExposure, kAngles };
/// "line" | "per-exposure" | "angles"; nullopt otherwise.
std::optional<RigStitchMode> ParseRigStitchMode(const std::string& name);
const char* RigStitchModeName(RigStitchMode mode);

/// One exposure: the POS (rig attitude, virtual centre, velocity; increments left empty) and the
/// height of its rectification plane.
struct RigStitchExposure {
  std::string image;
  RigExposure pose;
  double z_ref_m = 0.0;
};

struct RigStitchTie {
  std::string id;
  bool check = false;  // a check tie: measured, never adjusted
};

struct RigStitchObservation {
  int exposure = 0, head = 0, tie = 0;              // indices into the inputs
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // measured head pixel
  double sigma_px = 0.5;                            // > 0
  std::string label;                                // e.g. "observations.csv:17"
};

struct RigStitchOptions {
  RigStitchMode mode = RigStitchMode::kLine;
  std::optional<double> increment_sigma_rad;  // prior sigma of every increment angle, > 0
  std::optional<double> dt_sigma_s;           // prior sigma of every time offset, > 0
  bool snooping = true;
  double alpha = 0.05;                  // family-wise level of the snooping, (0, 1)
  double standard_radius_px = 400.0;    // a tie this close to a standard position of its zone
                                        // counts for it (virtual px), > 0
  double correlation_threshold = 0.95;  // |rho| of dT with an angle above: not determinable
  double relief_m = 0.0;                // relief off the plane for the displacement figure, >= 0
  double max_sigma0 = 3.0;              // sigma0 above: absurd (a-priori sigmas or model), > 0
  /// A stop (a failing tie kept to hold its standard position) is judged by its effect
  /// (calib/problem/suspect_effect.h): the increments and offsets re-estimated without the kept
  /// ties; the run is not valid only when one moves by more than this many of its sigmas, > 0.
  double suspect_effect_limit = 1.0;
  bool hold_heads = false;  // a reference run: increments and offsets held at the ground
                            // calibration, only the tie points adjust (benchmark peer)
  calib::SolverOptions solver;
};

struct StitchRms {
  double per_coordinate = 0.0, pair_2d = 0.0;  // virtual px
  int pairs = 0, ties = 0;
};
struct StitchRmsSet {
  StitchRms fit, check;
};
struct ZoneStitchRms {
  std::string zone;  // "AB"
  StitchRmsSet before, after;
};

struct RigStitchHead {
  std::string head;
  Eigen::Vector3d increment_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d increment_sigma_rad = Eigen::Vector3d::Zero();  // 0 for the reference head
  std::optional<double> dt_s;        // nullopt: not determinable (per-exposure mode, correlation)
  std::optional<double> dt_sigma_s;  // nullopt: held or not determinable
  double dt_fitted_s = 0.0;  // the adjusted dT (s), also where it is not determinable on its own:
                             // with the increments, the geometry of the "after" figures and of
                             // the stitched image (the pair is determined, its split is not)
  bool reference = false;
};

struct RigStitchExposureResult {
  std::string image;
  std::vector<RigStitchHead> heads;
  StitchRmsSet before, after;
  std::vector<ZoneStitchRms> zones;
};

struct StandardPositionCount {
  std::string image, name;
  int ties_before = 0, ties_after = 0;  // fitted ties counted for the position
};

struct DtCorrelation {
  std::string dt, angle;  // parameter names
  double rho = 0.0;
};

/// Where the run's time went (issue 35), wall seconds of this process.
struct RigStitchProfile {
  int solves = 0;           // adjustments solved (the first one and the snooping's re-solves)
  int iterations = 0;       // their Levenberg-Marquardt iterations, summed
  int snooping_rounds = 0;  // test rounds (cofactors + w tests)
  double solve_s = 0.0;     // the solves
  double testing_s = 0.0;   // the snooping's redundancy numbers and tests
  double covariance_s = 0.0, effect_s = 0.0;  // covariance; the stop's leave-out re-solve
  double setup_s = 0.0;                       // blocks, priors and ties added to the problem
  double figures_s = 0.0;  // per-head results, stitching RMS, standard positions, relief, validity
  double total_s = 0.0;    // the whole call
};

struct RigStitchResult {
  calib::SolveReport report;
  RigStitchProfile profile;
  double sigma0 = 0.0;
  int redundancy = 0;
  std::vector<RigStitchExposureResult> exposures;
  StitchRmsSet before, after;                  // the flight
  std::vector<ZoneStitchRms> zones;            // the flight
  std::vector<DtCorrelation> dt_correlations;  // largest |rho| of each dT with an angle
  bool dt_determinable = true;
  bool dt_held = false;               // angles mode, or no velocity
  std::vector<std::string> rejected;  // labels of the observations snooping removed
  bool stopped = false;               // snooping refused to empty a standard position
  std::vector<std::string> stop_reasons;
  calib::SuspectEffect stop_effect;  // of the kept failing ties, when stopped
  std::vector<StandardPositionCount> standard_positions;
  int dropped_ties = 0;                 // fitted ties with fewer than two observations (not used)
  double relief_displacement_px = 0.0;  // largest over the head pairs, at options.relief_m
  double height_m = 0.0;                // mean relative flying height above z_ref (m)
  double sigma0_px = 0.0;  // sigma0 x the median a-priori sigma of the fitted tie observations
  std::vector<Finding> warnings;  // doubtful, not invalid: by name (calib/core/finding.h)
  /// Why the run must not be trusted, each by name: not converged, covariance singular, sigma0
  /// above options.max_sigma0, snooping stopped at a standard position with an effect that
  /// matters (else a warning). Empty: a valid run.
  std::vector<std::string> failures;
};

/// Runs the self-calibrating stitching. The rig must have a level virtual camera; `positions` are
/// the standard tie positions of rig_design.h (may be empty: no standard-position rule).
RigStitchResult SelfCalibrateRigStitching(const calib::Rig& rig,
                                          const std::vector<RigStitchExposure>& exposures,
                                          const std::vector<RigStitchTie>& ties,
                                          const std::vector<RigStitchObservation>& observations,
                                          const std::vector<StandardPosition>& positions,
                                          const RigStitchOptions& options);

}  // namespace aerocal::stitch
