// Pix4D's perspective-lens model (Pix4Dmapper / PIX4Dmatic internal camera parameters as the .cam
// file and the quality report give them: focal length F and principal point (Px, Py) in mm,
// radial R1-R3, tangential T1-T2), an exact parameter mapping onto OpenCvModel.
//
// Sources and what they settle (checked 2026-11-24, issue 15):
// - Pix4D support, "How are the Internal and External Camera Parameters defined?"
//   (support.pix4d.com/hc/en-us/articles/202559089): the distorted homogeneous point is
//     x_hd = x_h (1 + R1 r^2 + R2 r^4 + R3 r^6) + 2 T1 x_h y_h + T2 (r^2 + 2 x_h^2)
//     y_hd = y_h (1 + R1 r^2 + R2 r^4 + R3 r^6) + T1 (r^2 + 2 y_h^2) + 2 T2 x_h y_h
//   and the pixel f (x_hd, y_hd) + (cx, cy): OpenCV's form with T1 in p1's place and T2 in p2's.
//   Its formulas are images; its figure text puts the image origin at the lower-left corner with
//   y up, which read literally would flip the sign of T1 and measure Py from the bottom.
// - Pix4D's own code and files do NOT flip: Pix4D's pyopf (github.com/Pix4D/pyopf,
//   src/pyopf/cameras/sensor_internals.py) defines the perspective internals "as described in"
//   that article with the "principal point with respect to the top left corner in pixels";
//   its opf2colmap converter copies (R1, R2, R3, T1, T2) and the principal point unchanged into
//   COLMAP's OPENCV / FULL_OPENCV (k1, k2, k3, p1, p2, cx, cy), and its undistorter applies T1 as
//   OpenCV's p1 in a y-down pixel frame. Pix4Dmapper's calibrated_camera_parameters.txt (the same
//   radial and tangential values as the .cam) states "camera model m = K [R|-Rt] X", a y-down
//   OpenCV camera matrix (docs.nframes.com, "Pix4D" orientation formats, quotes a real file); and
//   EasyIDP (a tool that projects into real Pix4D projects' images) applies T1, T2 the same way.
// So: Px, Py are mm from the top-left CORNER, y down; T1 = p1, T2 = p2. Not settled: whether
// Pix4D's pixel centres sit at +0.5 (corner origin, COLMAP's convention, as the wording says and
// as assumed here) or at integers (pyopf's undistorter indexes them so): 0.5 px in cx, cy.
// Conventions converted HERE (ExpandToOpenCv), nowhere else:
//   - mm -> px: fx = fy = F / p;
//   - top-left CORNER origin -> OpenCV (top-left pixel centre at 0): cx = Px / p - 0.5,
//     cy = Py / p - 0.5;
//   - tangential terms as OpenCV's: p1 = T1, p2 = T2.
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
    cv[M::kCy] = p[kPy] / pixel - T(0.5);
    cv[M::kK1] = p[kR1];
    cv[M::kK2] = p[kR2];
    cv[M::kK3] = p[kR3];
    cv[M::kP1] = p[kT1];
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
    p[kPy] = (cv[M::kCy] + 0.5) * pixel;
    p[kR1] = cv[M::kK1];
    p[kR2] = cv[M::kK2];
    p[kR3] = cv[M::kK3];
    p[kT1] = cv[M::kP1];
    p[kT2] = cv[M::kP2];
    return cv[M::kFx] == cv[M::kFy] && cv[M::kK4] == 0.0 && cv[M::kK5] == 0.0 && cv[M::kK6] == 0.0;
  }
};

}  // namespace aerocal::calib
