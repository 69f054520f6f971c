#include "calib/problem/data_snooping.h"

#include "calib/core/error.h"
#include "calib/core/stopwatch.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <tuple>

namespace aerocal::calib {
namespace {

constexpr double kUntestable = 1e-6;  // r below: no test can see anything there
constexpr int kModelErrorTop = 10;    // the largest w examined for a model error
// A survey is left out only when the block then fits its a-priori sigmas: sigma0 within
// 1 + kFitBand / sqrt(2 redundancy) (the chi-square band of sigma0, 3 of its sigmas). A model
// error (a camera the adjustment does not model) leaves sigma0 above it, and then a survey that
// disagrees cannot be told from the model error: leaving the worst one out would bend the
// block at that point (the centre point C5 of the conventional simulated flight: 6.6 m).
constexpr double kFitBand = 3.0;
// A survey with a direction of redundancy below this alone holds the block there (without it the
// block is 1 / sqrt(1e-4) = 100 survey sigmas loose at that point): never left out, named. The
// centre control point of the self-calibrating simulated flight (height r 1.6e-5: c absorbs the
// block's height there) moved by 10 m when its survey was left out for a wrong X.
constexpr double kHoldsTheBlock = 1e-4;

bool Contains(const std::vector<std::string>& list, const std::string& s) {
  return std::find(list.begin(), list.end(), s) != list.end();
}

BlockId PointOf(const ProblemBuilder& b, ResidualId id) {
  for (BlockId block : b.ResidualBlocks(id)) {
    const BlockKind kind = b.BlockKindOf(block);
    if (kind == BlockKind::kGroundPoint || kind == BlockKind::kTiePoint2d) return block;
  }
  return -1;
}

BlockId ImageOf(const ProblemBuilder& b, ResidualId id) {
  BlockId center = -1;
  for (BlockId block : b.ResidualBlocks(id)) {
    if (b.BlockKindOf(block) == BlockKind::kRotation) return block;
    if (b.BlockKindOf(block) == BlockKind::kCenter && center < 0) center = block;
  }
  return center;
}

// Readable name of an image block: "image 0012 angles" -> "image 0012".
std::string ImageName(const ProblemBuilder& b, BlockId block) {
  std::string name = b.BlockName(block);
  for (const char* suffix : {" angles", " centre"}) {
    const std::string s(suffix);
    if (name.size() > s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0)
      return name.substr(0, name.size() - s.size());
  }
  return name;
}

// The two-sided normal value with the tail probability of chi-square(dof) at t (dof 1..3;
// more: Wilson-Hilferty). Far in the tail (p below 1e-300) sqrt(t), which keeps the order.
double EquivalentNormal(double t, int dof) {
  if (dof == 1) return std::sqrt(t);
  double p = 0.0;
  if (dof == 2) {
    p = std::exp(-t / 2);
  } else if (dof == 3) {
    p = std::erfc(std::sqrt(t / 2)) + std::sqrt(2 * t / M_PI) * std::exp(-t / 2);
  } else {
    const double k = dof, z = (std::cbrt(t / k) - (1 - 2 / (9 * k))) / std::sqrt(2 / (9 * k));
    p = 0.5 * std::erfc(z / std::sqrt(2.0));
  }
  if (!(p > 1e-300)) return std::sqrt(t);
  return p >= 1.0 ? 0.0 : NormalCriticalValue(p);
}

std::string Fixed(double value, int digits) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", digits, value);
  return buffer;
}

struct Test {
  std::vector<TestedObservation> observations;
  std::map<ResidualId, size_t> index;
  std::vector<ResidualCluster> clusters;
  std::map<ResidualId, std::pair<size_t, int>> row_of;  // residual -> (cluster, first row)
  std::string method;
};

// A solve of the snooping (the first one or a re-solve after removals or restorations): from the
// current values, i.e. warm-started at the previous solution. Counted, with its LM iterations and
// seconds, so that a caller can see what the rounds cost.
void Resolve(ProblemBuilder& builder, const SolverOptions& solver, SnoopingOutcome* out) {
  out->report = builder.Solve(solver);
  ++out->solves;
  out->solve_iterations += out->report.iterations;
  out->seconds_solving += out->report.seconds;
}

class Snooper {
 public:
  Snooper(ProblemBuilder& builder, const SnoopingOptions& options, SnoopingOutcome* out)
      : b_(builder), o_(options), out_(*out) {}

