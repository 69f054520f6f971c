// Joint adjustment of sub-image stitching and aerial triangulation: the sub-image mappings are
// refined inside the bundle, so the stitched geometry is checked, and corrected, by ground control.
//
// Observations, all in one ProblemBuilder problem (on top of BlockAdjustment's):
// - subimage_image: raw sub-image measurements (u, v) -> mapping of their sub-image -> virtual
//   pixel -> 10-parameter camera -> collinearity (calib::SubimageCollinearityResidual);
// - stitch_reference: maker reference points, Map_k(u, v) = (U, V)_surveyed, per exposure;
// - stitch_tie: stitching tie points of each exposure, Map_k(u, v) = P (unknown virtual P);
// - plus image / control / GNSS-IMU / interior priors exactly as in BlockAdjustment.
// Mappings are one block per (camera, sub-image) for the whole flight, or per exposure
// (MappingScope), in the conditioned parameterisation (calib/camera/subimage_mapping.h).
// Datum of the focal plane: the base sub-images keep their camera-file mapping; without base
// sub-images the reference points carry it. The result states which.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calib/camera/subimage_mapping.h"
#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"

namespace aerocal::triangulation {

enum class MappingScope { kPerFlight, kPerExposure };
std::string MappingScopeName(MappingScope scope);
/// "per-flight" | "per-exposure"; ConfigError otherwise.
MappingScope ParseMappingScope(const std::string& text);

struct JointOptions {
  AdjustOptions adjust;
  MappingScope scope = MappingScope::kPerFlight;
  std::vector<std::string> base_ids;  // sub-images held at the camera file's mapping (datum)
  bool use_stitching = true;          // the project's stitching file, when it names one
  double stitch_sigma_px = 0.1;       // where stitch_obs.csv has no sigma_px, > 0
  /// ConfigError for an unknown base sub-image or a project without sub-image observations,
  /// InputError when the focal plane has no datum (no base sub-image and no reference point).
  void Validate(const Project& project) const;
};

struct MappingEstimate {
  std::string camera, subimage;
  std::string exposure;  // empty: one mapping for the whole flight
  calib::MappingModel model = calib::MappingModel::kAffine;
  bool base = false;
  std::vector<double> initial, params, sigma;  // plain form (FORMATS.md order)
};

/// Stitching precision of one exposure, before (the exposure's own stitching adjustment) and after
/// (its stitching residuals in the joint solution): sqrt(v^T P v / r) times the median sigma, px.
struct ExposureStitching {
  std::string image;
  int n_observations = 0;
  double sigma0_before_px = std::numeric_limits<double>::quiet_NaN();
  double sigma0_after_px = std::numeric_limits<double>::quiet_NaN();
};

struct JointResult {
  AdjustmentResult adjustment;
  MappingScope scope = MappingScope::kPerFlight;
  std::string datum;  // how the focal plane is fixed, in words
  std::vector<MappingEstimate> mappings;
  std::vector<ExposureStitching> stitching;
  std::vector<calib::HighCorrelation> mapping_interior_correlations;  // |rho| above threshold
  bool mapping_covariance_ok = false;
};

JointResult AdjustJoint(const Project& project, const JointOptions& options);

/// AdjustmentToJson plus `subimages` (FORMATS.md: {id, model, params, sigma}, with `exposure` for
/// per-exposure mappings), `datum`, `mapping_scope`, `stitching_per_exposure` and
/// `mapping_interior_correlations`.
nlohmann::json JointResultToJson(const JointResult& result);

}  // namespace aerocal::triangulation
