// OpenCV's camera models, forward form (ideal normalised coordinates -> distorted -> pixels).
//
// Source: OpenCV documentation, calib3d module, "Detailed Description"
// (https://docs.opencv.org/4.x/d9/d0c/group__calib3d.html): with x' = X/Z, y' = Y/Z (camera x
// right, y down, z forward), r^2 = x'^2 + y'^2,
//   x'' = x' (1 + k1 r^2 + k2 r^4 + k3 r^6) / (1 + k4 r^2 + k5 r^4 + k6 r^6)
//         + 2 p1 x' y' + p2 (r^2 + 2 x'^2)
//   y'' = y' (...) / (...) + p1 (r^2 + 2 y'^2) + 2 p2 x' y'
//   u = fx x'' + cx,  v = fy y'' + cy
// distCoeffs order (k1, k2, p1, p2[, k3[, k4, k5, k6]]). The thin-prism s1-s4 and tilt tau terms
// are not modelled. Fisheye (https://docs.opencv.org/4.x/db/d58/group__calib3d__fisheye.html):
//   theta = atan(r), theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8),
//   (x'', y'') = (theta_d / r) (x', y'), u = fx x'' + cx (skew alpha not modelled).
// Pixel convention: OpenCV addresses pixel centres by integer coordinates (cv::Mat indices,
// cornerSubPix, remap), so the top-left pixel centre is (0, 0) as in aerocal: u = col, v = row.
// Principal distance for the ideal photo coordinates: c = fy * pixel size (y is not scaled by an
// affinity in the 10-parameter model, so fx != fy becomes B1 there).
#pragma once

#include "calib/camera/models/model_common.h"

namespace aerocal::calib {

struct OpenCvModel : ForwardCameraModel<OpenCvModel> {
  static constexpr CameraModelId kId = CameraModelId::kOpenCv;
  static constexpr std::string_view kName = "opencv";
  enum Index : int { kFx, kFy, kCx, kCy, kK1, kK2, kP1, kP2, kK3, kK4, kK5, kK6, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{
      {"fx", "px", ParamGroup::kPrincipalDistance},
      {"fy", "px", ParamGroup::kPrincipalDistance},
      {"cx", "px", ParamGroup::kPrincipalPoint},
      {"cy", "px", ParamGroup::kPrincipalPoint},
      {"k1", "1", ParamGroup::kRadial},
      {"k2", "1", ParamGroup::kRadial},
      {"p1", "1", ParamGroup::kDecentering},
      {"p2", "1", ParamGroup::kDecentering},
      {"k3", "1", ParamGroup::kRadial},
      {"k4", "1", ParamGroup::kRadial},
      {"k5", "1", ParamGroup::kRadial},
      {"k6", "1", ParamGroup::kRadial},
  }};
  /// The free set of a calibration when none is given: OpenCV's own default (calibrateCamera
  /// without CALIB_RATIONAL_MODEL: the rational k4-k6 held at 0).
  static constexpr std::string_view kDefaultFree = "fx,fy,cx,cy,k1,k2,p1,p2,k3";

  /// OpenCV's distortion of normalised coordinates n (x right, y down): coefficients in
  /// distCoeffs order k = (k1, k2, p1, p2, k3, k4, k5, k6).
  template <typename T>
  static void Distort(const T* k, const T* n, T* nd) {
    const T x = n[0], y = n[1], r2 = x * x + y * y;
    const T radial = (T(1) + r2 * (k[0] + r2 * (k[1] + r2 * k[4]))) /
                     (T(1) + r2 * (k[5] + r2 * (k[6] + r2 * k[7])));
    nd[0] = x * radial + T(2) * k[2] * x * y + k[3] * (r2 + T(2) * x * x);
    nd[1] = y * radial + k[2] * (r2 + T(2) * y * y) + T(2) * k[3] * x * y;
  }
  /// Inverse of Distort by Newton (started at nd); false when it does not converge.
  template <typename T>
  static bool Undistort(const T* k, const T* nd, T* n) {
    const double start[2] = {ValueOf(nd[0]), ValueOf(nd[1])};
    const auto distort = [](const auto* kk, const auto* x, auto* y) { Distort(kk, x, y); };
    return InvertMap2<8>(distort, k, nd, start, n, 1e-14);
  }