  Test Run(int round) {
    const Stopwatch round_time;
    Test t;
    int components = 0;
    const std::vector<ResidualId> ids = TestedResiduals(&components);
    if (round == 1 && !initialized_) InitializeOutcome(components);
    ObservationCofactors cof = b_.ComputeObservationCofactors(ids, true, o_.max_dense_parameters);
    t.method = cof.method;
    out_.cofactor_method = cof.method;
    if (!cof.ok) {  // never tested on approximate redundancy numbers
      out_.cofactors_ok = false;
      out_.cofactor_message = cof.message;
      out_.findings.push_back("no test: the redundancy numbers could not be computed (" +
                              cof.message + ")");
      return t;
    }
    t.clusters = std::move(cof.clusters);
    IndexClusterRows(&t);
    const double s = std::max(out_.report.sigma0, 1.0);
    out_.reference_sigma = s;
    for (ResidualId id : ids) {
      TestedObservation x = TestOne(id, cof.redundancy.at(id), t, s, round);
      t.index[id] = t.observations.size();
      t.observations.push_back(std::move(x));
    }
    // Correlated groups of every observation (their sizes go into the report).
    for (auto& x : t.observations) {
      x.correlated = GroupOf(t, x);
      const auto d = decided_.find(x.id);
      if (d != decided_.end()) std::tie(x.verdict, x.reason) = d->second;
    }
    for (auto& x : t.observations) x.group_size = static_cast<int>(x.correlated.size());
    out_.cofactor_method = t.method;
    out_.seconds_testing += round_time.Seconds();
    return t;
  }

  // The active residuals of the tested groups, and their number of scalar components.
  std::vector<ResidualId> TestedResiduals(int* components) const {
    std::vector<ResidualId> ids;
    for (ResidualId id : AllResiduals()) {
      if (!b_.IsActive(id)) continue;
      if (!o_.groups.empty() && !Contains(o_.groups, b_.ResidualGroup(id))) continue;
      ids.push_back(id);
      *components += static_cast<int>(b_.EvaluateResidual(id).size());
    }
    return ids;
  }

  // The test's constants, fixed by the first test: alpha0 = alpha / components (Bonferroni),
  // its critical value (at least 3.29) and the non-centralities at the chosen power.
  void InitializeOutcome(int components) {
    initialized_ = true;
    out_.n_tested_components = components;
    out_.alpha = o_.alpha;
    out_.alpha0 = o_.alpha / std::max(1, components);
    out_.critical_value = o_.critical_value > 0 ? o_.critical_value
                                                : std::max(3.29, NormalCriticalValue(out_.alpha0));
    out_.power = o_.power;
    out_.delta0 = NonCentrality(out_.critical_value, o_.power);
    out_.delta0_joint = NonCentralityJoint(out_.critical_value, o_.power);
    out_.min_redundancy = o_.min_redundancy;
    out_.group_correlation = o_.group_correlation;
  }

  // Where each clustered residual's rows start in its cluster's Q_vv.
  void IndexClusterRows(Test* t) const {
    for (size_t c = 0; c < t->clusters.size(); ++c) {
      int row = 0;
      for (ResidualId id : t->clusters[c].residuals) {
        t->row_of[id] = {c, row};
        row += static_cast<int>(b_.EvaluateResidual(id).size());
      }
    }
  }

  // One observation's test: per component w = |v| / (s sqrt(r)) and its MDB delta0 s / sqrt(r)
  // (untestable below r = kUntestable), the largest w among the components controlled well
  // enough (r >= min_redundancy), and the joint test where it has correlated components.
  TestedObservation TestOne(ResidualId id,
                            const std::vector<double>& redundancy,
                            const Test& t,
                            double s,
                            int round) const {
    TestedObservation x;
    x.id = id;
    x.group = b_.ResidualGroup(id);
    x.label = b_.ResidualLabel(id);
    x.v = b_.EvaluateResidual(id);
    x.redundancy = redundancy;
    x.point = PointOf(b_, id);
    x.round = round;
    for (size_t k = 0; k < x.v.size(); ++k) {
      const double r = x.redundancy[k];
      if (r < kUntestable) {
        x.w.push_back(std::numeric_limits<double>::quiet_NaN());
        x.mdb_sigma.push_back(std::numeric_limits<double>::infinity());
        continue;
      }
      const double w = std::abs(x.v[k]) / (s * std::sqrt(r));
      x.w.push_back(w);
      x.mdb_sigma.push_back(out_.delta0 * s / std::sqrt(r));
      if (r >= o_.min_redundancy && w > x.w_max) {
        x.w_max = w;
        x.component = static_cast<int>(k);
      }
      if (r < o_.min_redundancy) x.w_weak = std::max(x.w_weak, w);
      x.w_full = std::max(x.w_full, w);
    }
    x.t_full = x.w_full * x.w_full;
    x.t_joint = x.w_max * x.w_max;
    // An observation of several correlated components (x, y of an image point) is tested as
    // a whole: per-component w of another observation can exceed both of the blundered one's,
    // the joint statistic cannot (its non-centrality is the largest at the blunder).
    const auto at = t.row_of.find(id);
    if (x.v.size() > 1 && at != t.row_of.end())
      JointTest(t.clusters[at->second.first], at->second.second, s, &x);
    return x;
  }

