// Joint adjustment of sub-image stitching and aerial triangulation: the sub-image mappings are
// refined inside the bundle, so the stitched geometry is checked, and corrected, by ground control.
//
// Not a second adjustment: the block adjustment with the sub-image camera as a sensor kind
// (triangulation/sensor/subimage_camera.h), whose observations and own residuals are
// - subimage_image: raw sub-image measurements (u, v) -> mapping of their sub-image -> virtual
//   pixel -> the camera in its model -> collinearity (calib::MakeSubimageCollinearityResidual);
// - stitch_reference: maker reference points, Map_k(u, v) = (U, V)_surveyed, per exposure;
// - stitch_tie: stitching tie points of each exposure, Map_k(u, v) = P (unknown virtual P);
// - plus image / control / GNSS-IMU / interior priors of BlockAdjustment.
// Mappings are one block per (camera, sub-image) for the whole flight, or per exposure
// (MappingScope), in the conditioned parameterisation (calib/camera/subimage_mapping.h).
// Datum of the focal plane: the base sub-images keep their camera-file mapping; without base
// sub-images the reference points carry it. The result states which.
// Mapping model: each sub-image's camera-file model, or one model for every free sub-image
// (JointOptions::model), normally the one the flight's stitching chose by the F test
// (JointMappingsFromStitching), starting from the stitching's flight-mean mappings.
#pragma once

#include "calib/camera/subimage_mapping.h"
#include "calib/problem/problem_builder.h"
#include "stitch/adjustment/flight_stability.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"
#include "triangulation/sensor/subimage_camera.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace aerocal {
class Progress;
}

namespace aerocal::triangulation {

/// --joint-model: "translation" | "conformal" | "affine" | "projective", or "auto" (nullopt: the
/// model the flight's stitching chooses); ConfigError otherwise.
std::optional<calib::MappingModel> ParseJointModel(const std::string& text);

/// The sub-image camera's options (scope, base_ids, use_stitching, stitch_sigma_px, model,
/// stitching_sigma0_before_px: subimage_camera.h) and the adjustment's.
struct JointOptions : SubimageCameraOptions {
  AdjustOptions adjust;
  std::string model_reason;  // why that model, in words (written to the result)
  /// Also the part of the interior's cofactor matrix that the control survey sigmas give
  /// (JointResult::interior_control_cofactor; two more covariance evaluations, no solve).
  bool control_cofactor = false;
  /// ConfigError for an unknown base sub-image or a project without sub-image observations,
  /// InputError when the focal plane has no datum (no base sub-image and no reference point).
  void Validate(const Project& project) const;
};

struct JointResult {
  AdjustmentResult adjustment;
  MappingScope scope = MappingScope::kPerFlight;
  std::string datum;  // how the focal plane is fixed, in words
  std::vector<MappingEstimate> mappings;
  std::vector<ExposureStitching> stitching;
  std::vector<calib::HighCorrelation> mapping_interior_correlations;  // |rho| above threshold
  bool mapping_covariance_ok = false;
  std::string mapping_model;         // of the free mappings ("affine"), or "camera file"
  std::string mapping_model_reason;  // JointOptions::model_reason
  /// With JointOptions::control_cofactor: Q N_control Q of the sub-image camera's interior
  /// (calibration/control_cofactor.h; parameter table order and units, not scaled by sigma0),
  /// the control coordinates' type-B part of its covariance; empty without a covariance.
  std::string interior_camera;
  Eigen::MatrixXd interior_control_cofactor;
};

JointResult AdjustJoint(const Project& project, const JointOptions& options);

/// The stitching measurements of `project`'s exposures of its one camera with sub-images, as
/// StitchExposures adjusts them: the rows (sigma_px filled with `default_sigma_px` where the file
/// has none) and the frames they make (stitch::GroupByFrame, in order of first appearance).
/// Errors as StitchExposures.
struct ExposureMeasurements {
  calib::Camera camera;
  std::vector<stitch::StitchObservation> rows;
  std::vector<stitch::FrameMeasurements> frames;
};
ExposureMeasurements ReadExposureMeasurements(const Project& project, double default_sigma_px);

/// Every exposure of `project`'s stitching measurements (`stitching:`) adjusted as
/// `aerocal stitch` does (`options.model` nullopt: per exposure the model the F test chooses),
/// for the project's one camera with sub-images. InputError when the project names no stitching
/// measurements or has no camera with sub-images, ConfigError when it has several.
stitch::BatchResult StitchExposures(const Project& project,
                                    const stitch::BatchOptions& options,
                                    double default_sigma_px,
                                    Progress* progress);

/// Mapping model and starting mappings of the joint adjustment from the flight's stitching
/// (`batch`, run with `batch_options`; null: no stitching measurements): `forced` when given, else
/// the flight's model (stitch::FlightModel: with --model auto the one the F test chose in most
/// exposures), or without stitching the camera file's models. Sets options->model,
/// options->model_reason and options->stitching_sigma0_before_px (each exposure's stitching with
/// that model); returns `camera` carrying the starting mappings (the stitching's flight means of
/// that model, stitch::FlightMeanCamera, when it was adjusted in every exposure).
calib::Camera JointMappingsFromStitching(const calib::Camera& camera,
                                         const stitch::BatchResult* batch,
                                         const stitch::BatchOptions& batch_options,
                                         std::optional<calib::MappingModel> forced,
                                         JointOptions* options);

/// `camera` with the joint estimate: interior of camera `camera_id` and the flight's mappings
/// (per-exposure mappings are not carried: the camera keeps its own).
calib::Camera JointUpdatedCamera(const calib::Camera& camera,
                                 const std::string& camera_id,
                                 const JointResult& result);

/// Terminal lines of the joint part: mapping model and why, every free mapping's largest
/// |estimate - start| / sigma, stitching sigma0 before/after (median over exposures), the
/// mapping/interior correlations above the threshold.
std::string FormatJointSummary(const JointResult& result);

/// AdjustmentToJson plus `subimages` (FORMATS.md: {id, model, params, sigma}, with `exposure` for
/// per-exposure mappings), `datum`, `mapping_scope`, `mapping_model`, `mapping_model_reason`,
/// `stitching_per_exposure` and `mapping_interior_correlations`.
nlohmann::json JointResultToJson(const JointResult& result);

}  // namespace aerocal::triangulation
