// Simulated laboratory direction measurements (issue 36 item 6): the image of a direction t
// (instrument frame; calib/residuals/direction.h) through an instrument setting G and a camera
// turned by R = instrument_from_camera (omega, phi, kappa), [U V W] = R^T G^T t, projected with the
// 10-parameter model's distortion, plus image noise. Shared by the library's and the command's
// tests. A 2 x 3-CCD camera's sub-images: MultiCcdMapping, ObserveInSubimages.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/camera.h"
#include "calib/camera/rotation.h"

#include <Eigen/Core>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

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

/// CCD `k` (0..5, row-major in 2 rows of 3) of a 2 x 3-CCD camera on a 6000 x 4000 px virtual
/// image: 2100 x 2100 px, ~125 px overlap, its affine mapping the nominal layout turned by `turn`
/// (rad), scaled by 1 + `scale`, sheared by `shear` and shifted by (`shift`, -`shift`) px. Ids
/// A..F.
inline calib::SubimageMapping MultiCcdMapping(
    int k, double turn = 0, double scale = 0, double shear = 0, double shift = 0) {
  const char* ids[6] = {"A", "B", "C", "D", "E", "F"};
  const double u0 = -50.0 + 1975.0 * (k % 3), v0 = -50.0 + 1950.0 * (k / 3);
  const double a = (1 + scale) * std::cos(turn), b = (1 + scale) * std::sin(turn);
  return {ids[k],
          2100,
          2100,
          calib::MappingModel::kAffine,
          {a, -b + shear, u0 + shift, b, a, v0 - shift}};
}

/// The true mappings of the simulated 2 x 3-CCD camera (CCD A, the reference, at the nominal
/// layout: a gauge holds it).
inline std::vector<calib::SubimageMapping> TrueMultiCcdMappings() {
  const double turn[6] = {0, 3e-4, -2e-4, 1e-4, -3e-4, 2e-4};
  const double scale[6] = {0, 2e-4, -1e-4, -2e-4, 1e-4, 1.5e-4};
  const double shear[6] = {0, -1e-4, 2e-4, 1e-4, -2e-4, 5e-5};
  const double shift[6] = {0, 1.2, -2.0, 0.7, 1.6, -0.9};
  std::vector<calib::SubimageMapping> out;
  for (int k = 0; k < 6; ++k)
    out.push_back(MultiCcdMapping(k, turn[k], scale[k], shear[k], shift[k]));
  return out;
}

/// The raw sub-image pixels (id, (u, v)) of direction t through the multi-CCD camera `truth`
/// (interior and mappings) turned by `opk_rad`: every CCD the cross falls on (20 px inside), each
/// with its own image noise of `sigma_px` per axis.
inline std::vector<std::pair<std::string, Eigen::Vector2d>> ObserveInSubimages(
    const calib::Camera& truth,
    const Eigen::Vector3d& opk_rad,
    const Eigen::Vector3d& t,
    double sigma_px,
    std::mt19937_64* rng) {
  std::vector<std::pair<std::string, Eigen::Vector2d>> out;
  const Eigen::Vector2d virtual_px =
      ObserveDirection(truth, opk_rad, Eigen::Matrix3d::Identity(), t, 1e-12, rng);
  if (!virtual_px.allFinite()) return out;
  std::normal_distribution<double> noise(0.0, sigma_px);
  for (const calib::SubimageMapping& m : truth.subimages) {
    const Eigen::Vector2d uv = m.SubFromVirtual(virtual_px);
    if (m.Contains(uv, -20.0))
      out.emplace_back(m.id, uv + Eigen::Vector2d(noise(*rng), noise(*rng)));
  }
  return out;
}

}  // namespace aerocal::testing