  // T = v^T Q_ii^+ v / s^2 over the eigen-directions of Q_ii with eigenvalue >= min_redundancy
  // (chi-square with that many degrees of freedom), as the normal w with the same tail
  // probability; the weakly controlled directions give w_weak, each its own 1-D test.
  void JointTest(const ResidualCluster& c, int row, double s, TestedObservation* x) const {
    const int m = static_cast<int>(x->v.size());
    const Eigen::MatrixXd q = c.qvv.block(row, row, m, m);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(q);
    const Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(x->v.data(), m);
    double t_stat = 0.0, w_weak = 0.0, t_full = 0.0;
    int dof = 0, dof_full = 0;
    for (int k = 0; k < m; ++k) {
      const double lambda = eig.eigenvalues()(k);
      if (lambda < kUntestable) continue;
      const double u = eig.eigenvectors().col(k).dot(v) / s;
      t_full += u * u / lambda;
      ++dof_full;
      if (lambda < o_.min_redundancy) {
        w_weak = std::max(w_weak, std::abs(u) / std::sqrt(lambda));
        continue;
      }
      t_stat += u * u / lambda;
      ++dof;
    }
    x->w_weak = std::max(x->w_weak, w_weak);
    x->w_full = dof_full > 0 ? EquivalentNormal(t_full, dof_full) : 0.0;
    x->t_full = t_full;
    if (dof == 2)  // the MDBs of a joint test of two components
      for (int k = 0; k < m; ++k)
        if (std::isfinite(x->mdb_sigma[k])) x->mdb_sigma[k] *= out_.delta0_joint / out_.delta0;
    if (dof == 0) {
      x->w_max = 0.0;
      x->t_joint = 0.0;
      x->component = -1;
      return;
    }
    x->w_max = EquivalentNormal(t_stat, dof);
    x->t_joint = t_stat;
  }

  std::vector<ResidualId> GroupOf(const Test& t, const TestedObservation& x) const {
    std::vector<ResidualId> group = {x.id};
    const auto at = t.row_of.find(x.id);
    if (at == t.row_of.end() || x.component < 0) return group;
    const ResidualCluster& c = t.clusters[at->second.first];
    const int i = at->second.second + x.component;
    const double qii = c.qvv(i, i);
    if (!(qii > kUntestable)) return group;
    int row = 0;
    for (ResidualId other : c.residuals) {
      const int n = static_cast<int>(t.observations[t.index.at(other)].v.size());
      if (other != x.id && !Contains(o_.report_only_groups, b_.ResidualGroup(other))) {
        for (int k = row; k < row + n; ++k) {
          const double qkk = c.qvv(k, k);
          if (!(qkk > kUntestable)) continue;
          if (std::abs(c.qvv(i, k)) / std::sqrt(qii * qkk) > o_.group_correlation) {
            group.push_back(other);
            break;
          }
        }
      }
      row += n;
    }
    return group;
  }

  std::vector<ResidualId> AllResiduals() const {
    std::vector<ResidualId> out(b_.NumResiduals());
    for (ResidualId id = 0; id < b_.NumResiduals(); ++id) out[id] = id;
    return out;
  }

  // The signature of a model error. In the first test: the largest w on the report-only
  // (control) points, where the survey pins the block and a model error shows most (their rays
  // are then held). In the final test: sigma0 above the limit, or the candidates left (held,
  // vetoed, weakly controlled, at the cap) clustering on one point or one image, each correlated
  // group counted once (one blunder makes its group's w equal, and a rejected blunder is gone).
  void DetectModelError(const Test& t, bool first) {
    std::vector<const TestedObservation*> top;
    for (const auto& x : t.observations)
      if (std::max(x.w_max, x.w_weak) > out_.critical_value &&
          x.verdict != SnoopingVerdict::kRejected)
        top.push_back(&x);
    const auto w_of = [](const TestedObservation* x) { return std::max(x->w_max, x->w_weak); };
    std::sort(top.begin(), top.end(), [&](auto* a, auto* b) { return w_of(a) > w_of(b); });
    if (top.size() > static_cast<size_t>(kModelErrorTop)) top.resize(kModelErrorTop);
    const int n = static_cast<int>(top.size());
    const double limit = o_.model_error_share * n;
    const std::string of = n == 0 ? std::string()
                                  : " of the " + std::to_string(n) + " largest w (" +
                                        Fixed(w_of(top.front()), 1) + " .. " +
                                        Fixed(w_of(top.back()), 1) + ")";
    std::vector<std::string> evidence;
    if (first) {
      int on_report_only = 0;
      for (const auto* x : top)
        on_report_only += x->point >= 0 && report_only_points_.count(x->point);
      if (n >= 2 && on_report_only >= 2 && on_report_only >= limit)
        evidence.push_back(std::to_string(on_report_only) + of + " on the " +
                           o_.report_only_groups.front() + " points");
    } else {
      if (out_.report.sigma0 > o_.model_error_sigma0)
        evidence.push_back("sigma0 " + Fixed(out_.report.sigma0, 2) + " > " +
                           Fixed(o_.model_error_sigma0, 2));
      std::map<BlockId, std::set<ResidualId>> per_point, per_image;  // groups by first member
      for (const auto* x : top) {
        const ResidualId g = *std::min_element(x->correlated.begin(), x->correlated.end());
        if (x->point >= 0) per_point[x->point].insert(g);
        const BlockId image = ImageOf(b_, x->id);
        if (image >= 0) per_image[image].insert(g);
      }
      for (const auto& [point, groups] : per_point)
        if (groups.size() >= 2 && groups.size() >= limit)
          evidence.push_back(std::to_string(groups.size()) + " independent" + of + " on " +
                             b_.BlockName(point));
      for (const auto& [image, groups] : per_image)
        if (groups.size() >= 2 && groups.size() >= limit)
          evidence.push_back(std::to_string(groups.size()) + " independent" + of + " on " +
                             ImageName(b_, image));
    }
    if (evidence.empty()) return;
    out_.model_error_suspected = true;
    out_.model_error_evidence.insert(
        out_.model_error_evidence.end(), evidence.begin(), evidence.end());
    std::string text = "model error suspected, not blunders:";
    for (size_t i = 0; i < evidence.size(); ++i) text += (i ? "; " : " ") + evidence[i];
    out_.findings.push_back(text);
  }

