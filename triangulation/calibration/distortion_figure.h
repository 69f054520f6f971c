// The distortion of a calibrated camera over its format, for the certificate's figure, in ANY
// registered camera model (camera_model.h): the certificate reads these samples instead of
// restating a model's formulas (issue 10).
//
// Correction at a measured photo point x (mm): ideal(x) - (x - x_p), with ideal() the model's
// IdealFromPixel and x_p the measured point of the principal ray (PixelFromIdeal(0, 0)); for the
// 10-parameter model that is its dx, dy (CONVENTIONS.md "10-parameter model").
// Radial profile against r (mm) from x_p:
// - the 10-parameter model: the certified quantities themselves, dr(r) = r (K1 r^2 + K2 r^4 +
//   K3 r^6) and the decentring magnitude dt(r) = r^2 sqrt(P1^2 + P2^2) (the budget's dr@R, dt@R);
// - any other model: the mean radial component of the correction over 72 directions, and the
//   RMS of its tangential component (a radially symmetric model has dt = 0).
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/camera_model.h"

#include <array>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// dr(r) and dt(r) of the 10-parameter model, um (r in mm).
double RadialDistortionUm(const calib::InteriorParams& p, double r_mm);
double DecentringDistortionUm(const calib::InteriorParams& p, double r_mm);

struct DistortionFigure {
  std::string profile_kind;                    // "10-parameter terms" | "mean over directions"
  std::vector<std::array<double, 3>> profile;  // r mm, dr um, dt um (0 .. half diagonal)
  std::vector<std::array<double, 4>> grid;     // x mm, y mm, dx um, dy um (format centre frame)
};

/// Samples of the camera's correction: `profile_samples` radii up to the half diagonal and a
/// `columns` x `rows` grid over the format. Points where the model's inversion fails are left out.
DistortionFigure DistortionOverFormat(const calib::ModelCamera& camera,
                                      int profile_samples = 100,
                                      int columns = 11,
                                      int rows = 9);

}  // namespace aerocal::triangulation
