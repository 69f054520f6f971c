// The flight workflow a calibration lab runs on one flight of a multi-CCD camera
// (`aerocal flight`):
//   1. per-exposure stitching with model comparison (F test) and the flight's stability;
//   2. conventional triangulation, then self-calibrating triangulation (10 parameters), then the
//      joint stitching + triangulation adjustment (when raw sub-image observations exist) with
//      the mapping model the flight's stitching chose (or the one given), starting from the
//      stitching's flight-mean mappings;
//   3. one result document (kind "flight") holding every step's FORMATS.md result, and the
//      calibrated camera for the next flight.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/adjustment/flight_stability.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace aerocal {
class Progress;
}

namespace aerocal::triangulation {

struct FlightWorkflowOptions {
  std::string camera_file;  // camera for every step (overrides the projects' camera files)
  std::string data_folder;  // project.yaml (virtual observations), optional project_subimage.yaml
  std::vector<std::string> base_ids;  // datum of the focal plane; empty: the reference points
  /// The self-calibration's parameters; with choose_free_set the candidates of
  /// AdjustWithChosenFreeSet (self_calibration_choice.h: only what the block determines and what
  /// is significant), else calibrated as they are (`--self-calibration all` or a list).
  std::vector<std::string> free_interior = {
      "c", "x0", "y0", "K1", "K2", "K3", "P1", "P2", "B1", "B2"};
  bool choose_free_set = true;        // `--self-calibration auto`, the default
  double suspect_effect_limit = 1.0;  // AdjustOptions::suspect_effect_limit
  double stitch_sigma_px = 0.1;       // where stitch_obs.csv has no sigma_px
  bool joint = true;                  // run the joint adjustment when sub-image observations exist
  /// Mapping model of the joint step; nullopt: the one the stitching F test chose for the flight.
  std::optional<calib::MappingModel> joint_model;
  /// Step 1 already done frame by frame (`aerocal batch`): one run per frame of FlightStitching,
  /// in its order; null: the workflow adjusts the frames itself. Either way the same numbers.
  const std::vector<stitch::FrameRun>* stitched_frames = nullptr;
};

/// Step 1's work, frame by frame: the stitching options of the flight and the measurements of
/// every exposure, exactly as RunFlightWorkflow adjusts them (stitch::StitchFrame of each frame
/// with `options`). No frames: the flight has no stitching step. InputError as the workflow.
struct FlightStitching {
  stitch::BatchOptions options;
  calib::Camera camera;
  std::vector<stitch::StitchObservation> rows;
  std::vector<stitch::FrameMeasurements> frames;
};
FlightStitching ReadFlightStitching(const FlightWorkflowOptions& options);

/// The stitching options of step 1 (FlightStitching::options) without reading the flight.
stitch::BatchOptions FlightStitchingOptions(const FlightWorkflowOptions& options);

/// Warning name when the joint adjustment's sigma0 exceeds the self-calibration's by more than
/// kJointSigma0RatioLimit: both fit the same image points (raw or virtual), so with a fitting
/// mapping model the two agree within about 10 %; far above, the mapping model does not fit.
inline constexpr const char* kWarningJointSigma0Ratio = "joint_sigma0_ratio";
inline constexpr double kJointSigma0RatioLimit = 1.5;

struct FlightWorkflowResult {
  nlohmann::json document;          // kind "flight"
  calib::Camera calibrated_camera;  // interior (and mappings, when joint) for the next flight
  bool converged = true;            // every adjustment converged
  /// Every step converged and is valid (AdjustmentResult::valid); otherwise `failures` names the
  /// failing steps and calibrated_camera must not be used (aerocal flight does not write it).
  bool valid = true;
  std::vector<std::pair<std::string, std::string>> failures;  // (step, reason)
  std::vector<std::string> summary;  // one line per step, for the terminal (and each warning)
  /// Which adjustment calibrated_camera comes from ("self_calibration" or "joint") and why.
  std::string camera_from, camera_from_reason;
};

/// Runs the workflow; `progress` (may be null) advances once per step (5 steps).
/// Throws InputError for unreadable or inconsistent input.
FlightWorkflowResult RunFlightWorkflow(const FlightWorkflowOptions& options, Progress* progress);

}  // namespace aerocal::triangulation