  // A blunder on one control ray looks like a model error in the first test: the largest w sit
  // on that control point's rays (the blunder pulls the point, its other rays follow). Before
  // they are held, the largest-w ray of a control point is removed alone (a group of one, the
  // veto agreeing) and the block re-solved: when no ray of a control point is then above the
  // critical value and sigma0 lies within 1 + kFitBand / sqrt(2 r), it was a blunder: rejected,
  // the suspicion withdrawn, `t` the test without it. Otherwise (a model error leaves the other
  // control rays above k and sigma0 above the band: the conventional flight's C5) it is restored
  // and the rays are held. Returns whether the ray was rejected.
  bool TryControlRayBlunder(Test* t,
                            int round,
                            const SolverOptions& solver,
                            size_t evidence_before,
                            size_t findings_before) {
    const TestedObservation* worst = nullptr;
    for (const auto& x : t->observations)
      if (x.point >= 0 && report_only_points_.count(x.point) &&
          !Contains(o_.report_only_groups, x.group) && x.w_max > out_.critical_value &&
          (!worst || x.w_max > worst->w_max))
        worst = &x;
    if (!worst || worst->correlated.size() > 1) return false;
    if (o_.veto && !o_.veto({worst->id}).empty()) return false;
    TestedObservation ray = *worst;
    const double reference_sigma = out_.reference_sigma;
    b_.RemoveResidual(ray.id);
    Resolve(b_, solver, &out_);
    bool fits = out_.report.usable && out_.report.redundancy > 0;
    Test next;
    if (fits) {
      next = Run(round);
      const double band = 1 + kFitBand / std::sqrt(2.0 * std::max(1, out_.report.redundancy));
      fits = out_.cofactors_ok && out_.report.sigma0 <= band;
      for (const auto& x : next.observations)
        fits &= !(x.point >= 0 && report_only_points_.count(x.point) &&
                  std::max(x.w_max, x.w_weak) > out_.critical_value);
    }
    if (!fits) {
      b_.RestoreResidual(ray.id);
      Resolve(b_, solver, &out_);
      out_.reference_sigma = reference_sigma;  // `t` stands: the solution is back
      return false;
    }
    out_.model_error_suspected = false;
    out_.model_error_evidence.resize(evidence_before);
    out_.findings.resize(findings_before);
    ray.verdict = SnoopingVerdict::kRejected;
    ray.round = round;
    ray.correlated = {ray.id};
    ray.group_size = 1;
    ray.reason =
        "the largest w sat on this control point's rays, as a model error would show; "
        "without this ray every control ray passes and sigma0 " +
        Fixed(out_.report.sigma0, 3) + " is within the band: a blunder";
    out_.findings.push_back("rejected: " + ray.label + " (w = " + Fixed(ray.w_max, 1) +
                            "): " + ray.reason);
    out_.rejected.push_back(ray);
    *t = std::move(next);
    return true;
  }

  void CollectReportOnlyPoints() {
    report_only_points_.clear();
    for (ResidualId id : AllResiduals())
      if (b_.IsActive(id) && Contains(o_.report_only_groups, b_.ResidualGroup(id))) {
        const BlockId p = PointOf(b_, id);
        if (p >= 0) report_only_points_.insert(p);
      }
  }

