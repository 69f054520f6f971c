// The sub-image camera: a multi-CCD camera whose observations are RAW sub-image pixels (u, v),
// taken to the virtual image by the mapping of their sub-image (CONVENTIONS.md "Sub-image to
// virtual image"), then through the frame camera's interior, in the camera's own registered model,
// and the exposure's pose (calib::MakeSubimageCollinearityResidual, group kGroupSubimage). The
// mappings are refined inside the bundle (the joint stitching + triangulation adjustment,
// triangulation/joint/): one block per (camera, sub-image) for the flight, or per exposure
// (MappingScope), in the conditioned parameterisation (calib/camera/subimage_mapping.h). Its own
// residuals: the stitching measurements of the block's exposures (maker reference points, group
// stitch_reference; stitching tie points with unknown virtual positions, group stitch_tie).
// Datum of the focal plane: the base sub-images keep their camera-file mapping; without base
// sub-images the reference points carry it.
#pragma once

#include "calib/camera/subimage_mapping.h"
#include "stitch/adjustment/frame_measurements.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/sensor/imaging_model.h"

#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

namespace aerocal::triangulation {

enum class MappingScope { kPerFlight, kPerExposure };
std::string MappingScopeName(MappingScope scope);
/// "per-flight" | "per-exposure"; ConfigError otherwise.
MappingScope ParseMappingScope(const std::string& text);

struct SubimageCameraOptions {
  MappingScope scope = MappingScope::kPerFlight;
  std::vector<std::string> base_ids;  // sub-images held at the camera file's mapping (datum)
  bool use_stitching = true;          // the project's stitching file, when it names one
  double stitch_sigma_px = 0.1;       // where stitch_obs.csv has no sigma_px, > 0
  /// Model of every free sub-image's mapping; nullopt: each its camera-file model. Starting values
  /// are the camera file's mappings converted (exact towards a richer model, about the sub-image
  /// centre towards a simpler one). Base sub-images keep their own.
  std::optional<calib::MappingModel> model;
  /// Stitching sigma0 (px) of each exposure's own stitching adjustment, by image: the "before"
  /// figures when the caller has them; other exposures are adjusted alone here.
  std::map<std::string, double> stitching_sigma0_before_px;
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

/// What the sub-image camera estimated, after the adjustment ran.
struct SubimageReport {
  std::vector<MappingEstimate> mappings;
  std::vector<ExposureStitching> stitching;
  std::vector<calib::HighCorrelation> mapping_interior_correlations;  // |rho| above threshold
  bool mapping_covariance_ok = false;
};

class SubimageCamera final : public ImagingModel {
 public:
  explicit SubimageCamera(SubimageCameraOptions options) : options_(std::move(options)) {}
  /// Raw sub-image pixels (u, v), mappings refined in the bundle.
  SensorKind Kind() const override { return SensorKind::kSubimage; }
  /// Reads the stitching measurements (options.use_stitching) and registers one mapping block
  /// per (camera, sub-image[, exposure]) that an observation or a stitching measurement uses,
  /// by dense index; base sub-images fixed.
  void RegisterBlocks(const SensorContext& context) override;
  /// Through the camera file's mapping.
  ImageRay StartingRay(const SensorContext& context,
                       const ImageObservation& observation) const override;
  /// Group kGroupSubimage; blocks mapping, interior, rotation, centre, point.
  ObservationTerm Observe(const SensorContext& context,
                          const ImageObservation& observation,
                          calib::BlockId point) override;
  /// The stitching measurements (reference and tie residuals) and their "before" figures.
  void AddOwnResiduals(const SensorContext& context) override;
  /// "image 0012 sub-image III point T442".
  std::string Describe(const ImageObservation& observation) const override;
  /// The sub-image and its raw pixel (u, v).
  void Annotate(const ImageObservation& observation, ObservationResidual* residual) const override;
  void Annotate(const ImageObservation& observation, RejectedObservation* rejected) const override;

  /// After the adjustment ran with `sigma0`: mappings with sigmas (plain form), their
  /// correlations with the interior, stitching precision after; and the virtual-image position
  /// (measured_px) of every raw sub-image residual of `adjustment`, by the refined mapping.
  SubimageReport Report(const SensorContext& context,
                        double sigma0,
                        AdjustmentResult* adjustment) const;

 private:
  struct Mapping {
    std::string camera, subimage, exposure;
    calib::MappingModel model = calib::MappingModel::kAffine;
    calib::MappingConditioning conditioning;
    std::vector<double> initial_plain;
    std::vector<double> values;  // conditioned, the block memory
    calib::BlockId block = -1;
    bool base = false;
    bool used = false;  // a residual sits on it
  };
  // Residuals of one exposure's stitching measurements, for its precision after the solution.
  struct FrameResiduals {
    std::vector<calib::ResidualId> residuals;
    int ties = 0;
    std::vector<double> sigmas_px;
  };
  /// (camera, sub-image, exposure or -1 per flight) -> index into mappings_.
  using Key = std::tuple<CameraIndex, int, ExposureIndex>;
  Key KeyOf(const SensorContext& context,
            const std::string& image,
            const std::string& subimage) const;
  Mapping& MappingOf(const SensorContext& context,
                     const std::string& image,
                     const std::string& subimage);

  SubimageCameraOptions options_;
  std::vector<Mapping> mappings_;  // sized once in RegisterBlocks: the builder holds addresses
  std::map<Key, int> mapping_index_;
  std::map<std::string, std::vector<stitch::FrameMeasurements>> frames_by_camera_;
  std::vector<ExposureStitching> stitching_;
  std::map<std::string, FrameResiduals> frame_residuals_;
  std::deque<Eigen::Vector2d> tie_points_;  // stable addresses: the builder holds them
};

}  // namespace aerocal::triangulation
