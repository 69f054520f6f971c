// What every camera model shares (STYLE.md section 4): the parameter table types, the frozen model
// ids, and the two generic pieces the models are built from:
// - InvertMap2: Newton inversion of a templated 2D map, usable with ceres::Jet (the iteration runs
//   on the values; one last Newton step in T carries the derivatives: the implicit-function
//   derivative, exact at convergence).
// - ForwardCameraModel<Derived>: for a model that maps ideal normalised camera coordinates to
//   pixels (OpenCV, COLMAP, Metashape, Pix4D: "forward" distortion), the uniform pair
//   MeasuredFromIdeal (closed form) / IdealFromMeasured (Newton) in photo mm.
//
// The uniform pair every model provides (camera_model.h), in the CONVENTIONS.md frames:
//   measured_mm: photo coordinates (x, y) mm of the measured image point (pixel_frame.h);
//   ideal_mm:    ideal image coordinates reduced to the principal point, y up, at the model's
//                principal distance c = PrincipalDistanceMm(params, frame):
//                ideal_mm = c * (-U / W, -V / W) for the image-space ray (U, V, W)
//                (the camera looks along -W; CONVENTIONS.md collinearity).
#pragma once

#include "calib/camera/pixel_frame.h"

#include <Eigen/Core>
#include <Eigen/LU>
#include <ceres/jet.h>

#include <array>
#include <cmath>
#include <string_view>

namespace aerocal::calib {

enum class ParamGroup { kPrincipalDistance, kPrincipalPoint, kRadial, kDecentering, kAffinity };

struct ParamInfo {
  std::string_view name;
  std::string_view unit;
  ParamGroup group;
};

/// The group's name in files and results: principal_distance, principal_point, radial,
/// decentering, affinity.
constexpr std::string_view ParamGroupName(ParamGroup group) {
  switch (group) {
    case ParamGroup::kPrincipalDistance:
      return "principal_distance";
    case ParamGroup::kPrincipalPoint:
      return "principal_point";
    case ParamGroup::kRadial:
      return "radial";
    case ParamGroup::kDecentering:
      return "decentering";
    case ParamGroup::kAffinity:
      return "affinity";
  }
  return "";
}

/// Registered camera models. The numbers are FROZEN: files and results store them; a removed
/// model's number is never reused. A new model takes the next free number.
enum class CameraModelId : int {
  kBrownFraser10 = 1,        // ours, correction form (brown_fraser10.h)
  kOpenCv = 2,               // OpenCV pinhole + k1-k6, p1, p2 (models/opencv.h)
  kOpenCvFisheye = 3,        // OpenCV fisheye k1-k4 (models/opencv.h)
  kColmapSimplePinhole = 4,  // COLMAP models (models/colmap.h)
  kColmapPinhole = 5,
  kColmapSimpleRadial = 6,
  kColmapRadial = 7,
  kColmapOpenCv = 8,
  kColmapFullOpenCv = 9,
  kMetashapeFrame = 10,    // Agisoft Metashape frame camera (models/metashape.h)
  kPix4dPerspective = 11,  // Pix4D perspective lens (models/pix4d.h)
};

/// Index of a parameter by its table name; -1 when unknown.
template <size_t N>
constexpr int IndexOfParam(const std::array<ParamInfo, N>& table, std::string_view name) {
  for (size_t i = 0; i < N; ++i)
    if (table[i].name == name) return static_cast<int>(i);
  return -1;
}

/// The value of a double or of a (nested) ceres::Jet.
inline double ValueOf(double v) { return v; }
template <typename U, int K>
double ValueOf(const ceres::Jet<U, K>& j) {
  return ValueOf(j.a);
}

/// Solves f(params, x) = target for x (2D) by Newton from `start`. `f` is a generic callable
/// f(const S* params, const S* x, S* y) for any scalar S (double, Jet). The iteration runs on the
/// values; a final Newton step in T gives `out` the derivatives of the implicit solution with
/// respect to params and target. The solution must lie on the branch of the map that holds
/// `centre` (where the map is the identity-like part of a lens: the principal point): a Newton
/// run from `start` that does not converge, or converges where the map is folded (det J <= 0, the
/// far side of a turning point of the distortion polynomial), is redone by continuation from
/// `centre` (the target moved there from f(centre) in steps). False when neither reaches the
/// target to |step| < tolerance on that branch (the target lies beyond the fold: not invertible).
template <int kNumParams, typename T, typename F>
bool InvertMap2(const F& f,
                const T* params,
                const T* target,
                const double* start,
                T* out,
                double tolerance,
                int max_iterations = 50,
                const double* centre = nullptr) {
  using J = ceres::Jet<double, 2>;
  J pj[kNumParams];
  for (int i = 0; i < kNumParams; ++i) pj[i] = J(ValueOf(params[i]));
  const Eigen::Vector2d goal(ValueOf(target[0]), ValueOf(target[1]));
  Eigen::Matrix2d jacobian;
  // f and its Jacobian at x.
  const auto evaluate = [&](const Eigen::Vector2d& x) {
    const J xj[2] = {J(x.x(), 0), J(x.y(), 1)};
    J y[2];
    f(pj, xj, y);
    jacobian << y[0].v[0], y[0].v[1], y[1].v[0], y[1].v[1];
    return Eigen::Vector2d(y[0].a, y[1].a);
  };
  // Newton towards `aim` from *x; true when it converged on the unfolded branch.
  const auto newton = [&](const Eigen::Vector2d& aim, Eigen::Vector2d* x, int iterations) {
    for (int iteration = 0; iteration < iterations; ++iteration) {
      const Eigen::Vector2d error = evaluate(*x) - aim;  // sets `jacobian` at *x
      const Eigen::Vector2d step = jacobian.partialPivLu().solve(error);
      if (!step.allFinite()) return false;
      *x -= step;
      if (step.norm() < tolerance) {
        evaluate(*x);
        return jacobian.determinant() > 0;
      }
    }
    return false;
  };
  const Eigen::Vector2d middle =
      centre ? Eigen::Vector2d(centre[0], centre[1]) : Eigen::Vector2d::Zero();
  // The branch of `centre`: no fold (det J <= 0) on the segment from it to the solution.
  const auto on_centre_branch = [&](const Eigen::Vector2d& x) {
    for (int k = 1; k < 8; ++k) {
      evaluate(middle + (x - middle) * (k / 8.0));
      if (!(jacobian.determinant() > 0)) return false;
    }
    return true;
  };
  Eigen::Vector2d x(start[0], start[1]);
  if (!newton(goal, &x, max_iterations) || !on_centre_branch(x)) {
    x = middle;
    const Eigen::Vector2d from = evaluate(x);
    if (!from.allFinite() || !(jacobian.determinant() > 0)) return false;
    constexpr int kSteps = 32;
    for (int k = 1; k <= kSteps; ++k) {
      const Eigen::Vector2d aim = from + (goal - from) * (double(k) / kSteps);
      if (!newton(aim, &x, k == kSteps ? max_iterations : 20)) return false;
    }
  }
  evaluate(x);
  const Eigen::Matrix2d inverse = jacobian.inverse();
  const T xt[2] = {T(x.x()), T(x.y())};
  T y[2];
  f(params, xt, y);
  const T d0 = y[0] - target[0], d1 = y[1] - target[1];
  out[0] = xt[0] - (T(inverse(0, 0)) * d0 + T(inverse(0, 1)) * d1);
  out[1] = xt[1] - (T(inverse(1, 0)) * d0 + T(inverse(1, 1)) * d1);
  return true;
}

/// The 12 OpenCV parameters every model maps to and from for the closed-form conversions
/// (OpenCvModel's order: fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6; OpenCV pixels: top-left
/// pixel centre (0, 0), y down).
using OpenCvParams = std::array<double, 12>;

/// Base of the models whose distortion is FORWARD: Derived provides
///   template <T> static void Project(const T* params, const PixelFrame&, const T* n, T* pixel)
///     normalised OpenCV-frame camera coordinates n = (X/Z, Y/Z) (x right, y down, z forward) ->
///     aerocal pixel (col, row) (pixel_frame.h), in ONE function holding its pixel convention;
///   template <T> static T PrincipalDistanceMm(const T* params, const PixelFrame&);
///   static bool ToOpenCv(const double* params, const PixelFrame&, OpenCvParams*) (true: exact;
///     false: the pinhole part filled as a starting value).
/// and gets the uniform pair in photo mm. aerocal's ideal (y up) is OpenCV's n with y negated.
template <typename Derived>
struct ForwardCameraModel {
  static constexpr bool kCorrectionForm = false;
  /// The free set of a calibration when none is given: every parameter (a model that knows
  /// better hides this with its own kDefaultFree, as OpenCvModel does).
  static constexpr std::string_view kDefaultFree = "all";

