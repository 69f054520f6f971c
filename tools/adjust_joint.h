// `aerocal adjust --joint-stitching per-flight|per-exposure`: the joint stitching + triangulation
// adjustment (triangulation/joint) of a project measured in raw sub-image pixels. Its options and
// its run, kept beside cmd_adjust.cc so that the plain adjustment's code stays as it is.
#pragma once

#include "tools/project_facts.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <functional>
#include <string>

namespace aerocal::tools {

struct JointAdjustArgs {
  std::string stitching;       // --joint-stitching: per-flight | per-exposure; empty: no joint run
  std::string model = "auto";  // --joint-model
  std::string base;            // --base: comma-separated datum sub-images
  double stitch_sigma_px = 0.1;
  bool Requested() const { return !stitching.empty(); }
};

/// OUT.yaml for a single camera, OUT_<id>.yaml for each of several (--write-camera).
std::string CameraOutputPath(const std::string& out, const std::string& id, bool several);

/// The end of every `adjust` run (plain, joint, rig): writes the result JSON to `out` (atomically,
/// also when not valid: `valid: false` and its reasons), prints each reason, and calls
/// `write_cameras` only when `write_camera` is set and the result is valid: a camera file that
/// exists is one the next flight may use; otherwise says "<camera_kind> not written". Returns the
/// exit code: 0 valid, 3 not valid (AdjustmentResult::valid).
int FinishAdjust(const triangulation::AdjustmentResult& result,
                 nlohmann::json json,
                 const std::string& out,
                 const std::string& write_camera,
                 const std::string& camera_kind,
                 const std::function<void()>& write_cameras);

/// Adds --joint-stitching, --joint-model, --base and --stitch-sigma-px (the last three need the
/// first).
void AddJointAdjustOptions(CLI::App& app, JointAdjustArgs* args);

/// Runs the joint adjustment of the project `input` (read from `project_path`, the command line's
/// platform options applied) with `options` (free interior, snooping, priors),
/// prints the summary, writes the result JSON to `out` and, when `write_camera` is set and the
/// result is valid, the camera with the refined interior and per-flight mappings. Returns the exit
/// code (0, or 3 when the result is not valid: AdjustmentResult::valid). ConfigError for
/// --robust-start, InputError for a project without sub-image observations.
int RunJointAdjust(const JointAdjustArgs& joint,
                   const triangulation::AdjustOptions& options,
                   const triangulation::Project& input,
                   const std::string& project_path,
                   const std::string& out,
                   const std::string& write_camera);

}  // namespace aerocal::tools
