// The sub-image stitching of `aerocal stitch` from its inputs: the options as the command's text
// gives them, and the frames of a stitch_obs.csv for RunStitchBatch. Shared by the command
// (tools/cmd_stitch.cc) and the Python module (tools/python/bind_stitch.cc), so both run exactly
// the same steps.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/adjustment/flight_stability.h"
#include "stitch/adjustment/frame_measurements.h"

#include <string>

namespace aerocal::stitch {

/// `model`: translation | conformal | affine | projective | auto (the F test at `alpha`);
/// `base`: comma-separated sub-images that keep the camera file's mapping. ConfigError naming the
/// option (`model_option`, `base_option`, `alpha_option`) for a bad value.
BatchOptions BatchOptionsFromText(const calib::Camera& camera,
                                  const std::string& model,
                                  const std::string& base,
                                  double alpha,
                                  bool data_snooping,
                                  const char* model_option = "--model",
                                  const char* alpha_option = "--alpha");

/// Reads `observations` (stitch_obs.csv; `sigma_px` where a row has none) grouped by frame, ready
/// for RunStitchBatch. InputError for a camera without sub-images or a file without measurements.
std::vector<FrameMeasurements> ReadStitchFrames(const calib::Camera& camera,
                                                const std::string& camera_path,
                                                const std::string& observations,
                                                double sigma_px);

}  // namespace aerocal::stitch
