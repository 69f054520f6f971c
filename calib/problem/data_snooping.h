// Data snooping (Baarda's w test, Pope's tau test above the a-priori level) on a ProblemBuilder,
// generic: it knows residual groups and block kinds, nothing about triangulation or stitching.
//
// Rounds
// - Solve; for every tested residual component w_k = |v_k| / (s sqrt(r_k)) with the redundancy
//   number r_k = (Q_vv P)_kk from ProblemBuilder::ComputeObservationCofactors and s = max(sigma0,
//   1) (Baarda's sigma 1 when the data fit their a-priori sigmas, Pope's sigma0 when worse).
// - An observation of several components (x, y) is tested jointly: T = v^T Q_ii^+ v / s^2 over
//   the directions of Q_ii with eigenvalue >= min_redundancy, as the normal w with the same tail
//   probability (w_max). Per-component w of ANOTHER observation can exceed both components of a
//   blundered one; the joint statistic's non-centrality is the largest at the blunder.
// - Candidates: w above the critical value k (from the family-wise alpha: alpha0 = alpha / n over
//   the n tested components, at least 3.29), on components with r >= min_redundancy.
// - In one round every candidate that is the largest w of its point (its eliminable block) and
//   of its image (its rotation block, else its centre block) is acted on: their tests are nearly
//   independent. Then the problem is solved again from the current solution.
// - Components with r < min_redundancy are "weakly controlled": a blunder there barely shows and a
//   model error looks like one. They are reported with their MDB, never rejected.
// - Correlated groups: the observations of the candidate's point cluster whose standardized
//   residuals correlate with the candidate's above group_correlation (|rho| from Q_vv) cannot be
//   told apart by any test. A group of more than one is reported as a group and acted on as a
//   whole: all its members are rejected (the blunder is surely removed; the cost is the group's
//   good observations, which carry no information the test could use to separate them), never
//   one arbitrary member named as "the" gross error. The caller's veto still applies to the group.
//   The group is that of the candidate's largest-w component; its other components can still
//   tell the members apart (a blunder across the strip on one of three rays of a strip whose
//   along-track residuals correlate 1.000): a member whose joint statistic t_joint falls short of
//   the candidate's by more than k^2 (likelihood ratio of "the blunder is there" below
//   exp(-k^2 / 2), the test's own tail) is separated by the data and kept; only the members the
//   residuals cannot separate are rejected with it. Likewise every other candidate of its point
//   (w above k) whose t_joint is within k^2 of the candidate's joins the group: correlated
//   below group_correlation (strip neighbours at ~0.95) they swap order with the noise often
//   enough that rejecting the larger alone names a good ray and leaves the blunder untestable.
// - report_only_groups (e.g. surveyed control coordinates) are tested and named when they fail,
//   never rejected as gross errors of the rays: a survey that disagrees with its rays is a
//   finding for people, and rejecting the rays instead would hide it.
// - Surveys first (leave_out_report_only): before the rays are snooped, every report-only
//   observation is tested over ALL its directions (w_full: the joint chi-square t_full over every
//   eigen-direction of Q_ii above 1e-6, weakly controlled ones included, as the normal w of the
//   same tail). A wrong survey pulls the block and large residuals land on the other surveys and
//   the rays (a corner control point's coordinate has r ~ 0.02 in the direction the block can
//   bend: 10 m on C1 of the self-calibrating simulated flight gave w 40 on C1, 40 on C4, 32 on
//   C5, and the per-direction test named C5), but the joint statistic of the wrong one has the
//   largest non-centrality. The worst failing survey is left out, the block re-solved and the
//   others re-tested, when the data single it out:
//   - no other failing survey has t_full within k^2 of it (else the test cannot tell them apart:
//     the group is named, e.g. opposite corners C1 and C4, or the four corners' heights);
//   - its own residual exceeds k sigmas (else the disagreement lies in a direction the block
//     bends to fit, where a model error looks the same: the conventional flight's C5, w 15 from a
//     residual of 0.8 sigma at r 0.003);
//   - no direction of it has r < 1e-4 (else it alone holds the block there);
//   - at most max_left_out are left out, and the caller's veto (datum) agrees.
//   A group, a survey that holds the block, the cap or the veto leave failing surveys that the
//   test names as suspects but cannot leave out: SnoopingOutcome::unresolved holds them (the
//   caller's run is then not a fit: a blunder somewhere in the datum) and they stay in the
//   adjustment. The surveys singled out and left out before a group stay out (left_out); before
//   the other stops they are restored and named with the suspects. A
//   failing survey whose residual is within k sigmas is not a suspect (a model error looks the
//   same: the conventional flight's C5 height on clean data).
//   An observation of several components is one test; a caller that wants components judged
//   separately (a survey's plan and height: their redundancy differs by orders of magnitude,
//   0.02 and 0.001 at a corner of the self-calibrating simulated flight) adds them as separate
//   residuals.
//   When every remaining survey then passes and sigma0 lies within 1 + 3 / sqrt(2 r) (a model
//   error would keep it above), those left out are "suspected control blunders"
//   (SnoopingOutcome::left_out, verdict "left out"): out of the adjustment, their rays kept and
//   tested as tie rays. Otherwise every survey is restored (RestoreResidual), the finding names
//   the worst or the group and why, and the run goes on as below (held, model error suspected).
// - The veto (caller-supplied) refuses a removal that would destroy the datum (a control point
//   left with < 2 rays, an exposure left under-determined); vetoed candidates are reported.
// - The cap: after max_rejections removals the run stops, says so and how many candidates were
//   left above the critical value (SnoopingOutcome::cap_reached).
// - Model error: when the largest w of the first test sit on the report-only (control) points,
//   their rays are held, not rejected (a model error shows most where the survey pins the
//   block), unless one ray explains them: a blunder on one control ray pulls its point and the
//   point's other rays follow, which looks the same. So first the largest-w ray of a control
//   point (a group of one, the veto agreeing) is removed alone and the block re-solved; when
//   every control ray then passes and sigma0 lies within 1 + 3 / sqrt(2 r), that ray is rejected
//   as a blunder and the suspicion withdrawn; otherwise it is restored and the rays are held (a
//   model error leaves the other control rays above k and sigma0 above the band). When the
//   final sigma0 is above model_error_sigma0, or the candidates left over (held, vetoed, weakly
//   controlled, at the cap) cluster on one point or one image (each correlated group counted
//   once), the outcome says "model error suspected" with the evidence.
//
// MDB: the marginal detectable blunder of component k (a blunder along that component), in
// sigmas of the observation: nabla_k = delta s / sqrt(r_k), with delta the square root of the
// non-centrality the observation's test needs for the power: for a one-dimensional test
// delta0 = k + z(power); for the joint test of two controlled components (x, y of an image point)
// delta0_joint, from chi-square(2) at the critical value T = chi2(2) quantile of the same tail
// probability (k 4.44, power 0.8: 5.57 instead of 5.28; the one-dimensional delta0 understated
// those MDBs by 5 %).
#pragma once

