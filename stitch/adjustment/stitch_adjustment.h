// Least-squares adjustment of the sub-image mappings of one frame (CONVENTIONS.md "Sub-image to
// virtual image"), through the shared ProblemBuilder.
//
// Observation equations (whitened by each measurement's sigma_px):
//   reference point:  Map_k(u, v) - (U, V)_surveyed          = v      (group stitch_reference)
//   tie point ray:    Map_k(u, v) - P                        = v      (group stitch_tie)
// with P the unknown virtual position of the tie point (2 unknowns per point). Unknowns are the
// mapping parameters of every non-base sub-image, in the CONDITIONED form (subimage_mapping.h);
// sub-images listed as base keep their camera-file mapping (the datum). Without base sub-images the
// reference points carry the datum.
//
// Results are reported in the plain parameter form with sigmas propagated through
// d(plain)/d(conditioned); the predicted precision of every sub-image corner is the mapping
// covariance propagated to the corner's virtual position: Cov(U, V) = G C G^T with
// G = d(U, V)/d(params). Gross errors: Baarda data snooping over both groups (every rejected
// observation listed with its standardized residual w).
#pragma once

#include "calib/camera/camera.h"
#include "calib/problem/problem_builder.h"
#include "stitch/adjustment/frame_measurements.h"

#include <Eigen/Core>

#include <array>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::stitch {

struct StitchOptions {
  std::vector<std::string> base_ids;  // sub-images whose mapping is held at the camera file's
  bool data_snooping = true;          // Baarda data snooping (else no observation is removed)
  double snooping_alpha = 0.05;       // family-wise level of the snooping test, (0, 1)
  /// Robust start (with data snooping, as `adjust --robust-start`): first an adjustment with a
  /// Cauchy loss (scale `robust_scale_sigma` sigmas); observations whose residual exceeds
  /// `robust_reject_sigma` robust scales (1.4826 median |v / sigma|, at least 1) are gross errors
  /// and left out before the clean adjustment and its snooping, so a decimal slip of 1e4..1e6 px
  /// can neither mask other errors nor pull the model choice (the F test sees clean adjustments).
  bool robust_start = true;
  double robust_scale_sigma = 3.0;
  double robust_reject_sigma = 20.0;  // only the obvious: snooping decides the rest
  calib::LossOptions loss;            // loss on every residual (the robust pass sets Cauchy)
  calib::SolverOptions solver;
  void Validate(const calib::Camera& camera) const;  // ConfigError for unknown base ids
};

/// Observation key: (point id, sub-image id).
using ObservationKey = std::pair<std::string, std::string>;

struct CornerPrecision {
  Eigen::Vector2d uv{0, 0};          // sub-image corner pixel
  Eigen::Vector2d virtual_px{0, 0};  // its estimated virtual position
  double sigma_U_px = 0, sigma_V_px = 0;
  double sigma_px() const;  // sqrt(sigma_U^2 + sigma_V^2)
};

struct SubimageEstimate {
  std::string id;
  calib::MappingModel model = calib::MappingModel::kAffine;
  bool base = false;                       // held fixed (datum): sigmas 0
  std::vector<double> params;              // plain form (FORMATS.md order)
  std::vector<double> sigma;               // plain form, same order
  Eigen::MatrixXd covariance;              // plain form
  std::array<CornerPrecision, 4> corners;  // (0,0), (W-1,0), (0,H-1), (W-1,H-1)
  double max_corner_sigma_px = 0;
};

struct PointResidual {
  std::string point, subimage;
  bool reference = false;      // reference point (else tie ray)
  Eigen::Vector2d v_px{0, 0};  // estimated minus observed virtual position, px
  double sigma_px = 0;
};

struct RejectedObservation {
  std::string point, subimage;
  bool reference = false;
  double w = 0;                // standardized residual at rejection
  Eigen::Vector2d v_px{0, 0};  // residual at rejection, px
};

struct FrameAdjustment {
  std::string frame;
  calib::MappingModel model = calib::MappingModel::kAffine;
  bool converged = false;
  int iterations = 0;
  double sigma0 = 0, sigma0_px = 0, vtpv = 0;
  int redundancy = 0, n_observations = 0, n_unknowns = 0;
  int n_ties = 0, n_references = 0;
  int n_single_ray_points = 0;  // points measured in one sub-image only: no equation, not used
  bool covariance_ok = false;
  std::vector<SubimageEstimate> subimages;  // camera order
  std::vector<PointResidual> residuals;
  std::vector<RejectedObservation> rejected;
  std::vector<std::string> diagnostics;
  double max_corner_sigma_px = 0;  // over all sub-images
};

/// Empty when every free sub-image of `frame` has at least as many observation equations as its
/// mapping (under `model`) has parameters, counting the observations not in `excluded`;
/// otherwise a message naming the first sub-image that does not
/// ("frame 0001, sub-image V: 2 points give 4 equations for the 6 affine parameters").
std::string FindUnderdetermined(const calib::Camera& camera,
                                const FrameMeasurements& frame,
                                calib::MappingModel model,
                                const StitchOptions& options,
                                const std::set<ObservationKey>& excluded = {});

/// Adjusts one frame with `model` for every free sub-image (base sub-images keep their own).
/// Observations in `excluded` are left out (listed nowhere; the caller has listed them).
/// Throws InputError with FindUnderdetermined's message when the model is under-determined.
FrameAdjustment AdjustFrame(const calib::Camera& camera,
                            const FrameMeasurements& frame,
                            calib::MappingModel model,
                            const StitchOptions& options,
                            const std::set<ObservationKey>& excluded = {});

/// The camera with the frame's estimated mappings (for resampling and reports).
calib::Camera CameraWithEstimates(const calib::Camera& camera, const FrameAdjustment& adjustment);

}  // namespace aerocal::stitch