  // Acts on one round's test; returns the number of removed residuals.
  int Act(Test& t, int round, int budget) {
    std::vector<TestedObservation*> candidates;
    for (auto& x : t.observations)
      if (x.w_max > out_.critical_value) candidates.push_back(&x);
    std::sort(
        candidates.begin(), candidates.end(), [](auto* a, auto* b) { return a->w_max > b->w_max; });
    std::map<BlockId, ResidualId> best_of_point, best_of_image;
    BestOfPointAndImage(t, candidates, &best_of_point, &best_of_image);
    int removed = 0;
    for (auto* x : candidates) {
      if (x->point >= 0 && best_of_point.at(x->point) != x->id) continue;
      const BlockId image = ImageOf(b_, x->id);
      if (image >= 0 && !decided_.count(x->id) && best_of_image.at(image) != x->id) continue;
      if (decided_.count(x->id)) continue;
      if (Contains(o_.report_only_groups, x->group)) {
        Decide(x,
               SnoopingVerdict::kHeld,
               "suspected blunder in the " + x->group + " observation " + x->label +
                   " (w = " + Fixed(x->w_max, 1) + "): check it; it is not rejected");
        continue;
      }
      if (out_.model_error_suspected && x->point >= 0 && report_only_points_.count(x->point)) {
        Decide(x,
               SnoopingVerdict::kHeld,
               "model error suspected: the ray of a " + o_.report_only_groups.front() +
                   " point is kept");
        continue;
      }
      if (removed >= budget) {
        x->verdict = SnoopingVerdict::kLeftAboveCritical;
        x->reason = "rejection cap reached";
        continue;
      }
      const std::vector<ResidualId> acted = ActedGroup(t, *x);
      const std::string veto = o_.veto ? o_.veto(acted) : std::string();
      if (!veto.empty()) {
        Decide(x, SnoopingVerdict::kVetoed, veto);
        continue;
      }
      removed += RejectGroup(t, *x, acted, round);
      x->verdict = SnoopingVerdict::kRejected;
    }
    return removed;
  }

  // The largest w of each point, over every tested observation and its weakly controlled
  // components too (decided ones included: the rays of a point whose survey is suspected, or
  // whose largest w sits on a weakly controlled component, stay), and of each image
  // (undecided candidates only): only those are acted on in a round.
  void BestOfPointAndImage(const Test& t,
                           const std::vector<TestedObservation*>& candidates,
                           std::map<BlockId, ResidualId>* best_of_point,
                           std::map<BlockId, ResidualId>* best_of_image) const {
    std::map<BlockId, std::pair<double, ResidualId>> point_max;
    for (const auto& x : t.observations) {
      if (x.point < 0) continue;
      const double w = std::max(x.w_max, x.w_weak);
      auto [it, added] = point_max.try_emplace(x.point, w, x.id);
      if (!added && w > it->second.first) it->second = {w, x.id};
    }
    for (const auto& [point, best] : point_max) (*best_of_point)[point] = best.second;
    for (auto* x : candidates) {
      const BlockId image = ImageOf(b_, x->id);
      if (image >= 0 && !decided_.count(x->id)) best_of_image->try_emplace(image, x->id);
    }
  }

  // What is rejected with candidate x: the members of its correlated group its other components
  // do not separate from it (joint statistic within k^2; see the header), and the other
  // candidates of its point the data cannot tell from it either (correlated below
  // group_correlation, e.g. strip neighbours at 0.95): rejecting the larger alone names the
  // good one in a share of runs and leaves the blunder on a point too weak to test it.
  std::vector<ResidualId> ActedGroup(const Test& t, const TestedObservation& x) const {
    std::vector<ResidualId> acted;
    const double margin = out_.critical_value * out_.critical_value;
    for (ResidualId member : x.correlated)
      if (member == x.id || x.t_joint - t.observations[t.index.at(member)].t_joint <= margin)
        acted.push_back(member);
    if (x.point >= 0)
      for (const auto& y : t.observations)
        if (y.point == x.point && y.id != x.id && y.w_max > out_.critical_value &&
            x.t_joint - y.t_joint <= margin && !decided_.count(y.id) &&
            !Contains(o_.report_only_groups, y.group) &&
            std::find(acted.begin(), acted.end(), y.id) == acted.end())
          acted.push_back(y.id);
    return acted;
  }

  // Rejects `acted` (x's group) with the reason, removing its residuals; returns their number.
  int RejectGroup(const Test& t,
                  const TestedObservation& x,
                  const std::vector<ResidualId>& acted,
                  int round) {
    std::string reason;
    if (acted.size() > 1) {
      reason = (x.point >= 0 ? b_.BlockName(x.point) : std::string("observation ")) + ": " +
               "one of these " + std::to_string(acted.size()) +
               " observations holds a gross error; they cannot be told apart (|rho| > " +
               Fixed(o_.group_correlation, 2) + "); all are rejected";
      out_.findings.push_back(reason + " (w = " + Fixed(x.w_max, 1) + ")");
    } else if (x.correlated.size() > 1) {
      reason = "its correlated group of " + std::to_string(x.correlated.size()) +
               " is told apart by its other components (joint statistic larger by more than " +
               "k^2): rejected alone";
    }
    for (ResidualId member : acted) {
      TestedObservation r = t.observations[t.index.at(member)];
      r.correlated = acted;
      r.group_size = static_cast<int>(acted.size());
      r.verdict = SnoopingVerdict::kRejected;
      r.round = round;
      r.reason = reason;
      out_.rejected.push_back(r);
      b_.RemoveResidual(member);
    }
    return static_cast<int>(acted.size());
  }

