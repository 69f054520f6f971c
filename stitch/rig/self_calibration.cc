// The self-calibrating rig stitching's modes and driver (self_calibration.h); its steps are in
// self_calibration_problem.h (set-up, solve, figures) and its result file in
// self_calibration_json.cc.
#include "stitch/rig/self_calibration.h"

#include "calib/core/error.h"
#include "calib/core/stopwatch.h"
#include "stitch/rig/self_calibration_problem.h"

namespace aerocal::stitch {

std::optional<RigStitchMode> ParseRigStitchMode(const std::string& name) {
  if (name == "line") return RigStitchMode::kLine;
  if (name == "per-exposure") return RigStitchMode::kPerExposure;
  if (name == "angles") return RigStitchMode::kAngles;
  return std::nullopt;
}

const char* RigStitchModeName(RigStitchMode mode) {
  switch (mode) {
    case RigStitchMode::kLine:
      return "line";
    case RigStitchMode::kPerExposure:
      return "per-exposure";
    case RigStitchMode::kAngles:
      return "angles";
  }
  return "?";
}

// The steps in order (self_calibration_problem.h): the problem, the solve with snooping, the
// precision, then the results and figures at the final solution.
RigStitchResult SelfCalibrateRigStitching(const calib::Rig& rig,
                                          const std::vector<RigStitchExposure>& exposures,
                                          const std::vector<RigStitchTie>& ties,
                                          const std::vector<RigStitchObservation>& observations,
                                          const std::vector<StandardPosition>& positions,
                                          const RigStitchOptions& options) {
  using namespace internal;  // the steps (self_calibration_problem.h)
  AEROCAL_CHECK(rig.virtual_camera.orientation == calib::VirtualOrientation::kLevel)
      << "the self-calibrating stitching makes the level (horizontal) virtual image";
  const Stopwatch call;
  RigStitchProblem p(rig, exposures, ties, observations, positions, options);
  AddHeadBlocks(p);
  DecideTimeOffsets(p);
  AddExposureBlocks(p);
  AddTies(p);
  p.result.profile.setup_s = call.Seconds();
  const std::vector<calib::ResidualId> kept_against_test = SolveWithSnooping(p);
  EstimatePrecision(p, kept_against_test);
  const Stopwatch figures;
  const std::vector<RigExposure> refined = CollectHeads(p);
  StitchingRms(p, refined);
  CountStandardPositions(p);
  ReliefDisplacement(p);
  Sigma0InPixels(p);
  JudgeRun(p);
  p.result.profile.figures_s = figures.Seconds();
  p.result.profile.total_s = call.Seconds();
  return std::move(p.result);
}

}  // namespace aerocal::stitch
