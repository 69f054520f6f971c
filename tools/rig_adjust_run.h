// `aerocal adjust` of a project whose camera file has a `rig` section (the rig bundle,
// triangulation/sensor/rig_head_camera.h) as one request and one run: shared by the command
// (tools/cmd_adjust.cc, which writes the result and the rig file) and Python's `aerocal.adjust`
// of such a block (tools/python/bind_adjust.cc).
#pragma once

#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/block/block_io.h"
#include "triangulation/sensor/rig_head_camera.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::tools {

/// The --rig-* options as given (modes fixed | free | weighted; sigmas in the options' units).
struct RigAdjustRequest {
  std::string mounts = "free", lever_arms = "free", increments = "fixed", time_offsets = "fixed";
  double increment_sigma_arcsec = 0.0, time_offset_sigma_ms = 0.0;
};

struct RigAdjustRun {
  triangulation::RigAdjustmentResult result;  // in the project's input frame
  nlohmann::json json;  // the result document without `kind`, valid and invalid_reasons set
  std::string printed;  // what the command prints on stdout
};

/// The refusals of a rig project: the rig bundle takes one rig and no frame-camera-only run
/// (--compare, --self-calibration auto, --robust-start). ConfigError naming the option.
void CheckRigProject(const triangulation::Project& input,
                     const std::string& project_path,
                     bool compare,
                     bool auto_free,
                     bool robust_start);

/// The rig options read and checked (ConfigError naming the --rig-* option), the rig bundle run
/// in the project's object frame and brought back to its input frame, the result document built
/// (`project` = project_path, the project's facts when read from files).
RigAdjustRun RunRigAdjust(const RigAdjustRequest& request,
                          const triangulation::AdjustOptions& options,
                          const triangulation::Project& input,
                          const std::string& project_path,
                          bool project_facts = true);

}  // namespace aerocal::tools