  // The smallest eigenvalue of Q_ii of `x` (its least redundant direction).
  static double SmallestCofactor(const Test& t, const TestedObservation& x) {
    const auto at = t.row_of.find(x.id);
    if (at == t.row_of.end()) return 0.0;
    const int m = static_cast<int>(x.v.size());
    const Eigen::MatrixXd q =
        t.clusters[at->second.first].qvv.block(at->second.second, at->second.second, m, m);
    return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(q).eigenvalues()(0);
  }

  // The state of the survey test across its rounds.
  struct SurveyRun {
    int n_surveys = 0, limit = 0;  // active surveys; at most `limit` of them left out
    std::vector<TestedObservation> left;
    std::string stopped;  // why no (further) survey is left out although one fails
    std::vector<TestedObservation> suspects;  // failing, singled out, but not left out
    bool inseparable = false;                 // the suspects are a group the test cannot tell apart
    bool unsolvable = false;  // the block without the last one left out cannot be solved
  };

  // Surveys first (see the header): leaves out the worst failing report-only observation while
  // the data single it out and that is what makes the others pass; restores them all when not.
  void TestSurveys(const SolverOptions& solver) {
    SurveyRun run;
    for (ResidualId id : AllResiduals())
      run.n_surveys += b_.IsActive(id) && Contains(o_.report_only_groups, b_.ResidualGroup(id));
    run.limit = o_.max_left_out > 0 ? o_.max_left_out : std::max(1, run.n_surveys / 3);
    for (;;) {
      Test t = Run(1);
      if (!out_.cofactors_ok) return;
      std::vector<const TestedObservation*> failing;  // worst first
      for (const auto& x : t.observations)
        if (Contains(o_.report_only_groups, x.group) && x.w_full > out_.critical_value)
          failing.push_back(&x);
      std::sort(
          failing.begin(), failing.end(), [](auto* a, auto* b) { return a->t_full > b->t_full; });
      if (failing.empty()) {  // every remaining survey passes; does the block fit its sigmas?
        const double band = 1 + kFitBand / std::sqrt(2.0 * std::max(1, out_.report.redundancy));
        if (!run.left.empty() && out_.report.sigma0 > band)
          run.stopped = "sigma0 " + Fixed(out_.report.sigma0, 3) + " without it is above " +
                        Fixed(band, 3) + " = 1 + 3 / sqrt(2 r): a model error remains";
        break;
      }
      const TestedObservation& worst = *failing.front();
      if (SurveyStays(t, failing, &run)) break;
      run.left.push_back(worst);
      b_.RemoveResidual(worst.id);
      Resolve(b_, solver, &out_);
      if (!out_.report.usable) {
        run.stopped = "the block without " + worst.label + " cannot be solved";
        run.unsolvable = true;  // it is in `left`: a suspect with those left out before it
        break;
      }
    }
    if (!run.suspects.empty() || run.unsolvable) RecordUnresolvedSurveys(&run);
    if (!run.stopped.empty()) {
      RestoreSurveys(run, solver);
      return;
    }
    for (auto& x : run.left) {
      x.verdict = SnoopingVerdict::kLeftOut;
      x.reason = "suspected blunder in the " + x.group + " observation " + x.label +
                 " (w = " + Fixed(x.w_full, 1) +
                 " over all its components): it disagrees with its rays and " +
                 (out_.unresolved.empty() ? "every other survey passes without it"
                                          : "it fails alone (the unresolved surveys apart)") +
                 "; left out of the adjustment, its rays kept";
      out_.findings.push_back("left out: " + x.reason);
      out_.left_out.push_back(x);
    }
  }

