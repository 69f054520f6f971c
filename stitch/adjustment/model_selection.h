// Choice of the sub-image mapping model of a frame by a statistical test, never by the lowest
// sigma0 alone (a richer model always fits a little better).
//
// The models are nested: translation (2) < conformal (4) < affine (6) < projective (8) parameters
// per free sub-image. Procedure:
// 1. every model is checked for determinability (FindUnderdetermined); refused models are listed
//    with the reason and left out;
// 2. gross errors are searched (data snooping) with the richest determinable model, which fits
//    whatever the simpler ones fit, and the same observations are removed from every candidate so
//    that all models are compared on identical observations;
// 3. starting from the simplest determinable model, the next richer model is accepted when the
//    F test of the variance ratio (f_distribution.h) is significant at level alpha (default 5 %):
//      F = ((vtpv_s - vtpv_c) / (r_s - r_c)) / (vtpv_c / r_c) > F(1 - alpha; r_s - r_c, r_c);
//    the first non-significant step stops the search. Each decision is one test at level alpha,
//    so a model that is right is kept with probability 1 - alpha.
#pragma once

#include "stitch/adjustment/stitch_adjustment.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

struct ModelCandidate {
  calib::MappingModel model = calib::MappingModel::kAffine;
  bool determinable = false;
  std::string refusal;         // why not, when !determinable
  FrameAdjustment adjustment;  // when determinable
  // F test against the model accepted before it (tested only when that one exists).
  bool tested = false;
  std::string against;  // name of the simpler model
  double f = 0, f_critical = 0, p_value = 1;
  int df1 = 0, df2 = 0;
  bool significant = false;
};

struct ModelChoice {
  calib::MappingModel chosen = calib::MappingModel::kAffine;
  std::string test;  // the named test and its level
  double alpha = 0.05;
  std::string reason;                         // human-readable decision
  std::vector<ModelCandidate> candidates;     // all four models, simplest first
  std::vector<RejectedObservation> rejected;  // gross errors, found with the richest model
  const FrameAdjustment& Chosen() const;
};

/// Adjusts `frame` with every determinable model and chooses one (see above). Throws InputError
/// with the reason for the simplest model when no model is determinable.
ModelChoice ChooseModel(const calib::Camera& camera,
                        const FrameMeasurements& frame,
                        const StitchOptions& options,
                        double alpha = 0.05);

}  // namespace aerocal::stitch
