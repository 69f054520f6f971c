// A line (pushbroom) camera, CONVENTIONS.md "Line (pushbroom) cameras", file: FORMATS.md "Line
// camera". Several physical line cameras (sub-cameras, e.g. three tilted -20 / 0 / +20 deg across
// track, optical axes meeting in one point) are combined into ONE virtual line camera:
//
// - detectors i = 0 .. N-1 in one sequence over all sub-cameras; sub-camera k owns [first, last];
// - the virtual camera has principal distance c (mm), pitch p (mm), looks along -z, line along x
//   (across track), y along track; it is mounted in the body by M = Rx Ry Rz(mount) and the lever
//   arm t (m, its projection centre in the body frame);
// - DESIGN position of detector i: without sub-cameras the straight line ((i - (N-1)/2) p, 0);
//   with sub-cameras, detector j = i - first of sub-camera k (its own c_k, p_k, mount M_k into the
//   virtual camera frame) is the ray M_k [(j - (n_k-1)/2) p_k, 0, -c_k]^T projected onto the
//   virtual focal plane: x = -c d_x / d_z, y = -c d_y / d_z (the patent's "stitching with the
//   design parameters");
// - CALIBRATION (dx_i, dy_i) mm is added to the design position: x_i = design_x(i) + dx_i,
//   y_i = design_y(i) + dy_i. Without sub-cameras this is CONVENTIONS' x_i = (i - (N-1)/2) p +
//   dx_i, y_i = dy_i exactly. It is a table (one value per detector; linear interpolation at
//   fractional detector positions) or a polynomial per sub-camera in the NORMALISED index u = (2 i
//   - first - last) / (last - first) in [-1, 1]: dx(i) = sum_k a_k u^k (mm).
//
// The patent (GFHK camera) writes the line along its y axis: a file in that convention swaps x and
// y at the reader, never here.
#pragma once

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::calib {

/// One physical line camera of the combination (design values).
struct LineSubcamera {
  std::string id;
  int first = 0, last = 0;                              // detector range in the virtual sequence
  double c_mm = 0.0;                                    // its principal distance, > 0
  double pitch_mm = 0.0;                                // its detector pitch, > 0
  Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero();  // sub-camera -> virtual camera frame
  int Count() const { return last - first + 1; }
};

/// Polynomial calibration of one detector range (a sub-camera), coefficients in mm of the powers
/// of the normalised index u (see above).
struct LinePolynomial {
  int first = 0, last = 0;
  std::vector<double> dx, dy;  // a_0, a_1, ... (mm); either may be empty (zero)
  /// u in [-1, 1] of detector i (a range of one detector has u = 0).
  double Normalised(double i) const {
    return last > first ? (2.0 * i - first - last) / double(last - first) : 0.0;
  }
};

struct LineCamera {
  std::string name;
  int detectors = 0;                                      // N, > 0
  double pitch_mm = 0.0;                                  // p, > 0
  double c_mm = 0.0;                                      // principal distance, > 0
  Eigen::Vector3d mount_rad = Eigen::Vector3d::Zero();    // virtual camera -> body (rad)
  Eigen::Vector3d lever_arm_m = Eigen::Vector3d::Zero();  // camera centre in the body frame (m)
  std::vector<LineSubcamera> subcameras;                  // empty: one straight line
  /// Calibration: a table (size N each, or both empty) or polynomials (one per range).
  std::vector<double> dx_mm, dy_mm;
  std::vector<LinePolynomial> calibration;
  /// The file wrote the line along its camera y axis (`line_axis: y`, the patent's convention);
  /// the values above are converted to ours at the reader and back at the writer.
  bool file_line_along_y = false;

  /// Index of the sub-camera (or polynomial range) holding detector position i (rounded to the
  /// nearest detector); -1 when outside 0 .. N-1. Without sub-cameras: 0.
  int SubcameraOf(double i) const;
  /// Design focal-plane position (mm) of detector position i (fractional allowed).
  Eigen::Vector2d DesignPosition(double i) const;
  /// Calibration (dx, dy) mm at detector position i.
  Eigen::Vector2d Correction(double i) const;
  /// x_i, y_i (mm) = design + calibration.
  Eigen::Vector2d DetectorPosition(double i) const { return DesignPosition(i) + Correction(i); }
  /// The detector ranges of the sub-cameras ({0, N-1} without them).
  std::vector<std::pair<int, int>> Ranges() const;
  /// Throws InputError("FILE: ...") when the values break the rules of the file format.
  void Validate(const std::string& file) const;
};

/// Evaluates sum_k a[k] u^k (Horner); templated for Jets.
template <typename T>
T EvaluatePolynomial(const T* a, int n, const T& u) {
  T value = T(0);
  for (int k = n - 1; k >= 0; --k) value = value * u + a[k];
  return value;
}

/// Its derivative sum_k k a[k] u^(k-1) (Horner); templated for Jets.
template <typename T>
T EvaluatePolynomialDerivative(const T* a, int n, const T& u) {
  T value = T(0);
  for (int k = n - 1; k >= 1; --k) value = value * u + double(k) * a[k];
  return value;
}

/// The combination of `subcameras` into one virtual line camera with principal distance c_mm and
/// pitch_mm, numbered in sequence (their first/last are set here), no calibration.
LineCamera CombineLineCameras(const std::string& name,
                              std::vector<LineSubcamera> subcameras,
                              double c_mm,
                              double pitch_mm);

}  // namespace aerocal::calib