  // Whether the worst failing survey (failing.front()) must stay: it cannot be told from others,
  // its own residual is within k, it alone holds the block, the cap is reached, or the caller
  // vetoes it. Then run->stopped says why, and the suspects are named.
  bool SurveyStays(const Test& t,
                   const std::vector<const TestedObservation*>& failing,
                   SurveyRun* run) const {
    const double k = out_.critical_value, s = out_.reference_sigma;
    const TestedObservation& worst = *failing.front();
    // Surveys the test cannot tell from the worst: chi-square within k^2 (the likelihood ratio
    // of the two explanations above exp(-k^2 / 2), the test's own tail).
    std::string group;
    int together = 0;
    for (const auto* x : failing)
      if (worst.t_full - x->t_full <= k * k) {
        group += (together++ ? ", " : "") + x->label + " (w = " + Fixed(x->w_full, 1) + ")";
      }
    double largest_v = 0.0;  // the survey's own residual, in sigmas
    for (double v : worst.v) largest_v = std::max(largest_v, std::abs(v) / s);
    const double holds = SmallestCofactor(t, worst);
    std::string& stopped = run->stopped;
    if (together > 1) {
      stopped = "the surveys " + group +
                " fail and the test cannot tell them apart (their chi-square statistics lie "
                "within k^2 = " +
                Fixed(k * k, 1) + "): one of them may be off";
      for (const auto* x : failing)
        if (worst.t_full - x->t_full <= k * k) run->suspects.push_back(*x);
      run->inseparable = true;
    } else if (largest_v <= k) {
      stopped = worst.label + " fails (w = " + Fixed(worst.w_full, 1) +
                " over all its components) but its residual is " + Fixed(largest_v, 1) +
                " sigma, within the critical value: the disagreement lies in a direction the "
                "block bends to fit (r < " +
                Fixed(o_.min_redundancy, 2) + "), where a model error looks the same";
    } else if (holds < kHoldsTheBlock) {
      stopped = worst.label + " fails (w = " + Fixed(worst.w_full, 1) +
                ") but it alone holds the block in one direction (redundancy " + Fixed(holds, 6) +
                "): without it the block would be loose there";
    } else if (static_cast<int>(run->left.size()) >= run->limit) {
      stopped = worst.label + " still fails (w = " + Fixed(worst.w_full, 1) + "); at most " +
                std::to_string(run->limit) + " of the " + std::to_string(run->n_surveys) +
                " surveys are left out";
    } else if (const std::string veto = o_.veto ? o_.veto({worst.id}) : std::string();
               !veto.empty()) {
      stopped = worst.label + " fails (w = " + Fixed(worst.w_full, 1) + "); " + veto;
    }
    if (stopped.empty()) return false;
    if (run->suspects.empty() && largest_v > k) run->suspects.push_back(worst);
    return true;
  }

  // Suspects it cannot leave out: not a fit, named as unresolved.
  void RecordUnresolvedSurveys(SurveyRun* run) {
    out_.unresolved_reason = run->stopped;
    if (run->inseparable && !run->left.empty()) {
      // Those singled out before a group the test cannot tell apart stay out (each failed
      // alone, beyond k sigmas; putting it back would bend the block by its blunder too):
      // both are named, and the caller's run is not a fit.
      out_.findings.push_back("surveys tested first: " + run->stopped +
                              ": these surveys are kept, named as unresolved");
      run->stopped.clear();
    } else {  // every survey is restored below: those left out before are suspects as well
      run->suspects.insert(run->suspects.begin(), run->left.begin(), run->left.end());
    }
    out_.unresolved = std::move(run->suspects);
  }

  // Not a survey blunder the data single out: every survey stays (those left out restored).
  void RestoreSurveys(const SurveyRun& run, const SolverOptions& solver) {
    std::string names;
    for (const auto& x : run.left) names += (names.empty() ? "" : ", ") + x.label;
    if (!run.left.empty()) {
      for (const auto& x : run.left) b_.RestoreResidual(x.id);
      Resolve(b_, solver, &out_);
    }
    out_.findings.push_back("surveys tested first: " + run.stopped +
                            (run.left.empty() ? std::string()
                                              : "; leaving out " + names +
                                                    " (w = " + Fixed(run.left.front().w_full, 1) +
                                                    ") did not make the block fit") +
                            ": every survey kept (a survey blunder, or a model error)");
  }

  void Decide(TestedObservation* x, SnoopingVerdict verdict, const std::string& reason) {
    x->verdict = verdict;
    x->reason = reason;
    if (decided_.emplace(x->id, std::make_pair(verdict, reason)).second &&
        verdict != SnoopingVerdict::kLeftAboveCritical)
      out_.findings.push_back(std::string(VerdictName(verdict)) + ": " + x->label +
                              " (w = " + Fixed(x->w_max, 1) + "): " + reason);
  }

 private:
  ProblemBuilder& b_;
  const SnoopingOptions& o_;
  SnoopingOutcome& out_;
  std::set<BlockId> report_only_points_;
  std::map<ResidualId, std::pair<SnoopingVerdict, std::string>> decided_;
  bool initialized_ = false;  // the critical value is fixed by the first test
};

}  // namespace

const char* VerdictName(SnoopingVerdict verdict) {
  switch (verdict) {
    case SnoopingVerdict::kAccepted:
      return "accepted";
    case SnoopingVerdict::kRejected:
      return "rejected";
    case SnoopingVerdict::kWeaklyControlled:
      return "weakly controlled";
    case SnoopingVerdict::kVetoed:
      return "vetoed";
    case SnoopingVerdict::kHeld:
      return "held";
    case SnoopingVerdict::kLeftAboveCritical:
      return "left above critical";
    case SnoopingVerdict::kLeftOut:
      return "left out";
  }
  return "?";
}

