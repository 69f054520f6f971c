// Self-calibrating bundle block adjustment (aerial triangulation) with control and check points.
//
// Observations (all whitened, CONVENTIONS.md "Statistics"):
// - image: collinearity of every virtual-image measurement with the 10-parameter camera
//   (calib/residuals/collinearity.h), group kGroupImage;
// - control: the surveyed coordinates of control points as weighted observations of their ground
//   point block (sigma from points.csv), group kGroupControl: two residuals per point, its plan
//   (X, Y; label "control <id> plan") and its height (Z; "control <id> height"), which data
//   snooping tests and leaves out each on its own (a wrong height keeps a good plan survey);
// - eo_prior: GNSS centres / IMU angles from the sigma columns of exposures.csv, kGroupEoPrior;
// - interior_prior: the camera file's `interior_sigma` of free interior parameters.
// Check points enter only through their image rays (as tie points); their adjusted coordinates are
// compared with the survey afterwards. Interior parameters are one block per camera; which entries
// are free is AdjustOptions::free_interior (a SubsetManifold in the builder).
//
// Starting values: exposures.csv; control points from their survey; other points from points.csv
// when given, else by forward intersection (forward_intersection.h). A self-calibrating run first
// adjusts with the interior fixed, then frees the listed parameters (robust start from exterior
// orientations off by tens of metres and degrees).
//
// Sensor kinds (triangulation/sensor/imaging_model.h): the platform (triangulation/block/
// platform.h, built once from the project) says which sensor took each observation; the
// observation goes to the model of that sensor's kind: the frame camera for virtual-image pixels,
// a model the caller hands to the constructor (the sub-image camera of the joint adjustment, the
// rig heads of the rig bundle), else the kind's default from MakeImagingModel (raw sub-image
// pixels at the camera file's mappings). Each model registers its own blocks, gives the rays of
// its observations for the point starting values, builds their residuals, describes them and
// annotates their result entries; the adjustment keeps the points, the platform poses, the
// priors, the datum, statistics and data snooping (of every group the kinds' terms came in) and
// never tests a kind.
//
// Identities: exposures (ExposureIndex, Project::exposures order) and ground points (PointIndex,
// the observed point ids sorted) are dense indices assigned once when the block is built; every
// loop, the snooping bookkeeping and the datum guard work on them. Ids are strings only when read
// (the public *Block(id) lookups) and in labels and results; loops that decide an order (priors,
// notes, covariance blocks, results) go by sorted id, so results do not depend on the indices.
#pragma once

#include "calib/core/progress.h"
#include "calib/problem/data_snooping.h"
#include "calib/problem/problem_builder.h"
#include "triangulation/adjustment/adjust_options.h"
#include "triangulation/adjustment/adjustment_result.h"
#include "triangulation/block/block.h"
#include "triangulation/sensor/imaging_model.h"

#include <Eigen/Core>

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

struct KeptAdjustment;

class BlockAdjustment {
 public:
  /// Validates the options, computes starting values and builds every residual.
  /// Throws InputError when the block cannot be started (an exposure without observations is
  /// only reported; an observation whose ray misses every start is an input error).
  /// `sensors`: models of sensor kinds besides the frame camera, at most one per kind; they take
  /// every observation of their kind (kinds not given get MakeImagingModel's default). `image_loss`
  /// is applied to the image observations (robust start); none by default.
  BlockAdjustment(const Project& project,
                  const AdjustOptions& options,
                  std::vector<std::unique_ptr<ImagingModel>> sensors = {},
                  const calib::LossOptions& image_loss = {});
  ~BlockAdjustment();
  BlockAdjustment(const BlockAdjustment&) = delete;
  BlockAdjustment& operator=(const BlockAdjustment&) = delete;

  calib::ProblemBuilder& builder() { return builder_; }
  /// What the sensor kinds see (builder, dense indices, poses, the frame camera's interiors).
  const SensorContext& context() const;
  /// Block ids (-1 when absent).
  calib::BlockId InteriorBlock(const std::string& camera) const;
  calib::BlockId RotationBlock(const std::string& image) const;
  calib::BlockId CenterBlock(const std::string& image) const;
  calib::BlockId PointBlock(const std::string& point) const;

