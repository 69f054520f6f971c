// The simulated line-camera flights the pushbroom tests share (issue 17, 28): the small flight of
// the boresight / lever-arm tests and the issue-28 datum flight.
#pragma once

#include "triangulation/pushbroom/line_simulation.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace aerocal::triangulation {

/// 3 x 120 detectors, 800 lines, 700 control points, node spacing 100; the simulator's defaults
/// otherwise (0.25 px, control 0.1 m, POS 5 cm / 0.005 deg, no sub-camera errors).
inline LineSimulationOptions SmallFlight(std::uint64_t seed = 7) {
  LineSimulationOptions o;
  o.detectors_per_camera = 120;
  o.lines = 800;
  o.control_points = 700;
  o.node_spacing_lines = 100;
  o.seed = seed;
  return o;
}

/// The issue-28 flight: the small flight with every sub-camera's own 1 px offset, scale, rotation
/// and curvature errors, POS bias and drift (5 cm, 0.005 deg), on either layout.
inline LineSimulationOptions DatumFlight(bool linear_layout, std::uint64_t seed) {
  LineSimulationOptions o = SmallFlight(seed);
  o.subcamera_error_px = 1.0;
  o.linear_layout = linear_layout;
  o.pos_bias_m = 0.05;
  o.pos_bias_deg = 0.005;
  o.pos_drift_m = 0.05;
  o.pos_drift_deg = 0.005;
  return o;
}

/// No error anywhere: image and control noise, the POS's spline, bias and drift all zero.
inline void RemoveNoise(LineSimulationOptions* o) {
  o->image_noise_px = o->control_noise_m = 0;
  o->pos_error_m = o->pos_error_deg = o->pos_bias_m = o->pos_bias_deg = 0;
  o->pos_drift_m = o->pos_drift_deg = 0;
}

/// The name of a test parameterised by the layout (DatumFlight's `linear_layout`).
inline std::string LayoutName(const ::testing::TestParamInfo<bool>& info) {
  return info.param ? "LinearVirtualCcd" : "Subcameras";
}

}  // namespace aerocal::triangulation