#include "calib/problem/problem_builder.h"

#include <functional>
#include <string>
#include <vector>

namespace aerocal::calib {

struct SnoopingOptions {
  std::vector<std::string> groups;              // tested groups; empty = every group
  std::vector<std::string> report_only_groups;  // tested and reported, never rejected
  double alpha = 0.05;              // family-wise level over the tested components, (0, 1)
  double critical_value = 0.0;      // of |w|; 0: from alpha / n_tested (at least 3.29)
  double power = 0.80;              // of the test, for the MDB, (0.5, 1)
  double min_redundancy = 0.1;      // r below: weakly controlled, never rejected
  double group_correlation = 0.99;  // |rho| above: the observations cannot be told apart
  int max_rejections = 100;         // removals (group members count one each), > 0
  /// Test the report-only observations first and leave out the failing ones when that makes the
  /// others pass (see the header); off: they are only named and held.
  bool leave_out_report_only = false;
  /// At most this many report-only observations left out; 0: a third of them (at least 1).
  int max_left_out = 0;
  double model_error_sigma0 = 1.5;  // final sigma0 above: model error suspected
  /// Share of the largest w (at most 10, at least 2) on one point / image / the report-only
  /// points from which a model error is suspected.
  double model_error_share = 0.5;
  /// Non-empty reason: removing these residuals (a candidate or its whole group) is refused.
  std::function<std::string(const std::vector<ResidualId>&)> veto;
  /// Passed to ComputeObservationCofactors: a singular reduced matrix larger than this is not
  /// inverted; then nothing is tested and the outcome says so (cofactors_ok false).
  int max_dense_parameters = 4000;
};

enum class SnoopingVerdict {
  kAccepted,           // tested, below the critical value
  kRejected,           // removed as a gross error (alone or with its correlated group)
  kWeaklyControlled,   // above the critical value on a component with r < min_redundancy
  kVetoed,             // candidate whose removal the caller refused (datum)
  kHeld,               // candidate of a report-only group, or held by a suspected model error
  kLeftAboveCritical,  // candidate left when the rejection cap was reached
  kLeftOut             // report-only observation left out: the others pass without it
};
const char* VerdictName(SnoopingVerdict verdict);

struct TestedObservation {
  ResidualId id = -1;
  std::string group, label;
  std::vector<double> v;           // whitened residual at the test
  std::vector<double> redundancy;  // r per component
  std::vector<double> w;           // per component; NaN where r < 1e-6 (untestable)
  std::vector<double> mdb_sigma;   // per component, in sigmas; +inf where untestable
  /// The observation's test statistic on the normal scale: for several components (an image
  /// point's x, y) the joint chi-square test over its controlled directions (Q_ii eigenvalues
  /// >= min_redundancy) mapped to the normal w of the same tail probability; for one, its w.
  double w_max = 0.0;
  /// The chi-square statistic behind w_max (v^T Q_ii^+ v / s^2 over the controlled directions;
  /// w_max^2 for one component): members of a correlated group are told apart by it.
  double t_joint = 0.0;
  int component = -1;   // its largest-w controlled component (for the group)
  double w_weak = 0.0;  // largest w of the weakly controlled components
  /// The joint statistic over every testable direction (eigenvalue of Q_ii >= 1e-6, weakly
  /// controlled ones included) as a normal w: the test of a survey (leave_out_report_only).
  double w_full = 0.0;
  double t_full = 0.0;                 // the chi-square statistic behind w_full
  std::vector<ResidualId> correlated;  // with itself: observations it cannot be told apart from
  int group_size = 1;
  BlockId point = -1;  // its eliminable block, -1 when none
  SnoopingVerdict verdict = SnoopingVerdict::kAccepted;
  int round = 0;       // round of the verdict
  std::string reason;  // for the verdicts other than accepted
};

struct SnoopingOutcome {
  SolveReport report;  // of the final adjustment
  double alpha = 0.0, alpha0 = 0.0, critical_value = 0.0, power = 0.0, delta0 = 0.0;
  double delta0_joint = 0.0;  // for the joint test of two components (see the MDB above)
  double min_redundancy = 0.0, group_correlation = 0.0, reference_sigma = 1.0;
  int n_tested_components = 0;
  std::string cofactor_method;
  bool cofactors_ok = true;  // false: nothing could be tested (cofactor_message says why)
  std::string cofactor_message;
  int rounds = 0;
  int solves = 0;                // solves made by snooping (0: `report` is the caller's `solved`)
  int solve_iterations = 0;      // LM iterations of those solves, summed
  double seconds_solving = 0.0;  // their SolveReport::seconds, summed
  bool cap_reached = false;
  int remaining_above_critical = 0;         // candidates left when the cap was reached
  std::vector<TestedObservation> rejected;  // in order, with their test values
  /// Report-only observations left out (suspected survey blunders), with the test that failed.
  std::vector<TestedObservation> left_out;
  /// Report-only observations that fail the surveys-first test when none of them can be left out:
  /// the test cannot tell them apart (a group), or the worst alone holds the block in a direction,
  /// or the veto / max_left_out keep it. Every survey is kept and these are named: one of them is
  /// off (or the model does not fit them). Empty when nothing fails, when the failing survey's
  /// residual is within the critical value (a model error looks the same) and when a model error
  /// remains after leaving out the worst (sigma0 above the band).
  std::vector<TestedObservation> unresolved;
  std::string unresolved_reason;  // why none of `unresolved` could be left out
  /// The final test of every active tested residual (and the vetoed / held candidates).
  std::vector<TestedObservation> tested;
  bool model_error_suspected = false;
  std::vector<std::string> model_error_evidence;
  std::vector<std::string> findings;  // suspected control blunders, groups, vetoes, the cap
  double seconds_testing = 0.0;       // cofactors and tests (not the solves)
};

/// Solves, snoops as described above, returns the final report and every verdict.
/// `solved`: the report of a solve the caller just made on `builder` at its current values (the
/// first solve is then skipped; re-solving a converged problem costs a factorisation and moves
/// nothing beyond the solver tolerance); null: solve first.
SnoopingOutcome SolveWithDataSnooping(ProblemBuilder& builder,
                                      const SolverOptions& solver,
                                      const SnoopingOptions& options,
                                      const SolveReport* solved = nullptr);

/// delta0 = k + z(power): the non-centrality a blunder needs to be found with that power.
double NonCentrality(double critical_value, double power);

/// sqrt(lambda) with P(chi2(2, lambda) > T) = power, T the chi-square(2) value with the tail
/// probability of |N(0,1)| > critical_value: the non-centrality (as a normal shift) of the joint
/// test of two components.
double NonCentralityJoint(double critical_value, double power);

}  // namespace aerocal::calib