double NonCentrality(double critical_value, double power) {
  // z(power): P(N(0,1) > z) = 1 - power, i.e. the two-sided value of 2 (1 - power).
  return critical_value + NormalCriticalValue(2.0 * (1.0 - power));
}

double NonCentralityJoint(double critical_value, double power) {
  // P(chi2(2, lambda) > t) = sum_j Poisson(j; lambda / 2) P(chi2(2 + 2j) > t), with
  // P(chi2(2m) > t) = exp(-t / 2) sum_{i < m} (t / 2)^i / i!; bisection on lambda.
  const double p = std::erfc(critical_value / std::sqrt(2.0));
  const double half_t = -std::log(p);  // t / 2
  const auto tail = [&](double lambda) {
    const double h = lambda / 2;
    double sum = 0.0, central = 0.0, term = std::exp(-half_t);  // term: (t/2)^i / i! e^{-t/2}
    double poisson = std::exp(-h);
    for (int j = 0; j < 2000; ++j) {
      central += term;  // P(chi2(2 (j + 1)) > t)
      sum += poisson * central;
      term *= half_t / (j + 1);
      poisson *= h / (j + 1);
      if (j > h && poisson < 1e-18) break;
    }
    return sum;
  };
  double lo = 0.0, hi = 4 * (critical_value + 10) * (critical_value + 10);
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (tail(mid) < power ? lo : hi) = mid;
  }
  return std::sqrt(0.5 * (lo + hi));
}

SnoopingOutcome SolveWithDataSnooping(ProblemBuilder& builder,
                                      const SolverOptions& solver,
                                      const SnoopingOptions& options,
                                      const SolveReport* solved) {
  AEROCAL_CHECK(options.alpha > 0 && options.alpha < 1) << "snooping alpha " << options.alpha;
  AEROCAL_CHECK(options.power > 0.5 && options.power < 1) << "snooping power " << options.power;
  AEROCAL_CHECK(options.max_rejections > 0) << "max_rejections " << options.max_rejections;
  SnoopingOutcome out;
  Snooper snooper(builder, options, &out);
  if (solved) {
    out.report = *solved;
  } else {
    Resolve(builder, solver, &out);
  }
  if (options.leave_out_report_only && !options.report_only_groups.empty() && out.report.usable &&
      out.report.redundancy > 0)
    snooper.TestSurveys(solver);
  snooper.CollectReportOnlyPoints();
  int removed_total = 0;
  for (int round = 1; out.report.usable && out.report.redundancy > 0; ++round) {
    out.rounds = round;
    Test test = snooper.Run(round);
    if (round == 1) {
      const size_t evidence = out.model_error_evidence.size(), findings = out.findings.size();
      snooper.DetectModelError(test, true);
      if (out.model_error_evidence.size() > evidence &&
          snooper.TryControlRayBlunder(&test, round, solver, evidence, findings))
        ++removed_total;
    }
    if (test.observations.empty()) break;
    const int budget = options.max_rejections - removed_total;
    const int removed = budget > 0 ? snooper.Act(test, round, budget) : 0;
    removed_total += removed;
    // Weakly controlled observations above the critical value: named, never rejected.
    for (auto& x : test.observations)
      if (x.verdict == SnoopingVerdict::kAccepted && x.w_weak > out.critical_value) {
        x.verdict = SnoopingVerdict::kWeaklyControlled;
        x.reason = "w " + Fixed(x.w_weak, 1) + " on a component with r < " +
                   Fixed(options.min_redundancy, 2) + ": a blunder there is barely visible";
      }
    if (removed == 0) {
      for (auto& x : test.observations)
        if (x.verdict == SnoopingVerdict::kAccepted && x.w_max > out.critical_value) {
          if (budget > 0) {  // not the largest of its point / image: a held or vetoed one is
            x.verdict = SnoopingVerdict::kHeld;
            x.reason =
                "its point or image holds a larger w that is held, vetoed or weakly controlled";
            continue;
          }
          x.verdict = SnoopingVerdict::kLeftAboveCritical;
          x.reason = "rejection cap reached";
        }
      for (const auto& x : test.observations)
        if (x.verdict == SnoopingVerdict::kLeftAboveCritical) ++out.remaining_above_critical;
      out.cap_reached = budget <= 0 && out.remaining_above_critical > 0;
      if (out.cap_reached)
        out.findings.push_back("rejection cap of " + std::to_string(options.max_rejections) +
                               " reached: " + std::to_string(out.remaining_above_critical) +
                               " candidate(s) left above the critical value " +
                               Fixed(out.critical_value, 2));
      snooper.DetectModelError(test, false);
      out.tested = std::move(test.observations);
      break;
    }
    Resolve(builder, solver, &out);
  }
  return out;
}

}  // namespace aerocal::calib
