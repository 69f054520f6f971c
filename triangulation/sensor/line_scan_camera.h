// The line (pushbroom) camera as a sensor kind (imaging_model.h; CONVENTIONS.md "Line (pushbroom)
// cameras"; issue 17). Its calibration from cloud control points runs it:
// triangulation/pushbroom/line_calibration.h (CalibrateLineCamera).
//
// Observations: a detector position (col) on a scan line (row) of the strip: an ImageObservation
// whose `image` is the strip id (kLineStripImage), `pixel` = (col, row), `line` its line in
// observations.csv (named in errors). A pose per SCAN LINE, not per exposure: the kind owns its
// trajectory, the POS (pos_trajectory.h) interpolated to the line plus smooth corrections, a
// uniform cubic B-spline in the line index with nodes every `node_spacing_lines` lines
// (calib::CubicBSplineWeights); it does not use the platform's per-exposure poses
// (SensorContext::poses).
//
// Blocks the kind owns, registered in this order (RegisterBlocks):
//   "nodeJ"           per spline node J: dX, dY, dZ (m), domega, dphi, dkappa (rad), added to the
//                     POS position and angles; start 0
//   "detector_ID"     per sub-camera ID: a_0..a_5, b_0..b_5 (mm), the calibration polynomials in
//                     the sub-camera's normalised index (calib/camera/line_camera.h); start 0 (on
//                     top of the file's calibration); which entries are fixed is the caller's
//                     (degree: SetFixedDetectorEntries); the datum is the caller's too
//                     (LineDatumResidual below, on the reference sub-camera's block)
//   "c"               principal distance (mm), fixed unless `free_c`
//   "mount"           boresight M omega, phi, kappa (rad), camera -> body; fixed | free | weighted
//   "lever_arm"       camera centre in the body frame (m); fixed | free | weighted
//   "time_offset"     dt (s): the line's true time minus its pos.csv time (shutter / POS latency),
//                     to first order through the POS velocity and attitude rate; fixed at 0
//                     unless `time_offset`
// Residual of an observation: calib::LineCollinearityResidual (group kGroupLineImage): the angle
// between the detector's ray and the ray to the point in a frame attached to the table
// (calib/residuals/line_ray_angle.h; invariant under the camera's rotation and scale), weighted in
// pixels at the file's c and table and rescaled to the current angle per detector and per line
// (the start range to the point from the POS, the file's lever arm and the point's start value);
// blocks node J .. J+3, detector, c, mount, lever_arm, time_offset, point.
// Own residuals (AddOwnResiduals): the POS prior on every node (group kGroupPosPrior, around 0 with
// the POS sigmas) when `pos_prior`; the weighted boresight and lever arm around the file's values
// (group kGroupLinePrior).
#pragma once

#include "calib/camera/line_camera.h"
#include "calib/residuals/autodiff_residual.h"
#include "calib/residuals/line_collinearity.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/imaging_model.h"

#include <Eigen/Core>

#include <array>
#include <cmath>
#include <vector>

