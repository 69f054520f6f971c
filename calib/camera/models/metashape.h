// Agisoft Metashape's frame-camera model, forward form, parameters as Metashape's calibration XML
// writes them (f, cx, cy, b1, b2, k1-k4, p1-p4; f, cx, cy, b1, b2 in pixels).
//
// Source: Agisoft Metashape User Manual (Professional Edition 1.6-2.x), Appendix C "Camera models",
// "Frame cameras": with x = X/Z, y = Y/Z (camera x right, y down, z forward), r^2 = x^2 + y^2,
//   x' = x (1 + K1 r^2 + K2 r^4 + K3 r^6 + K4 r^8) + (P1 (r^2 + 2 x^2) + 2 P2 x y)(1 + P3 r^2 + P4
//   r^4) y' = y (1 + K1 r^2 + K2 r^4 + K3 r^6 + K4 r^8) + (P2 (r^2 + 2 y^2) + 2 P1 x y)(1 + P3 r^2
//   + P4 r^4) u = w / 2 + cx + x' f + x' B1 + y' B2,   v = h / 2 + cy + y' f
// "the image coordinate system has the origin at the top left image pixel, with the center of the
// top left pixel having coordinates (0.5, 0.5)". The same formulas and the (0.5, 0.5) corner are
// quoted from Appendix C in the Agisoft forum thread on the distortion plot (agisoft.com/forum,
// 2022). Conventions converted HERE (Project), nowhere else:
//   - pixel: col = u - 0.5, row = v - 0.5; cx, cy are offsets from the format centre w/2, h/2;
//   - P1/P2 are SWAPPED against OpenCV: Metashape P1 multiplies (r^2 + 2 x^2) like OpenCV's p2,
//     so p1_opencv = P2, p2_opencv = P1;
//   - B1 is exact in OpenCV (fx = f + B1, fy = f); B2 (skew), K4, P3, P4 have no OpenCV term.
// Principal distance for the ideal photo coordinates: c = f * pixel size.
#pragma once

#include "calib/camera/models/opencv.h"

namespace aerocal::calib {

struct MetashapeFrameModel : ForwardCameraModel<MetashapeFrameModel> {
  static constexpr CameraModelId kId = CameraModelId::kMetashapeFrame;
  static constexpr std::string_view kName = "metashape_frame";
  enum Index : int { kF, kCx, kCy, kB1, kB2, kK1, kK2, kK3, kK4, kP1, kP2, kP3, kP4, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{
      {"f", "px", ParamGroup::kPrincipalDistance},
      {"cx", "px", ParamGroup::kPrincipalPoint},
      {"cy", "px", ParamGroup::kPrincipalPoint},
      {"b1", "px", ParamGroup::kAffinity},
      {"b2", "px", ParamGroup::kAffinity},
      {"k1", "1", ParamGroup::kRadial},
      {"k2", "1", ParamGroup::kRadial},
      {"k3", "1", ParamGroup::kRadial},
      {"k4", "1", ParamGroup::kRadial},
      {"p1", "1", ParamGroup::kDecentering},
      {"p2", "1", ParamGroup::kDecentering},
      {"p3", "1", ParamGroup::kDecentering},
      {"p4", "1", ParamGroup::kDecentering},
  }};
  static constexpr double kPixelOffset = 0.5;  // centre of the top-left pixel at (0.5, 0.5)

  template <typename T>
  static void Project(const T* p, const PixelFrame& frame, const T* n, T* pixel) {
    const T x = n[0], y = n[1], r2 = x * x + y * y;
    const T radial = T(1) + r2 * (p[kK1] + r2 * (p[kK2] + r2 * (p[kK3] + r2 * p[kK4])));
    const T tangential = T(1) + r2 * (p[kP3] + r2 * p[kP4]);
    const T xd = x * radial + (p[kP1] * (r2 + T(2) * x * x) + T(2) * p[kP2] * x * y) * tangential;
    const T yd = y * radial + (p[kP2] * (r2 + T(2) * y * y) + T(2) * p[kP1] * x * y) * tangential;
    const T u = T(0.5 * frame.width_px) + p[kCx] + xd * (p[kF] + p[kB1]) + yd * p[kB2];
    const T v = T(0.5 * frame.height_px) + p[kCy] + yd * p[kF];
    pixel[0] = u - T(kPixelOffset);
    pixel[1] = v - T(kPixelOffset);
  }
  template <typename T>
  static T PrincipalDistanceMm(const T* p, const PixelFrame& frame) {
    return p[kF] * T(frame.pixel_size_mm);
  }
  static bool ToOpenCv(const double* p, const PixelFrame& frame, OpenCvParams* cv) {
    using M = OpenCvModel;
    cv->fill(0.0);
    (*cv)[M::kFx] = p[kF] + p[kB1];
    (*cv)[M::kFy] = p[kF];
    (*cv)[M::kCx] = 0.5 * frame.width_px + p[kCx] - kPixelOffset;
    (*cv)[M::kCy] = 0.5 * frame.height_px + p[kCy] - kPixelOffset;
    (*cv)[M::kK1] = p[kK1];
    (*cv)[M::kK2] = p[kK2];
    (*cv)[M::kK3] = p[kK3];
    (*cv)[M::kP1] = p[kP2];
    (*cv)[M::kP2] = p[kP1];
    return p[kB2] == 0.0 && p[kK4] == 0.0 && p[kP3] == 0.0 && p[kP4] == 0.0;
  }
  static bool FromOpenCv(const OpenCvParams& cv, const PixelFrame& frame, double* p) {
    using M = OpenCvModel;
    for (int i = 0; i < kNumParams; ++i) p[i] = 0.0;
    p[kF] = cv[M::kFy];
    p[kB1] = cv[M::kFx] - cv[M::kFy];
    p[kCx] = cv[M::kCx] + kPixelOffset - 0.5 * frame.width_px;
    p[kCy] = cv[M::kCy] + kPixelOffset - 0.5 * frame.height_px;
    p[kK1] = cv[M::kK1];
    p[kK2] = cv[M::kK2];
    p[kK3] = cv[M::kK3];
    p[kP1] = cv[M::kP2];
    p[kP2] = cv[M::kP1];
    return cv[M::kK4] == 0.0 && cv[M::kK5] == 0.0 && cv[M::kK6] == 0.0;
  }
};

}  // namespace aerocal::calib
