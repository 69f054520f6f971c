#include "tools/rig_adjust_run.h"

#include "calib/core/error.h"
#include "calib/problem/mounted_block.h"
#include "tools/project_facts.h"
#include "triangulation/georef/object_frame.h"

#include <cmath>

namespace aerocal::tools {

void CheckRigProject(const triangulation::Project& input,
                     const std::string& project_path,
                     bool compare,
                     bool auto_free,
                     bool robust_start) {
  const std::string rig = "rig project (camera '" + input.rigs.begin()->first + "')";
  if (compare)
    throw ConfigError("--compare: not available for a " + rig +
                      ": its conventional reference "
                      "run is a frame-camera adjustment (run adjust with and without "
                      "--self-calibration instead)");
  if (auto_free)
    throw ConfigError("--self-calibration auto: not available for a " + rig +
                      " (give the "
                      "parameters to calibrate)");
  if (robust_start)
    throw ConfigError("--robust-start: not available for a " + rig +
                      ": the robust start "
                      "re-adjusts frame cameras only (reject blunders with data snooping, the "
                      "default)");
  if (input.rigs.size() > 1) {
    std::string names;
    for (const auto& [id, unused] : input.rigs) names += (names.empty() ? "" : ", ") + id;
    throw ConfigError(project_path + ": rig cameras " + names +
                      ": the rig bundle takes one "
                      "rig per project (adjust each rig's exposures in a project of its own)");
  }
}

RigAdjustRun RunRigAdjust(const RigAdjustRequest& request,
                          const triangulation::AdjustOptions& options,
                          const triangulation::Project& input,
                          const std::string& project_path,
                          bool project_facts) {
  triangulation::RigAdjustOptions rig;
  rig.mounts = calib::BlockModeOption(request.mounts, "--rig-mounts");
  rig.lever_arms = calib::BlockModeOption(request.lever_arms, "--rig-lever-arms");
  rig.increments = calib::BlockModeOption(request.increments, "--rig-increments");
  rig.time_offsets = calib::BlockModeOption(request.time_offsets, "--rig-time-offsets");
  rig.increment_sigma_rad = request.increment_sigma_arcsec * M_PI / (180.0 * 3600.0);
  rig.time_offset_sigma_s = request.time_offset_sigma_ms * 1e-3;
  rig.Validate();

  // Adjusted in the object frame (a local Cartesian frame for geographic input), reported in
  // the input frame, as the frame-camera adjustment.
  const triangulation::ObjectFrame frame(input.frame);
  const triangulation::Project project = triangulation::ToAdjustmentFrame(input, frame);
  RigAdjustRun run;
  run.result = triangulation::AdjustRig(project, options, rig);
  triangulation::ToInputFrame(frame, &run.result.adjustment);
  run.printed = triangulation::FormatSummary(run.result.adjustment) +
                triangulation::FormatRigSummary(run.result);
  run.json = triangulation::AdjustmentToJson(run.result.adjustment);
  run.json.update(triangulation::RigResultToJson(run.result));
  run.json["project"] = project_path;
  if (project_facts) AddProjectFacts(input, &run.json);
  run.json["valid"] = run.result.adjustment.valid;
  run.json["invalid_reasons"] = run.result.adjustment.invalid_reasons;
  return run;
}

}  // namespace aerocal::tools
