// Pix4D's perspective-lens model (Pix4Dmapper / PIX4Dmatic internal camera parameters as the .cam
// file and the quality report give them: focal length F and principal point (Px, Py) in mm,
// radial R1-R3, tangential T1-T2), an exact parameter mapping onto OpenCvModel.
//
// Source: Pix4D support, "How are the Internal and External Camera Parameters defined?"
// (support.pix4d.com/hc/en-us/articles/202559089): the camera frame follows the PATB convention
// (x right, y up, the camera looking along -Z); "the origin of the image coordinate system is at
// the lower-left corner of the image"; the distorted homogeneous point is
//   x_hd = x_h (1 + R1 r^2 + R2 r^4 + R3 r^6) + 2 T1 x_h y_h + T2 (r^2 + 2 x_h^2)
//   y_hd = y_h (1 + R1 r^2 + R2 r^4 + R3 r^6) + T1 (r^2 + 2 y_h^2) + 2 T2 x_h y_h
// and the image point is F (x_hd, y_hd) + (Px, Py). The page gives its formulas as images; what is
// written here is our reading of its text (x_h, y_h = the normalised ray in that y-up frame), not
// yet checked against a file written by Pix4D: a real .cam file with its quality-report pixels is
// the test that settles it.
// Conventions converted HERE (ExpandToOpenCv), nowhere else:
//   - mm -> px: fx = fy = F / p;
//   - lower-left CORNER origin, y up -> OpenCV (top-left pixel centre, y down):
//     cx = Px / p - 0.5,  cy = H - 0.5 - Py / p;
//   - the y flip changes the sign of the tangential term that pairs with y: p1 = -T1, p2 = T2.
#pragma once

#include "calib/camera/models/opencv.h"

namespace aerocal::calib {

struct Pix4dPerspectiveModel : ForwardCameraModel<Pix4dPerspectiveModel> {
  static constexpr CameraModelId kId = CameraModelId::kPix4dPerspective;
  static constexpr std::string_view kName = "pix4d_perspective";
  enum Index : int { kF, kPx, kPy, kR1, kR2, kR3, kT1, kT2, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{
      {"F", "mm", ParamGroup::kPrincipalDistance},
      {"Px", "mm", ParamGroup::kPrincipalPoint},
      {"Py", "mm", ParamGroup::kPrincipalPoint},
      {"R1", "1", ParamGroup::kRadial},
      {"R2", "1", ParamGroup::kRadial},
      {"R3", "1", ParamGroup::kRadial},
      {"T1", "1", ParamGroup::kDecentering},
      {"T2", "1", ParamGroup::kDecentering},
  }};

  template <typename T>
  static void ExpandToOpenCv(const T* p, const PixelFrame& frame, T* cv) {
    using M = OpenCvModel;
    for (int j = 0; j < M::kNumParams; ++j) cv[j] = T(0);
    const T pixel = T(frame.pixel_size_mm);
    cv[M::kFx] = p[kF] / pixel;
    cv[M::kFy] = p[kF] / pixel;
    cv[M::kCx] = p[kPx] / pixel - T(0.5);
    cv[M::kCy] = T(frame.height_px - 0.5) - p[kPy] / pixel;
    cv[M::kK1] = p[kR1];
    cv[M::kK2] = p[kR2];
    cv[M::kK3] = p[kR3];
    cv[M::kP1] = -p[kT1];
    cv[M::kP2] = p[kT2];
  }
  template <typename T>
  static void Project(const T* p, const PixelFrame& frame, const T* n, T* pixel) {
    T cv[OpenCvModel::kNumParams];
    ExpandToOpenCv(p, frame, cv);
    OpenCvModel::Project(cv, frame, n, pixel);
  }
  template <typename T>
  static T PrincipalDistanceMm(const T* p, const PixelFrame&) {
    return p[kF];
  }
  static bool ToOpenCv(const double* p, const PixelFrame& frame, OpenCvParams* cv) {
    ExpandToOpenCv(p, frame, cv->data());
    return true;
  }
  /// Exact when fx = fy and k4 = k5 = k6 = 0; otherwise F from fy as a starting value.
  static bool FromOpenCv(const OpenCvParams& cv, const PixelFrame& frame, double* p) {
    using M = OpenCvModel;
    const double pixel = frame.pixel_size_mm;
    p[kF] = cv[M::kFy] * pixel;
    p[kPx] = (cv[M::kCx] + 0.5) * pixel;
    p[kPy] = (frame.height_px - 0.5 - cv[M::kCy]) * pixel;
    p[kR1] = cv[M::kK1];
    p[kR2] = cv[M::kK2];
    p[kR3] = cv[M::kK3];
    p[kT1] = -cv[M::kP1];
    p[kT2] = cv[M::kP2];
    return cv[M::kFx] == cv[M::kFy] && cv[M::kK4] == 0.0 && cv[M::kK5] == 0.0 &&
           cv[M::kK6] == 0.0;
  }
};

}  // namespace aerocal::calib
