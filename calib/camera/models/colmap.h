// COLMAP's pinhole-family camera models as EXACT parameter subsets of OpenCvModel
// (models/opencv.h): the distortion formula is OpenCV's, written once there.
//
// Source: COLMAP documentation "Camera Models" (https://colmap.github.io/cameras.html) and
// src/colmap/sensor/models.h: SIMPLE_PINHOLE (f, cx, cy), PINHOLE (fx, fy, cx, cy),
// SIMPLE_RADIAL (f, cx, cy, k), RADIAL (f, cx, cy, k1, k2), OPENCV (fx, fy, cx, cy, k1, k2, p1,
// p2), FULL_OPENCV (fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6); "SIMPLE_RADIAL, RADIAL ...
// are simplified versions of the OPENCV model"; models.h implements OPENCV and FULL_OPENCV with
// OpenCV's formula (same p1/p2 order, FULL_OPENCV's rational radial term).
// Pixel convention (the one conversion, kColmapPixelOffset): COLMAP puts the image origin at the
// top-left CORNER, the centre of the top-left pixel at (0.5, 0.5) (COLMAP FAQ / the
// `Camera::ImgFromCam` convention used by its feature extraction), so
//   cx_colmap = cx_opencv + 0.5,  cy_colmap = cy_opencv + 0.5.
// Mapping onto OpenCV is exact in both directions where the subset holds the parameters
// (f -> fx = fy; missing terms 0); FromOpenCv says false (not exact) otherwise.
#pragma once

#include "calib/camera/models/opencv.h"

namespace aerocal::calib {

inline constexpr double kColmapPixelOffset = 0.5;

/// A COLMAP model given by which OpenCV parameters each of its parameters sets: Traits has kId,
/// kName, kColmapName, Index, kNumParams, kParams and kSlots (per parameter a bit mask of
/// OpenCvModel indices).
template <typename Traits>
struct ColmapCameraModel : Traits, ForwardCameraModel<ColmapCameraModel<Traits>> {
  static constexpr int kNumParams = Traits::kNumParams;

