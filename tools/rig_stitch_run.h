// `aerocal rig stitch` as one request and one run (the self-calibrating stitching of a rig block
// from its project, ties read from observations.csv or matched on the head images): shared by the
// command (tools/cmd_rig.cc, which adds the stitched images and the output set) and Python's
// `aerocal.rig_stitch` (tools/python/bind_rig.cc).
#pragma once

#include "calib/camera/rig.h"
#include "stitch/rig/self_calibration.h"
#include "stitch/rig/self_calibration_json.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::tools {

struct RigStitchRequest {
  std::string camera, project, mode = "line";
  bool no_snooping = false;
  double alpha = 0.05;
  std::optional<double> increment_sigma_arcsec;  // weighted prior on every increment angle
  std::optional<double> dt_sigma_ms;             // weighted prior on every time offset
  std::optional<double> relief_m;                // relief of the block off the plane
  double standard_radius_px = 400.0;
  double max_sigma0 = 3.0;
  double suspect_effect_limit = 1.0;
  double default_sigma_px = 0.5;
  std::string images;             // folder of the head images <image>_<head>.tif
  bool match_ties = false;        // ties matched on the head images instead of observations.csv
  bool need_head_images = false;  // every head image must exist (the stitched images follow)
};

struct RigStitchRun {
  calib::Rig rig;
  std::vector<stitch::RigStitchExposure> exposures;
  stitch::RigStitchOptions options;
  stitch::RigStitchResult result;
  nlohmann::json json;  // the result document (kind rig_stitch), without the stitched images
  std::string printed;  // what the command prints on stdout
};

/// Reads, checks and runs; InputError / ConfigError naming the file or the option.
RigStitchRun RunRigStitch(const RigStitchRequest& request);

/// The head image of an exposure under `folder`: <image>_<head>.tif (or .tiff, .png, .jpg).
std::string HeadImagePath(const std::string& folder,
                          const std::string& image,
                          const std::string& head);

/// The camera model of each head with its parameter table, keyed by head id (`camera_models` of
/// the rig result documents).
nlohmann::json HeadCameraModels(const calib::Rig& rig);

}  // namespace aerocal::tools