namespace aerocal::triangulation {

inline constexpr const char* kGroupLineImage = "line_image";
inline constexpr const char* kGroupPosPrior = "pos_prior";
/// Owner of the line camera's mounted blocks (boresight, lever arm): their priors are in group
/// calib::PriorGroup(kLineOwner) = kGroupLinePrior (calib/problem/mounted_block.h).
inline constexpr const char* kLineOwner = "line";
inline constexpr const char* kGroupLinePrior = "line_prior";  // boresight / lever-arm priors
inline constexpr const char* kLineStripImage = "strip";       // the image id of a line strip
inline constexpr const char* kGroupLineDatum = "line_datum";  // the reference sub-camera's datum

/// The Legendre constant and linear components over u in [-1, 1] of the polynomial
/// sum_k a[k] u^k (n terms): mean = sum over even k of a_k / (k + 1) (P0 = 1), slope = sum over
/// odd k of 3 a_k / (k + 2) (P1 = u, (3/2) int u p(u) du). They do not change when a higher
/// Legendre term is added or dropped: the datum of the reference sub-camera (module README
/// "Datum") fixes them, so it does not depend on the polynomial degree.
template <typename T>
void LegendreMeanAndSlope(const T* a, int n, T* mean, T* slope) {
  *mean = T(0.0);
  *slope = T(0.0);
  for (int k = 0; k < n; ++k)
    if (k % 2 == 0)
      *mean += a[k] / double(k + 1);
    else
      *slope += a[k] * (3.0 / double(k + 2));
}

/// The datum of the reference sub-camera: its correction's Legendre mean and slope are zero, per
/// axis (r = [mean_x, slope_x, mean_y, slope_y] / sigma_mm, [4, unitless]; block: the detector
/// polynomials a_0..a_5, b_0..b_5, mm). A pseudo-observation as tight as the datum must be
/// (`sigma_mm` ~ 1e-4 px: its own variance is ~1e-3 of a table's); it replaces the four fixed
/// entries of the earlier datum (a_0 = a_1 = b_0 = b_1 = 0), so the redundancy is the same.
struct LineDatumResidual : calib::AutoDiffResidual<LineDatumResidual, 4, 2 * calib::kLineMaxTerms> {
  explicit LineDatumResidual(double sigma_mm) : inverse_sigma_(1.0 / sigma_mm) {}
  template <typename T>
  bool operator()(const T* coefficients, T* r) const {
    for (int axis = 0; axis < 2; ++axis) {
      LegendreMeanAndSlope(coefficients + axis * calib::kLineMaxTerms,
                           calib::kLineMaxTerms,
                           &r[2 * axis],
                           &r[2 * axis + 1]);
      r[2 * axis] *= inverse_sigma_;
      r[2 * axis + 1] *= inverse_sigma_;
    }
    return true;
  }
  double inverse_sigma_;
};

/// Focal-plane position (mm) of `point` seen from the pose of `trajectory` at (fractional) `line`
/// through `camera`'s mount and lever arm (no spline corrections); false when it lies on or behind
/// the camera.
bool ProjectAtLine(const calib::LineCamera& camera,
                   const PosTrajectory& trajectory,
                   double line,
                   const Eigen::Vector3d& point,
                   Eigen::Vector2d* xy);

/// What the line camera estimates (the data are the camera file and the POS).
struct LineScanOptions {
  int node_spacing_lines = 100;  // spline node spacing, lines, >= 1
  bool free_c = false;           // estimate c
  bool pos_prior = true;         // POS sigmas as priors on every node
  Eigen::Vector3d pos_sigma_center_m = Eigen::Vector3d::Constant(0.05);                 // > 0
  Eigen::Vector3d pos_sigma_opk_rad = Eigen::Vector3d::Constant(0.005 * M_PI / 180.0);  // > 0
  PlatformParamMode boresight = PlatformParamMode::kFixed;  // the camera file's mount M
  double boresight_sigma_rad = 0.0;                         // weighted: per angle, > 0
  PlatformParamMode lever_arm = PlatformParamMode::kFixed;  // the camera file's lever arm
  double lever_arm_sigma_m = 0.0;                           // weighted: per axis, > 0
  bool time_offset = false;                                 // estimate the time offset dt
};

/// Where a detector position lies: its sub-camera and normalised index u in [-1, 1].
struct LineDetectorSite {
  int subcamera = 0;
  double u = 0.0;
};

/// What Observe built for one observation (bookkeeping of the calibration: RMS, plots, segments).
struct LineTerm {
  int subcamera = 0;
  double detector = 0.0, u = 0.0;
  // Focal-plane sigmas x and y: the residual is their first-order equivalent in angle, so
  // r * sigma_mm is the focal-plane misclosure (mm) to first order.
  Eigen::Vector2d sigma_mm = Eigen::Vector2d::Zero();
  int segment = 0;  // first of its four spline nodes
};

class LineScanCamera final : public ImagingModel {
 public:
  using Vector6d = Eigen::Matrix<double, 6, 1>;
  using DetectorValues = std::array<double, 2 * calib::kLineMaxTerms>;