  template <typename T>
  static bool MeasuredFromIdeal(const T* params,
                                const PixelFrame& frame,
                                const T* ideal_mm,
                                T* measured_mm) {
    const T c = Derived::PrincipalDistanceMm(params, frame);
    const T n[2] = {ideal_mm[0] / c, -ideal_mm[1] / c};
    T pixel[2];
    Derived::Project(params, frame, n, pixel);
    frame.PhotoFromPixel(pixel, measured_mm);
    return true;
  }

  /// Newton inversion of Project, started at the pinhole inverse; tolerance 1e-13 in normalised
  /// coordinates (~1e-9 px at f = 10000 px).
  template <typename T>
  static bool IdealFromMeasured(const T* params,
                                const PixelFrame& frame,
                                const T* measured_mm,
                                T* ideal_mm) {
    T pixel[2];
    frame.PixelFromPhoto(measured_mm, pixel);
    double values[Derived::kNumParams];
    for (int i = 0; i < Derived::kNumParams; ++i) values[i] = ValueOf(params[i]);
    OpenCvParams cv;
    Derived::ToOpenCv(values, frame, &cv);
    const double start[2] = {(ValueOf(pixel[0]) - cv[2]) / cv[0],
                             (ValueOf(pixel[1]) - cv[3]) / cv[1]};
    T n[2];
    const auto project = [&frame](const auto* p, const auto* x, auto* y) {
      Derived::Project(p, frame, x, y);
    };
    if (!InvertMap2<Derived::kNumParams>(project, params, pixel, start, n, 1e-13)) return false;
    const T c = Derived::PrincipalDistanceMm(params, frame);
    ideal_mm[0] = c * n[0];
    ideal_mm[1] = -c * n[1];
    return true;
  }
};

}  // namespace aerocal::calib
