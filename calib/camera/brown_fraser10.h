// The 10-parameter self-calibration model (Brown / Fraser 1997), correction form, exactly as
// CONVENTIONS.md "The 10-parameter self-calibration model" defines it.
//
// Parameters (block of 10, table units): c [mm], x0 [mm], y0 [mm], K1 [mm^-2], K2 [mm^-4],
// K3 [mm^-6], P1 [mm^-1], P2 [mm^-1], B1 [1], B2 [1].
// With xb = x - x0, yb = y - y0 and r2 = xb^2 + yb^2 at the MEASURED photo coordinates (x, y):
//   dx = xb (K1 r2 + K2 r2^2 + K3 r2^3) + P1 (r2 + 2 xb^2) + 2 P2 xb yb + B1 xb + B2 yb
//   dy = yb (K1 r2 + K2 r2^2 + K3 r2^3) + 2 P1 xb yb + P2 (r2 + 2 yb^2)
// The ideal (corrected) coordinates, reduced to the principal point, are (xb + dx, yb + dy);
// they obey collinearity: xb + dx = -c U / W, yb + dy = -c V / W.
#pragma once

#include "calib/camera/models/model_common.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <string_view>

namespace aerocal::calib {

struct BrownFraser10Model {
  static constexpr CameraModelId kId = CameraModelId::kBrownFraser10;
  static constexpr std::string_view kName = "brown_fraser_10";
  static constexpr bool kCorrectionForm = true;  // closed form measured -> ideal
  enum Index : int { kC, kX0, kY0, kK1, kK2, kK3, kP1, kP2, kB1, kB2, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{
      {"c", "mm", ParamGroup::kPrincipalDistance},
      {"x0", "mm", ParamGroup::kPrincipalPoint},
      {"y0", "mm", ParamGroup::kPrincipalPoint},
      {"K1", "mm^-2", ParamGroup::kRadial},
      {"K2", "mm^-4", ParamGroup::kRadial},
      {"K3", "mm^-6", ParamGroup::kRadial},
      {"P1", "mm^-1", ParamGroup::kDecentering},
      {"P2", "mm^-1", ParamGroup::kDecentering},
      {"B1", "1", ParamGroup::kAffinity},
      {"B2", "1", ParamGroup::kAffinity},
  }};

  /// Index of a parameter by its table name ("c", "K1", ...); -1 when unknown.
  static int IndexOf(std::string_view name) { return IndexOfParam(kParams, name); }

  /// The free set of a calibration when none is given (`calibrate`): all but the affinity.
  static constexpr std::string_view kDefaultFree = "c,x0,y0,K1,K2,K3,P1,P2";

  /// The distortion profile at a radius r (mm from the principal point), um (Fraser 1997):
  /// radial dr = K1 r^3 + K2 r^5 + K3 r^7, decentring magnitude dt = r^2 sqrt(P1^2 + P2^2).
  static double RadialDistortionUm(const double* params, double r_mm) {
    const double r2 = r_mm * r_mm;
    return 1e3 * r_mm * (params[kK1] * r2 + params[kK2] * r2 * r2 + params[kK3] * r2 * r2 * r2);
  }
  static double DecentringDistortionUm(const double* params, double r_mm) {
    return 1e3 * r_mm * r_mm * std::hypot(params[kP1], params[kP2]);
  }

  /// Correction (dx, dy) in mm at the principal-point-reduced MEASURED coordinates xb (mm).
  template <typename T>
  static void CorrectionReduced(const T* params, const T* xb, T* dxy) {
    const T r2 = xb[0] * xb[0] + xb[1] * xb[1];
    const T radial = r2 * (params[kK1] + r2 * (params[kK2] + r2 * params[kK3]));
    dxy[0] = xb[0] * radial + params[kP1] * (r2 + T(2) * xb[0] * xb[0]) +
             T(2) * params[kP2] * xb[0] * xb[1] + params[kB1] * xb[0] + params[kB2] * xb[1];
    dxy[1] = xb[1] * radial + T(2) * params[kP1] * xb[0] * xb[1] +
             params[kP2] * (r2 + T(2) * xb[1] * xb[1]);
  }

  /// Ideal coordinates reduced to the principal point, (xb + dx, yb + dy) in mm, from MEASURED
  /// photo coordinates xy (mm).
  template <typename T>
  static void IdealFromMeasured(const T* params, const T* xy_mm, T* ideal_mm) {
    const T xb[2] = {xy_mm[0] - params[kX0], xy_mm[1] - params[kY0]};
    T d[2];
    CorrectionReduced(params, xb, d);
    ideal_mm[0] = xb[0] + d[0];
    ideal_mm[1] = xb[1] + d[1];
  }

  /// Inverse of IdealFromMeasured by Newton iteration: the measured photo coordinates (mm) whose
  /// ideal reduced coordinates are `ideal_mm`. Converges to |step| < tolerance_mm; false otherwise.
  static bool MeasuredFromIdeal(const double* params,
                                const Eigen::Vector2d& ideal_mm,
                                Eigen::Vector2d* measured_mm,
                                double tolerance_mm = 1e-11);

  // The uniform interface of the registry (camera_model.h, models/model_common.h).
  template <typename T>
  static T PrincipalDistanceMm(const T* params, const PixelFrame&) {
    return params[kC];
  }
  template <typename T>
  static bool IdealFromMeasured(const T* params,
                                const PixelFrame&,
                                const T* measured_mm,
                                T* ideal_mm) {
    IdealFromMeasured(params, measured_mm, ideal_mm);
    return true;
  }
  /// Newton to 1e-10 px (Jet-safe: derivatives of the implicit solution).
  template <typename T>
  static bool MeasuredFromIdeal(const T* params,
                                const PixelFrame& frame,
                                const T* ideal_mm,
                                T* measured_mm) {
    return MeasuredFromIdeal(params, ideal_mm, measured_mm, 1e-10 * frame.pixel_size_mm);
  }
  template <typename T>
  static bool MeasuredFromIdeal(const T* params,
                                const T* ideal_mm,
                                T* measured_mm,
                                double tolerance_mm) {
    const double start[2] = {ValueOf(ideal_mm[0]) + ValueOf(params[kX0]),
                             ValueOf(ideal_mm[1]) + ValueOf(params[kY0])};
    const auto ideal = [](const auto* p, const auto* xy, auto* out) {
      IdealFromMeasured(p, xy, out);
    };
    const double centre[2] = {ValueOf(params[kX0]), ValueOf(params[kY0])};
    return InvertMap2<kNumParams>(
        ideal, params, ideal_mm, start, measured_mm, tolerance_mm, 50, centre);
  }
  /// Exact OpenCV equivalent when K1 = K2 = K3 = P1 = P2 = B2 = 0 (the affinity B1 becomes
  /// fx = c / ((1 + B1) p), fy = c / p); otherwise that pinhole part as a starting value.
  static bool ToOpenCv(const double* params, const PixelFrame& frame, OpenCvParams* cv);
  /// Exact when OpenCV has no distortion (c = fy p, B1 = fy / fx - 1); else the pinhole part.
  static bool FromOpenCv(const OpenCvParams& cv, const PixelFrame& frame, double* params);
};

}  // namespace aerocal::calib