  /// `camera` and `pos` must outlive the kind.
  LineScanCamera(const calib::LineCamera& camera,
                 const PosTrajectory& pos,
                 const LineScanOptions& options);
  SensorKind Kind() const override { return SensorKind::kLine; }
  /// Observations of the strip (image kLineStripImage).
  bool Measures(const ImageObservation& observation) const;
  /// Nodes, detector polynomials, c, mount, lever arm (header comment), fixed per the options.
  void RegisterBlocks(const SensorContext& context) override;
  /// The detector's ray at its line's pose (POS + spline corrections) through the mount, lever arm
  /// and the calibrated detector position, at the blocks' current values.
  ImageRay StartingRay(const SensorContext& context,
                       const ImageObservation& observation) const override;
  /// Group kGroupLineImage. InputError "observations_file:LINE" for a detector outside the
  /// camera or a line outside the POS. The whitening uses the point block's current values (the
  /// image motion of one line at that point).
  ObservationTerm Observe(const SensorContext& context,
                          const ImageObservation& observation,
                          calib::BlockId point) override;
  /// POS priors on the nodes; weighted boresight and lever arm.
  void AddOwnResiduals(const SensorContext& context) override;

  /// Sub-camera and normalised index of a detector position (nearest detector's sub-camera).
  LineDetectorSite DetectorSite(double detector) const;
  /// Body pose at a (fractional) line: the POS plus the spline corrections' current values.
  void PoseAtLine(double line, Eigen::Vector3d* center_m, Eigen::Vector3d* opk_rad) const;
  int NumNodes() const { return static_cast<int>(nodes_.size()); }
  const std::vector<calib::BlockId>& NodeBlocks() const { return node_blocks_; }
  const std::vector<Vector6d>& Nodes() const { return nodes_; }
  const std::vector<calib::BlockId>& DetectorBlocks() const { return detector_blocks_; }
  const std::vector<DetectorValues>& Detectors() const { return detector_; }
  /// Sets the fixed entries of sub-camera s's polynomial block (their values to 0; the others
  /// free): degree and datum are the calibration's.
  void SetFixedDetectorEntries(calib::ProblemBuilder& builder,
                               int s,
                               const std::vector<int>& fixed);
  calib::BlockId CBlock() const { return c_block_; }
  calib::BlockId MountBlock() const { return mount_block_; }
  calib::BlockId LeverArmBlock() const { return lever_block_; }
  calib::BlockId TimeOffsetBlock() const { return time_block_; }
  double TimeOffsetS() const { return time_offset_s_; }
  double CMm() const { return c_; }
  const Eigen::Vector3d& MountRad() const { return mount_; }
  const Eigen::Vector3d& LeverArmM() const { return lever_; }
  const LineScanOptions& options() const { return options_; }
  /// One per Observe call, in call order.
  const std::vector<LineTerm>& Terms() const { return terms_; }

 private:
  const calib::LineCamera& camera_;
  const PosTrajectory& pos_;
  LineScanOptions options_;
  std::vector<std::pair<int, int>> ranges_;
  // Sized once in RegisterBlocks: the builder holds their addresses.
  std::vector<Vector6d> nodes_;
  std::vector<DetectorValues> detector_;
  double c_ = 0.0;
  Eigen::Vector3d mount_ = Eigen::Vector3d::Zero(), lever_ = Eigen::Vector3d::Zero();
  double time_offset_s_ = 0.0;
  std::vector<calib::BlockId> node_blocks_, detector_blocks_;
  calib::BlockId c_block_ = -1, mount_block_ = -1, lever_block_ = -1, time_block_ = -1;
  std::vector<LineTerm> terms_;
};

}  // namespace aerocal::triangulation
