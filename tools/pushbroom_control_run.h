// `aerocal pushbroom control` without its files: the request (the command's inputs and options),
// the checks, the reading of the reference frames and the cloud control itself. Shared by the
// command (which writes observations.csv, points.csv, control.json and l1.png into --out) and
// Python's `aerocal.pushbroom_control`.
#pragma once

#include "triangulation/pushbroom/cloud_control.h"

#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::tools {

struct PushbroomControlRequest {
  std::string camera;      // nominal line camera file
  std::string pos;         // pos.csv of the line image
  std::string line_image;  // the line image (rows = scan lines)
  std::string reference_camera;
  std::string reference_exposures;  // exposures.csv of the reference frames, or
  std::string reference_result;     // the block result of `aerocal adjust` (its used exposures)
  std::string reference_images;     // folder of the reference frames' images
  triangulation::CloudControlOptions options;
};

struct PushbroomControlRun {
  triangulation::CloudControlResult result;
  int reference_exposures = 0;  // reference frames used
  int skipped_exposures = 0;    // exposures of --reference-result the adjustment did not use
  nlohmann::json document;      // control.json (kind pushbroom_control, without the stamp)
};

/// Checks the request (ConfigError naming the option, InputError naming the file; the L1 image's
/// size bounded before anything is allocated), reads the inputs and makes the cloud control.
PushbroomControlRun RunPushbroomControl(const PushbroomControlRequest& request);

}  // namespace aerocal::tools