  /// Pixel of distorted normalised coordinates nd; p starts with fx, fy, cx, cy.
  template <typename T>
  static void PixelFromDistorted(const T* p, const T* nd, T* pixel) {
    pixel[0] = p[kFx] * nd[0] + p[kCx];
    pixel[1] = p[kFy] * nd[1] + p[kCy];
  }
  template <typename T>
  static void Project(const T* p, const PixelFrame&, const T* n, T* pixel) {
    const T k[8] = {p[kK1], p[kK2], p[kP1], p[kP2], p[kK3], p[kK4], p[kK5], p[kK6]};
    T nd[2];
    Distort(k, n, nd);
    PixelFromDistorted(p, nd, pixel);
  }
  template <typename T>
  static T PrincipalDistanceMm(const T* p, const PixelFrame& frame) {
    return p[kFy] * T(frame.pixel_size_mm);
  }
  static bool ToOpenCv(const double* p, const PixelFrame&, OpenCvParams* cv) {
    for (int i = 0; i < kNumParams; ++i) (*cv)[i] = p[i];
    return true;
  }
  static bool FromOpenCv(const OpenCvParams& cv, const PixelFrame&, double* p) {
    for (int i = 0; i < kNumParams; ++i) p[i] = cv[i];
    return true;
  }
};

struct OpenCvFisheyeModel : ForwardCameraModel<OpenCvFisheyeModel> {
  static constexpr CameraModelId kId = CameraModelId::kOpenCvFisheye;
  static constexpr std::string_view kName = "opencv_fisheye";
  enum Index : int { kFx, kFy, kCx, kCy, kK1, kK2, kK3, kK4, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {
      {OpenCvModel::kParams[OpenCvModel::kFx],
       OpenCvModel::kParams[OpenCvModel::kFy],
       OpenCvModel::kParams[OpenCvModel::kCx],
       OpenCvModel::kParams[OpenCvModel::kCy],
       OpenCvModel::kParams[OpenCvModel::kK1],
       OpenCvModel::kParams[OpenCvModel::kK2],
       OpenCvModel::kParams[OpenCvModel::kK3],
       OpenCvModel::kParams[OpenCvModel::kK4]}};

  template <typename T>
  static void Distort(const T* k, const T* n, T* nd) {
    using std::atan;
    using std::sqrt;
    const T r2 = n[0] * n[0] + n[1] * n[1];
    T scale;
    if (ValueOf(r2) < 1e-20) {
      scale = T(1) + (k[0] - T(1.0 / 3.0)) * r2;  // series of theta_d / r at r -> 0
    } else {
      const T r = sqrt(r2), theta = atan(r), t2 = theta * theta;
      scale = theta * (T(1) + t2 * (k[0] + t2 * (k[1] + t2 * (k[2] + t2 * k[3])))) / r;
    }
    nd[0] = n[0] * scale;
    nd[1] = n[1] * scale;
  }
  template <typename T>
  static void Project(const T* p, const PixelFrame&, const T* n, T* pixel) {
    T nd[2];
    Distort(p + kK1, n, nd);
    OpenCvModel::PixelFromDistorted(p, nd, pixel);  // same fx, fy, cx, cy at the start
  }
  template <typename T>
  static T PrincipalDistanceMm(const T* p, const PixelFrame& frame) {
    return OpenCvModel::PrincipalDistanceMm(p, frame);
  }
  /// Never exact (an equidistant projection is no pinhole): the pinhole part as a start.
  static bool ToOpenCv(const double* p, const PixelFrame&, OpenCvParams* cv) {
    cv->fill(0.0);
    for (int i = 0; i < 4; ++i) (*cv)[i] = p[i];
    return false;
  }
  static bool FromOpenCv(const OpenCvParams& cv, const PixelFrame&, double* p) {
    for (int i = 0; i < kNumParams; ++i) p[i] = i < 4 ? cv[i] : 0.0;
    return false;
  }
};

}  // namespace aerocal::calib
