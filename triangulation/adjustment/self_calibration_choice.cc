#include "triangulation/adjustment/self_calibration_choice.h"

#include "calib/core/csv.h"
#include "calib/core/log.h"
#include "stitch/adjustment/f_distribution.h"
#include "triangulation/adjustment/block_adjustment.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

namespace aerocal::triangulation {
namespace {

constexpr const char* kCameraPrefix = "camera ";

// "camera cam1.c" -> "c" when it names an interior parameter, else "".
std::string InteriorName(const std::string& covariance_name) {
  if (covariance_name.rfind(kCameraPrefix, 0) != 0) return "";
  const size_t dot = covariance_name.rfind('.');
  return dot == std::string::npos ? "" : covariance_name.substr(dot + 1);
}

bool IsFree(const std::vector<std::string>& free, const std::string& name) {
  return !name.empty() && std::find(free.begin(), free.end(), name) != free.end();
}

// Rule 1 of the header: a free parameter in the null space, else the free interior parameter most
// correlated (above the limit) with a parameter outside the camera.
std::optional<FreeSetChoice::Held> NotDeterminable(const AdjustmentResult& r,
                                                   const std::vector<std::string>& free,
                                                   double limit) {
  for (const std::string& u : r.determinability.undetermined)
    if (IsFree(free, InteriorName(u)))
      return FreeSetChoice::Held{
          InteriorName(u), "not determinable (null space of the normal matrix)", 0.0, "", 0};
  std::optional<FreeSetChoice::Held> worst;
  for (const auto& h : r.determinability.high_correlations) {
    const std::string a = InteriorName(h.a), b = InteriorName(h.b);
    const double rho = std::abs(h.correlation);
    if (rho <= limit || (!a.empty() && !b.empty())) continue;  // interior pairs: significance
    const std::string& p = a.empty() ? b : a;
    if (!IsFree(free, p) || (worst && worst->statistic >= rho)) continue;
    worst = FreeSetChoice::Held{
        p, "not determinable (traded against the orientation)", rho, a.empty() ? h.a : h.b, 0};
  }
  return worst;
}

// Rule 2: the least significant free parameter, t = |estimate - camera file| / sigma (the largest
// over the block's cameras), when below `t_critical`.
std::optional<FreeSetChoice::Held> LeastSignificant(const AdjustmentResult& r,
                                                    const std::vector<std::string>& free,
                                                    double t_critical) {
  std::map<std::string, double> t_of;
  for (const auto& camera : r.cameras) {
    const std::vector<calib::ParamInfo> table = calib::CameraModelParams(camera.model);
    for (size_t k = 0; k < table.size(); ++k) {
      const std::string name(table[k].name);
      if (!IsFree(free, name) || !(camera.sigma[k] > 0)) continue;
      const double t = std::abs(camera.estimated[k] - camera.initial[k]) / camera.sigma[k];
      t_of[name] = std::max(t_of.count(name) ? t_of[name] : 0.0, t);
    }
  }
  std::optional<FreeSetChoice::Held> least;
  for (const std::string& name : free) {  // candidate order decides ties
    const auto t = t_of.find(name);
    if (t == t_of.end() || t->second >= t_critical) continue;
    if (!least || t->second < least->statistic)
      least = FreeSetChoice::Held{name, "not significant", t->second, "", 0};
  }
  return least;
}

}  // namespace

AdjustmentResult AdjustWithChosenFreeSet(const Project& project,
                                         const AdjustOptions& options,
                                         const FreeSetChoiceOptions& choice_options,
                                         Progress* progress,
                                         KeptAdjustment* keep) {
  FreeSetChoice choice;
  choice.candidates = options.free_interior;
  choice.significance_t = calib::NormalCriticalValue(
      choice_options.alpha / std::max<size_t>(1, options.free_interior.size()));
  choice.correlation_limit = choice_options.correlation_limit;
  AdjustOptions o = options;
  for (int round = 1;; ++round) {
    AdjustmentResult r = Adjust(project, o, nullptr, keep);
    choice.rounds = round;
    std::optional<FreeSetChoice::Held> held;
    // Without a solution or a covariance nothing can be judged: the result says why.
    if (!o.free_interior.empty() && r.converged() &&
        (r.determinability.covariance_ok || !r.determinability.undetermined.empty())) {
      held = NotDeterminable(r, o.free_interior, choice_options.correlation_limit);
      if (!held && r.determinability.covariance_ok)
        held = LeastSignificant(r, o.free_interior, choice.significance_t);
    }
    if (!held) {
      // The rounds left unused (at most one per candidate, plus the last): the bar completes.
      if (progress) progress->Advance(AutoFreeSetRounds(options) - round + 1);
      choice.chosen = o.free_interior;
      std::string list;
      for (const auto& h : choice.held) list += (list.empty() ? "" : ", ") + h.parameter;
      r.notes.push_back("--self-calibration auto: " + std::to_string(choice.chosen.size()) +
                        " of " + std::to_string(choice.candidates.size()) +
                        " parameters calibrated" +
                        (list.empty() ? "" : "; held at the camera file's values: " + list) +
                        " (self_calibration_choice)");
      r.free_set_choice = choice;
      return r;
    }
    held->round = round;
    LogInfo("self-calibration auto, round " + std::to_string(round) + ": " + held->parameter +
            " held (" + held->reason + ", " + FormatNumber(held->statistic, 3) +
            (held->with.empty() ? "" : " with " + held->with) + ")");
    choice.held.push_back(*held);
    if (progress) progress->Advance();
    o.free_interior.erase(
        std::find(o.free_interior.begin(), o.free_interior.end(), held->parameter));
  }
}

CheckPointComparison CompareCheckPoints(const AdjustmentResult& conventional,
                                        const AdjustmentResult& self_calibrated,
                                        double alpha) {
  CheckPointComparison c;
  c.alpha = alpha;
  std::map<std::string, Eigen::Vector3d> conv;
  for (const auto& d : conventional.check_points) conv[d.point] = d.difference_m;
  double ss_conv = 0.0, ss_self = 0.0;
  for (const auto& d : self_calibrated.check_points) {
    const auto it = conv.find(d.point);
    if (it == conv.end()) continue;
    ++c.n;
    ss_conv += it->second.squaredNorm();
    ss_self += d.difference_m.squaredNorm();
  }
  if (c.n == 0 || !(ss_conv > 0)) {
    c.message = c.n == 0 ? "no common check points: not tested" : "conventional check errors are 0";
    return c;
  }
  c.tested = true;
  c.f = ss_self / ss_conv;
  c.f_critical = stitch::FDistributionQuantile(1.0 - alpha, 3.0 * c.n, 3.0 * c.n);
  c.worse = c.f > c.f_critical;
  c.message = "check points (n = " + std::to_string(c.n) +
              "): sum|e|^2 self-calibrated / conventional F = " + FormatNumber(c.f, 4) +
              (c.worse ? " > " : " <= ") + FormatNumber(c.f_critical, 4) + " = F(" +
              FormatNumber(1 - alpha, 3) + "; " + std::to_string(3 * c.n) + ", " +
              std::to_string(3 * c.n) + ")" +
              (c.worse ? ": the self-calibrated camera makes the check points significantly worse"
                       : ": not significantly worse");
  return c;
}

}  // namespace aerocal::triangulation
