// `aerocal match` as one request and one run (tie points in the overlap strips of the frames):
// shared by the command (tools/cmd_match.cc, which writes stitch_obs.csv) and Python's
// `aerocal.match`.
#pragma once

#include "stitch/simulation/stitch_simulator.h"

#include <string>
#include <vector>

namespace aerocal::tools {

struct MatchRequest {
  std::string camera;
  std::string frame, images;  // one frame: --frame and --images I=a.tif,II=b.tif,...
  std::string list;           // or a flight: CSV frame,subimage,image
  std::string search = "predicted";
  std::string detector;  // --search descriptors only; empty: sift
  std::string lsm = "on";
  double sigma_px = 0.3;
  double cell_px = 100.0;
};

struct MatchRun {
  std::vector<stitch::StitchObservation> rows;  // the ties, every frame
  std::string table;                            // the per-strip table the command prints
};

/// Reads the camera and the images and matches every frame, with the command's progress;
/// InputError / ConfigError naming the file (list.csv:LINE) or the option.
MatchRun RunMatching(const MatchRequest& request);

}  // namespace aerocal::tools