  /// Solves (two stages when self-calibrating), snoops for gross errors, estimates the covariance
  /// and compares control and check points. Never throws on non-convergence. `progress` (may be
  /// null) advances by kRunStages: the fixed-interior solve, the solve with snooping, the
  /// covariance.
  AdjustmentResult Run(Progress* progress = nullptr);
  static constexpr int kRunStages = 3;
  /// After a robust Run(): the virtual-image observations whose standardized residual
  /// w = |v| / (s sqrt(r)) (redundancy numbers r of the geometry, s the robust scale 1.4826
  /// median of |v| / sqrt(r) over the testable components) exceeds `reject`, with that w.
  struct Screened {
    ImageObservation observation;
    int source = -1;  // its index in the project's observations (the dense id, no matching)
    Eigen::Vector2d residual_px = Eigen::Vector2d::Zero();  // photo x, y
    double w = 0.0;
  };
  std::vector<Screened> ScreenRobustly(double reject);
  /// The whitened residual (photo x, y) of `observation`, which need not be one of the
  /// adjustment's, at the blocks' current values (after Run(): the solution): its term built by
  /// the sensor kind that measures it, exactly as the solve builds the terms it adds (the camera's
  /// own model through the registry). nullopt when its exposure or point has no block here, or
  /// the ray misses (behind the camera, the model's inversion fails).
  std::optional<Eigen::Vector2d> ResidualAtCurrentValues(const ImageObservation& observation);
  /// After Run(): every active control observation's weight times `weight` (> 0; its sigmas over
  /// sqrt(weight), from the survey's, so 1 restores them) at the current values, nothing solved:
  /// the covariance then taken is Q(t) = (N_image + t N_control)^-1 at the same linearisation
  /// (the control part of the budget, triangulation/calibration/uncertainty_budget.h).
  void ScaleControlWeights(double weight);
  /// With options.auto_robust_start: Run() returns right after the first solve, with
  /// robust_start_needed set, when its residuals call for a robust start (Adjust() uses it).
  void StopWhenRobustStartNeeded(bool stop) { stop_for_robust_start_ = stop; }

