// A multi-CCD camera's sub-images calibrated from directions in ONE adjustment (issue 36 item 6):
// the camera file's own model, one interior of the virtual focal plane (c, principal point,
// distortion) and per sub-image its mapping onto the virtual image (subimage_mapping.h), a
// direction measured at (u, v) in a raw sub-image (calib/residuals/direction.h,
// ModelSubimageDirectionResidual). One instrument rotation R (instrument_from_camera) for all
// sub-images: they sit behind one lens.
//
// What the directions determine (the datum). A transformation A of the virtual plane applied to
// every mapping at once (M_k -> A M_k) changes nothing the directions see when the interior and R
// can undo it: at a distortion-free interior the composite ray of a sub-image pixel is
// R K(c, x0, y0, B1, B2)^-1 A M_k, and K^-1 with R spans all plane projectivities, so A may be any
// transformation of the mappings' own kind: 2 (translation), 4 (conformal), 6 (affine),
// 8 (projective) null directions. With distortion these directions are separated only through the
// distortion's curvature (relative eigenvalues ~1e-6 .. 1e-9 of the scaled normal matrix at a
// typical lens), which defines no frame a user can rely on. The gauge is therefore derived from
// the rank of the normal matrix, not chosen: on the DESIGN problem, the start values with every
// radial, decentring and affinity term 0 and each observation replaced by the exact image of its
// target's (start) direction (zero residuals: at any other point a scale or a turn of the plane
// changes the residuals in proportion to themselves and the defect hides among eigenvalues of
// ~1e-10), with every observed sub-image's mapping free, the null space of the Jacobi-scaled
// normal matrix (relative threshold kSubimageGaugeThreshold) is computed
// (ProblemBuilder::NullSpace); its dimension d is the rank defect, and the d entries of the
// REFERENCE sub-image's mapping that span it (column-pivoted QR of the null vectors' rows in that
// block) are held at the camera file's values. The reference sub-image thereby realises the
// virtual focal plane; every other mapping, the interior and R are estimated relative to it. The
// design's normal matrix with the gauge is checked to be of full rank (rank_defect_with_gauge =
// 0); the adjustment itself runs on the measurements from the start values.
// With fewer interior terms free (e.g. B1, B2 held) the defect is smaller (a similarity: 4) and
// fewer reference entries are held.
#pragma once

#include "calib/camera/camera.h"
#include "triangulation/calibration/direction_calibration.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// Relative eigenvalue (of the Jacobi-scaled normal matrix) below which a direction is null: the
/// exact null directions of the distortion-free point are at rounding level (< 1e-14), the
/// determined ones of a direction calibration above 1e-8.
inline constexpr double kSubimageGaugeThreshold = 1e-11;

/// The datum of a sub-image calibration (see the header comment).
struct SubimageDirectionGauge {
  std::string reference;          // the sub-image whose mapping entries are held
  std::vector<std::string> held;  // the held entries' names (plain names of the mapping model)
  int rank_defect = 0;            // without the gauge (every observed mapping free)
  int rank_defect_with_gauge = 0;
  /// Smallest relative eigenvalues without the gauge (ascending; the defect's count is below
  /// `threshold`, the next shows the gap), and with it.
  std::vector<double> smallest_relative_eigenvalues, smallest_relative_eigenvalues_with_gauge;
  double threshold = kSubimageGaugeThreshold;
  bool ok = false;      // the null space was computed and the reference's entries span it
  std::string message;  // why not, when !ok
};

/// One sub-image's estimated mapping.
struct SubimageDirectionMapping {
  std::string id;
  int observations = 0;
  calib::SubimageMapping mapping;            // estimated (plain parameters)
  std::vector<std::optional<double>> sigma;  // plain, a-posteriori; none: held or no covariance
  std::vector<bool> held;                    // per plain entry: held by the gauge
};

struct SubimageDirectionsCalibration {
  /// The virtual camera: interior (camera.interior with the estimated mappings in
  /// camera.subimages), its sigmas and covariance, R, residuals per observation (sub-image px),
  /// the estimated targets, the method, the solve report.
  DirectionCalibration frame;
  std::vector<SubimageDirectionMapping> subimages;  // observed sub-images, the reference first
  SubimageDirectionGauge gauge;
};

/// Adjusts the `observations` (pixel = (u, v) in the raw sub-image named by
/// `subimage_of_observation`) of `targets` with the multi-CCD camera `start` (its interior and
/// mappings the start values), R starting at `start_opk_rad`. `reference` names the sub-image that
/// carries the gauge ("" : the first of the camera file's sub-images that has observations).
/// Sub-images without observations keep their mappings. Throws InputError naming the observation
/// (unknown target or sub-image, sigma out of range), for a sub-image with fewer scalar
/// observations than its mapping's parameters (at its first observation), for a reference that
/// is not an observed sub-image, and for a name of `options.free_interior` not in the model.
SubimageDirectionsCalibration CalibrateSubimagesFromDirections(
    const calib::Camera& start,
    const Eigen::Vector3d& start_opk_rad,
    const std::vector<DirectionTarget>& targets,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of_observation,
    const std::string& reference = "",
    const DirectionCalibrationOptions& options = {});

/// The observations taken to the virtual image through the start camera's mappings (pixel =
/// VirtualFromSub(u, v)): for start values (StartRotationFromDirections, StartUnknownTargets) and
/// the check that every direction is in front of the camera.
std::vector<DirectionObservation> VirtualObservations(
    const calib::Camera& start,
    const std::vector<DirectionObservation>& observations,
    const std::vector<std::string>& subimage_of_observation);

}  // namespace aerocal::triangulation
