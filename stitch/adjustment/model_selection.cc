#include "stitch/adjustment/model_selection.h"

#include "calib/core/error.h"
#include "stitch/adjustment/f_distribution.h"

#include <cstdio>

namespace aerocal::stitch {

const FrameAdjustment& ModelChoice::Chosen() const {
  for (const auto& c : candidates)
    if (c.model == chosen) return c.adjustment;
  throw LogicError("model choice without the chosen candidate");
}

ModelChoice ChooseModel(const calib::Camera& camera,
                        const FrameMeasurements& frame,
                        const StitchOptions& options,
                        double alpha) {
  ModelChoice choice;
  choice.alpha = alpha;
  char text[256];
  std::snprintf(
      text, sizeof(text), "F test of the variance ratio between nested models, alpha %g", alpha);
  choice.test = text;
  int richest = -1;
  for (calib::MappingModel model : calib::kAllMappingModels) {
    ModelCandidate c;
    c.model = model;
    c.refusal = FindUnderdetermined(camera, frame, model, options);
    c.determinable = c.refusal.empty();
    if (c.determinable) richest = static_cast<int>(choice.candidates.size());
    choice.candidates.push_back(std::move(c));
  }
  if (richest < 0) throw InputError(choice.candidates.front().refusal);

  // Gross errors with the richest model; the same observations are left out of every candidate.
  ModelCandidate& rich = choice.candidates[richest];
  rich.adjustment = AdjustFrame(camera, frame, rich.model, options);
  choice.rejected = rich.adjustment.rejected;
  std::set<ObservationKey> excluded;
  for (const auto& r : choice.rejected) excluded.insert({r.point, r.subimage});
  StitchOptions plain = options;
  plain.data_snooping = false;
  for (int i = 0; i < richest; ++i) {
    ModelCandidate& c = choice.candidates[i];
    if (!c.determinable) continue;
    // Leaving the rejected observations out can make a model under-determined again.
    c.refusal = FindUnderdetermined(camera, frame, c.model, options, excluded);
    c.determinable = c.refusal.empty();
    if (!c.determinable) continue;
    c.adjustment = AdjustFrame(camera, frame, c.model, plain, excluded);
    c.adjustment.rejected = choice.rejected;
  }

  // Sequential F tests, simplest first.
  const ModelCandidate* accepted = nullptr;
  std::string reason;
  for (ModelCandidate& c : choice.candidates) {
    if (!c.determinable) continue;
    if (!accepted) {
      accepted = &c;
      reason =
          std::string(calib::MappingModelName(c.model)) + " is the simplest determinable model";
      continue;
    }
    const FrameAdjustment& s = accepted->adjustment;
    const FrameAdjustment& r = c.adjustment;
    c.tested = true;
    c.against = std::string(calib::MappingModelName(accepted->model));
    c.df1 = s.redundancy - r.redundancy;
    c.df2 = r.redundancy;
    if (c.df1 <= 0 || c.df2 <= 0 || r.vtpv <= 0) {
      c.tested = false;
      break;
    }
    c.f = ((s.vtpv - r.vtpv) / c.df1) / (r.vtpv / c.df2);
    c.f_critical = FDistributionQuantile(1.0 - alpha, c.df1, c.df2);
    c.p_value = 1.0 - FDistributionCdf(c.f, c.df1, c.df2);
    c.significant = c.f > c.f_critical;
    std::snprintf(text,
                  sizeof(text),
                  "; %s against %s: F = %.3g %s F(%g; %d, %d) = %.3g",
                  std::string(calib::MappingModelName(c.model)).c_str(),
                  c.against.c_str(),
                  c.f,
                  c.significant ? ">" : "<=",
                  1.0 - alpha,
                  c.df1,
                  c.df2,
                  c.f_critical);
    reason += text;
    reason += c.significant ? " (significant: accepted)" : " (not significant: stop)";
    if (!c.significant) break;
    accepted = &c;
  }
  choice.chosen = accepted->model;
  choice.reason = reason + "; chosen: " + std::string(calib::MappingModelName(choice.chosen));
  return choice;
}

}  // namespace aerocal::stitch