 private:
  struct Storage;
  /// The model of each sensor kind: the frame camera, the given ones (one per kind), and for
  /// every other kind the platform observes its default (MakeImagingModel), when it has one.
  void ChooseModels(std::vector<std::unique_ptr<ImagingModel>> given);
  /// The model of the kind of project observation `source` (its platform sensor). InputError
  /// "observations_file:LINE" naming the command that adjusts a kind without a model here.
  ImagingModel* ModelOf(size_t source) const;
  void BuildExposures();
  /// The observations, the points and their starting values, in these steps:
  void BuildPoints();
  /// Each observation with the model of its sensor's kind, as that model keeps it (AsAdjusted).
  void CollectObservations();
  /// A dense index per observed point id (sorted ids) with its ground point, if any.
  void IndexPoints();
  /// Notes each exposure no observation names (issue 28).
  void NoteUnobservedExposures();
  /// One pass leaving out the exposures that see fewer than three points (unless GNSS and IMU
  /// priors hold them) and then the points left with one ray; true when it left anything out.
  bool DropUndeterminedExposures();
  /// The points' starting values (survey, intersection of the rays, a fallback height) and
  /// blocks; notes the points left out.
  void StartPoints();
  /// Adds the ground point block of `point` (a dense index of the observed points), starting at
  /// `start_m`; its block when it has one already.
  calib::BlockId AddPoint(PointIndex point, const Eigen::Vector3d& start_m);
  void AddImageResiduals(const calib::LossOptions& loss);
  void AddPriors();
  /// The platform blocks (lever arm and GNSS time offset with GNSS priors, boresight with IMU
  /// priors), fixed, free or weighted as Project::platform says.
  void AddPlatformBlocks();
  PlatformEstimate PlatformResult(const calib::CovarianceReport& cov) const;
  void DefineDatum();
  /// Data snooping with the datum guard; fills result->rejected and result->snooping.
  calib::SnoopingOutcome Snoop(AdjustmentResult* result);
  // Snoop's steps (block_adjustment_snooping.cc).
  calib::SnoopingOptions SnoopingSettings(const std::vector<int>& image_rays) const;
  /// The datum guard: refuses a removal that leaves a control point below two rays, an exposure
  /// below three points (unless GNSS and IMU priors hold it) or, without GNSS centres, fewer than
  /// three plan or height surveys; keeps the active ray counts up to date on every approval.
  std::function<std::string(const std::vector<calib::ResidualId>&)> DatumVeto(
      std::vector<int>* point_rays, std::vector<int>* image_rays) const;
  void SummariseSnooping(const calib::SnoopingOutcome& out, SnoopingSummary* summary);
  /// What to do about a suspected model error, by what the block can determine.
  std::string SelfCalibrationSuggestion() const;
  void RecordTested(const calib::SnoopingOutcome& out, SnoopingSummary* summary);
  void RecordRejected(const calib::SnoopingOutcome& out, AdjustmentResult* result);
  /// ScreenRobustly's verdict on the rays of one point (block_adjustment_screening.cc): `judged`
  /// gets each ray's |v| / s at the point's own fit, or 0 where the final snooping decides.
  void JudgeRaysOfPoint(PointIndex point,
                        const std::vector<calib::ResidualId>& rays,
                        const std::map<calib::ResidualId, double>& w_of,
                        double scale,
                        double reject,
                        std::map<calib::ResidualId, double>* judged);
  /// Human name of a residual: "image 0012 point T442" or the builder's label.
  std::string Describe(calib::ResidualId id) const;

  // Run's steps (block_adjustment_run.cc), in their order there.
  /// The share of the active image residuals' components above robust_trigger_w.
  double GrossShare() const;
  void DropSingleRayPoints(AdjustmentResult* result);
  void CollectResiduals(AdjustmentResult* result) const;
  /// sigma0, and in px and um through the median a-priori image sigma.
  void SetSigma0Units(AdjustmentResult* result) const;
  struct CovarianceBlocks {
    std::vector<calib::BlockId> all;    // whose covariance is estimated
    std::vector<calib::BlockId> cross;  // with everything (interior, free platform parameters)
  };
  CovarianceBlocks CovarianceBlocksOf(bool with_exterior) const;
  calib::CovarianceReport EstimateCovariance(const CovarianceBlocks& blocks,
                                             const AdjustmentResult& result);
  void CollectCameras(const calib::CovarianceReport& cov, AdjustmentResult* result) const;
  void CollectExposures(const calib::CovarianceReport& cov, AdjustmentResult* result) const;
  void CollectPoints(AdjustmentResult* result) const;
  void JudgeUnresolvedSurveys(const calib::CovarianceReport& cov,
                              const CovarianceBlocks& blocks,
                              AdjustmentResult* result);

  const Project& project_;
  AdjustOptions options_;
  calib::ProblemBuilder builder_;
  std::unique_ptr<Storage> storage_;
  bool stop_for_robust_start_ = false;
};

/// Builds and runs; with options.robust_start, first a robust adjustment whose solution starts
/// the final one (the reported initial interior stays the camera file's). `progress` (may be null)
/// advances by AdjustStages(options) units of work. With `keep`, the final adjustment (solved,
/// at its solution) and a copy of the project it was built from are left there
/// (kept_adjustment.h: the covariance of entries named after the run).
AdjustmentResult Adjust(const Project& project,
                        const AdjustOptions& options,
                        Progress* progress = nullptr,
                        KeptAdjustment* keep = nullptr);
/// Units of work of Adjust() with these options, for a Progress bar.
int AdjustStages(const AdjustOptions& options);

}  // namespace aerocal::triangulation