  /// The OpenCV parameters (OpenCV pixel convention) of a COLMAP parameter vector.
  template <typename T>
  static void ExpandToOpenCv(const T* p, T* cv) {
    for (int j = 0; j < OpenCvModel::kNumParams; ++j) cv[j] = T(0);
    for (int i = 0; i < kNumParams; ++i)
      for (int j = 0; j < OpenCvModel::kNumParams; ++j)
        if (Traits::kSlots[i] & (1u << j)) cv[j] = p[i];
    cv[OpenCvModel::kCx] -= T(kColmapPixelOffset);
    cv[OpenCvModel::kCy] -= T(kColmapPixelOffset);
  }
  template <typename T>
  static void Project(const T* p, const PixelFrame& frame, const T* n, T* pixel) {
    T cv[OpenCvModel::kNumParams];
    ExpandToOpenCv(p, cv);
    OpenCvModel::Project(cv, frame, n, pixel);
  }
  template <typename T>
  static T PrincipalDistanceMm(const T* p, const PixelFrame& frame) {
    T cv[OpenCvModel::kNumParams];
    ExpandToOpenCv(p, cv);
    return OpenCvModel::PrincipalDistanceMm(cv, frame);
  }
  static bool ToOpenCv(const double* p, const PixelFrame&, OpenCvParams* cv) {
    ExpandToOpenCv(p, cv->data());
    return true;
  }
  /// Exact when every OpenCV term the model lacks is 0 and shared slots are equal (fx = fy for
  /// one focal length); otherwise the nearest subset (f = fy) as a starting value.
  static bool FromOpenCv(const OpenCvParams& cv_in, const PixelFrame&, double* p) {
    OpenCvParams cv = cv_in;
    cv[OpenCvModel::kCx] += kColmapPixelOffset;
    cv[OpenCvModel::kCy] += kColmapPixelOffset;
    unsigned covered = 0;
    bool exact = true;
    for (int i = 0; i < kNumParams; ++i) {
      covered |= Traits::kSlots[i];
      int slot = -1;  // the slot the parameter is read from: fy for a single focal length
      for (int j = 0; j < OpenCvModel::kNumParams && slot != OpenCvModel::kFy; ++j)
        if (Traits::kSlots[i] & (1u << j)) slot = j;
      p[i] = cv[slot];
      for (int j = 0; j < OpenCvModel::kNumParams; ++j)
        if ((Traits::kSlots[i] & (1u << j)) && cv[j] != p[i]) exact = false;
    }
    for (int j = 0; j < OpenCvModel::kNumParams; ++j)
      if (!(covered & (1u << j)) && cv[j] != 0.0) exact = false;
    return exact;
  }
};

namespace colmap_internal {
constexpr unsigned Bit(int opencv_index) { return 1u << opencv_index; }
using M = OpenCvModel;
inline constexpr ParamInfo kF{"f", "px", ParamGroup::kPrincipalDistance};
inline constexpr ParamInfo kFx{"fx", "px", ParamGroup::kPrincipalDistance};
inline constexpr ParamInfo kFy{"fy", "px", ParamGroup::kPrincipalDistance};
inline constexpr ParamInfo kCx{"cx", "px", ParamGroup::kPrincipalPoint};
inline constexpr ParamInfo kCy{"cy", "px", ParamGroup::kPrincipalPoint};

struct SimplePinhole {
  static constexpr CameraModelId kId = CameraModelId::kColmapSimplePinhole;
  static constexpr std::string_view kName = "colmap_simple_pinhole";
  static constexpr std::string_view kColmapName = "SIMPLE_PINHOLE";
  enum Index : int { kF_, kCx_, kCy_, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{kF, kCx, kCy}};
  static constexpr std::array<unsigned, kNumParams> kSlots = {
      {Bit(M::kFx) | Bit(M::kFy), Bit(M::kCx), Bit(M::kCy)}};
};
struct Pinhole {
  static constexpr CameraModelId kId = CameraModelId::kColmapPinhole;
  static constexpr std::string_view kName = "colmap_pinhole";
  static constexpr std::string_view kColmapName = "PINHOLE";
  enum Index : int { kFx_, kFy_, kCx_, kCy_, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{kFx, kFy, kCx, kCy}};
  static constexpr std::array<unsigned, kNumParams> kSlots = {
      {Bit(M::kFx), Bit(M::kFy), Bit(M::kCx), Bit(M::kCy)}};
};
struct SimpleRadial {
  static constexpr CameraModelId kId = CameraModelId::kColmapSimpleRadial;
  static constexpr std::string_view kName = "colmap_simple_radial";
  static constexpr std::string_view kColmapName = "SIMPLE_RADIAL";
  enum Index : int { kF_, kCx_, kCy_, kK_, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {
      {kF, kCx, kCy, {"k", "1", ParamGroup::kRadial}}};
  static constexpr std::array<unsigned, kNumParams> kSlots = {
      {Bit(M::kFx) | Bit(M::kFy), Bit(M::kCx), Bit(M::kCy), Bit(M::kK1)}};
};
struct Radial {
  static constexpr CameraModelId kId = CameraModelId::kColmapRadial;
  static constexpr std::string_view kName = "colmap_radial";
  static constexpr std::string_view kColmapName = "RADIAL";
  enum Index : int { kF_, kCx_, kCy_, kK1_, kK2_, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {
      {kF, kCx, kCy, {"k1", "1", ParamGroup::kRadial}, {"k2", "1", ParamGroup::kRadial}}};
  static constexpr std::array<unsigned, kNumParams> kSlots = {
      {Bit(M::kFx) | Bit(M::kFy), Bit(M::kCx), Bit(M::kCy), Bit(M::kK1), Bit(M::kK2)}};
};
struct OpenCv {
  static constexpr CameraModelId kId = CameraModelId::kColmapOpenCv;
  static constexpr std::string_view kName = "colmap_opencv";
  static constexpr std::string_view kColmapName = "OPENCV";
  enum Index : int { kFx_, kFy_, kCx_, kCy_, kK1_, kK2_, kP1_, kP2_, kNumParams };
  static constexpr std::array<ParamInfo, kNumParams> kParams = {{kFx,
                                                                 kFy,
                                                                 kCx,
                                                                 kCy,
                                                                 M::kParams[M::kK1],
                                                                 M::kParams[M::kK2],
                                                                 M::kParams[M::kP1],
                                                                 M::kParams[M::kP2]}};
  static constexpr std::array<unsigned, kNumParams> kSlots = {{Bit(M::kFx),
                                                               Bit(M::kFy),
                                                               Bit(M::kCx),
                                                               Bit(M::kCy),
                                                               Bit(M::kK1),
                                                               Bit(M::kK2),
                                                               Bit(M::kP1),
                                                               Bit(M::kP2)}};
};
struct FullOpenCv {
  static constexpr CameraModelId kId = CameraModelId::kColmapFullOpenCv;
  static constexpr std::string_view kName = "colmap_full_opencv";
  static constexpr std::string_view kColmapName = "FULL_OPENCV";
  enum Index : int { kNumParams = M::kNumParams };  // OpenCV's order and names
  static constexpr std::array<ParamInfo, kNumParams> kParams = M::kParams;
  static constexpr std::array<unsigned, kNumParams> kSlots = {{Bit(0),
                                                               Bit(1),
                                                               Bit(2),
                                                               Bit(3),
                                                               Bit(4),
                                                               Bit(5),
                                                               Bit(6),
                                                               Bit(7),
                                                               Bit(8),
                                                               Bit(9),
                                                               Bit(10),
                                                               Bit(11)}};
};
}  // namespace colmap_internal

using ColmapSimplePinholeModel = ColmapCameraModel<colmap_internal::SimplePinhole>;
using ColmapPinholeModel = ColmapCameraModel<colmap_internal::Pinhole>;
using ColmapSimpleRadialModel = ColmapCameraModel<colmap_internal::SimpleRadial>;
using ColmapRadialModel = ColmapCameraModel<colmap_internal::Radial>;
using ColmapOpenCvModel = ColmapCameraModel<colmap_internal::OpenCv>;
using ColmapFullOpenCvModel = ColmapCameraModel<colmap_internal::FullOpenCv>;

}  // namespace aerocal::calib
