// Plots of `aerocal pushbroom calibrate --plot` (issue 17: "plots of the error curves and of the
// fitted polynomials"): per sub-camera one row of two panels, across track (x) and along track
// (y). Each panel shows, against the detector index, the reprojection error of every observation
// without the detector calibration (LineErrorSample, dots), the fitted table (one polyline,
// class "fit") and its 1-sigma band (polygon, class "band"; absent where the sigma is unknown),
// in pitches (px). SVG 1.1 text in the style of `camera show --plot` (tools/cmd_camera.cc).
#pragma once

#include "triangulation/pushbroom/line_calibration.h"

#include <string>

namespace aerocal::triangulation {

/// The SVG document; `title` is escaped.
std::string LineCalibrationSvg(const LineCalibrationResult& result, const std::string& title);

}  // namespace aerocal::triangulation
