// Which interior parameters a block can calibrate (`--self-calibration auto`, issue 28): free only
// what the block determines and what is significant, by backward elimination as DBAT's
// significance testing and Metashape's adaptive fitting do.
//
// From the candidate set (the camera model's parameters, or a list), one parameter at a time is
// held at the camera file's value and the block re-adjusted, until every free parameter passes:
//  1. determinable: not in the normal matrix's null space, and no correlation above
//     `correlation_limit` with a parameter outside the camera (an exposure's centre or angles,
//     the platform): such a parameter is not calibrated by this block but traded against the
//     orientation (c ~ the flying heights without GNSS over flat ground). The worst goes first.
//  2. significant: t = |estimate - camera file| / sigma above the two-sided normal critical value
//     of the family-wise level `alpha` over the candidates (Bonferroni: alpha / k for k
//     candidates, 2.81 for ten at 5 %): k parameters are tested at once, and a per-parameter 5 %
//     lets one in two of ten null parameters through by chance. The least significant goes first.
//     Interior parameters correlated among themselves (K1, K2, K3) are not held for that: they are
//     judged by significance.
// Every held parameter is named with its reason and statistic (FreeSetChoice::held).
//
// The check-point test (CheckPointComparison): with check points, a self-calibrated run whose
// check errors are significantly larger than the conventional run's (F = sum|e_self|^2 /
// sum|e_conv|^2 over the common check points against F(1 - alpha; 3n, 3n)) does not calibrate the
// camera: the flight writes no camera and marks the result invalid. The two runs share the points
// and most observations, so their errors are positively correlated and the F test is
// conservative (it calls a difference significant later than independent samples would).
#pragma once

#include "calib/core/progress.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct KeptAdjustment;

struct FreeSetChoiceOptions {
  double alpha = 0.05;              // family-wise level of the significance tests, (0, 1)
  double correlation_limit = 0.95;  // (0, 1)
};

/// Adjusts `project` with options.free_interior as the candidates, holding parameters as the
/// header says until every free one is determinable and significant. The returned result is the
/// adjustment with the chosen set; its `free_set_choice` says what was held and why. `progress`
/// (may be null) advances by AutoFreeSetRounds(options) units: one per round, the rest at the end.
/// `keep`: the last round's adjustment, as Adjust() keeps it.
AdjustmentResult AdjustWithChosenFreeSet(const Project& project,
                                         const AdjustOptions& options,
                                         const FreeSetChoiceOptions& choice = {},
                                         Progress* progress = nullptr,
                                         KeptAdjustment* keep = nullptr);
/// The most rounds AdjustWithChosenFreeSet can take: one per candidate held, plus the final one.
inline int AutoFreeSetRounds(const AdjustOptions& options) {
  return static_cast<int>(options.free_interior.size()) + 1;
}

/// The check-point test of the header: `worse` when the self-calibrated run's check errors are
/// significantly larger (alpha one-sided) than the conventional run's on their common points.
struct CheckPointComparison {
  int n = 0;  // common check points
  double f = 0, f_critical = 0, alpha = 0.05;
  bool tested = false;  // n >= 1 and the conventional errors are not all zero
  bool worse = false;
  std::string message;
};
CheckPointComparison CompareCheckPoints(const AdjustmentResult& conventional,
                                        const AdjustmentResult& self_calibrated,
                                        double alpha = 0.05);

}  // namespace aerocal::triangulation
