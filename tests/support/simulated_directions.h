// Simulated laboratory direction measurements (issue 36 item 6): the image of a direction t
// (instrument frame; calib/residuals/direction.h) through an instrument setting G and a camera
// turned by R = instrument_from_camera (omega, phi, kappa), [U V W] = R^T G^T t, projected with the
// 10-parameter model's distortion, plus image noise. Shared by the library's and the command's
// tests.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera.h"
#include "calib/camera/rotation.h"

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <random>

namespace aerocal::testing {

/// t(a, e) = (sin a cos e, sin e, -cos a cos e), angles in rad.
inline Eigen::Vector3d InstrumentDirection(double azimuth, double elevation) {
  return {std::sin(azimuth) * std::cos(elevation),
          std::sin(elevation),
          -std::cos(azimuth) * std::cos(elevation)};
}

/// The measured pixel (col, row) of t through g for the camera `truth` (10-parameter model) turned
/// by `opk_rad`, with normal image noise of `sigma_px` per axis; NaN when the model's inversion
/// fails.
inline Eigen::Vector2d ObserveDirection(const calib::Camera& truth,
                                        const Eigen::Vector3d& opk_rad,
                                        const Eigen::Matrix3d& g,
                                        const Eigen::Vector3d& t,
                                        double sigma_px,
                                        std::mt19937_64* rng) {
  const Eigen::Vector3d uvw = calib::RotationFromOpk(opk_rad).transpose() * g.transpose() * t;
  const double c = truth.interior[0];
  const Eigen::Vector2d ideal(-c * uvw.x() / uvw.z(), -c * uvw.y() / uvw.z());
  Eigen::Vector2d measured;
  if (!calib::BrownFraser10Model::MeasuredFromIdeal(truth.interior.data(), ideal, &measured))
    return Eigen::Vector2d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::normal_distribution<double> noise(0.0, sigma_px);
  return truth.frame().PixelFromPhoto(measured) + Eigen::Vector2d(noise(*rng), noise(*rng));
}

/// A random rotation of `sigma_rad` per axis: a collimator's or a setting's angular error.
inline Eigen::Matrix3d RandomSmallRotation(double sigma_rad, std::mt19937_64* rng) {
  std::normal_distribution<double> n(0.0, sigma_rad);
  return calib::RotationFromOpk(Eigen::Vector3d(n(*rng), n(*rng), n(*rng)));
}

}  // namespace aerocal::testing
