// The directions file of a laboratory calibration (`aerocal calibrate --directions FILE`;
// docs/formats.md "Directions file"): one CSV row per measured image point of a collimator's
// cross or of a goniometer's target,
//
//   target,col,row[,sigma_px][,azimuth_deg,elevation_deg][,sigma_arcsec][,setting,turn_deg,tilt_deg][,group][,unit]
//
// - target: the collimator / target id; col, row: its measured image position (camera pixel
//   frame, docs/conventions.md), sigma_px its image sigma (> 0; default --sigma-px).
// - azimuth_deg, elevation_deg: the target's direction in the instrument frame (direction.h:
//   t = (sin a cos e, sin e, -cos a cos e), a = e = 0 along the camera's nominal viewing direction
//   -z). Given on every row of a known target (a collimator), identical; left empty on every row
//   of a target whose direction is estimated (a goniometer's fixed target).
// - sigma_arcsec: the angular sigma (per axis) of the collimator's direction or of the goniometer
//   setting, >= 0 (default 0).
// - setting, turn_deg, tilt_deg: a goniometer setting, the instrument's rotation of the camera
//   mount G = Rx(tilt) Ry(turn) (turn about the instrument's y axis, then tilt about its x axis;
//   default 0, 0 = identity); every row of one setting repeats its angles. Without a `setting`
//   column a row's setting is named by its angles.
// - group: optional; rows of one group (a repeated series, another mounting) are also calibrated
//   alone and the groups' agreement tested (calibration.h).
// - unit: optional; the head of a rig file (ReadUnitDirections) that measured the row, on every
//   row; col, row are in that head's pixel frame and bounded by its format. A single camera file
//   takes no unit (ReadDirections refuses a non-empty cell).
// Each error names FILE:LINE, the column and the rule.
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/calibration/direction_calibration.h"

#include <map>
#include <string>
#include <vector>

namespace aerocal::triangulation {

struct DirectionData {
  std::vector<DirectionTarget> targets;            // in the order of first appearance
  std::vector<DirectionObservation> observations;  // one per row (DirectionObservation::where)
  std::vector<std::string> groups;                 // per observation ("" none); empty: no column
  std::vector<std::string> units;  // per observation (ReadUnitDirections); empty: one camera
  int settings = 0;                // distinct goniometer settings (0: none)
};

/// Reads a directions file; `camera` bounds the image positions to its format and
/// `default_sigma_px` (> 0) is the image sigma of rows without sigma_px. Throws InputError
/// "FILE:LINE: ..." on bad content (see the header comment).
DirectionData ReadDirections(const std::string& path,
                             const calib::Camera& camera,
                             double default_sigma_px);

/// Reads a directions file whose rows each name one of `units` (id -> camera: a rig's heads) in
/// the `unit` column. Throws InputError "FILE:LINE: ..." as ReadDirections, and for a missing
/// `unit` column (line 1), an empty unit cell or a unit not in `units` (at its row).
/// `camera_file` names the units' file in messages.
DirectionData ReadUnitDirections(const std::string& path,
                                 const std::map<std::string, calib::Camera>& units,
                                 const std::string& camera_file,
                                 double default_sigma_px);

}  // namespace aerocal::triangulation
