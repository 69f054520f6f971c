#include "triangulation/adjustment/block_adjustment.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"
#include "calib/core/log.h"
#include "calib/core/median.h"
#include "calib/core/string_printf.h"
#include "calib/problem/mounted_block.h"
#include "calib/problem/suspect_effect.h"
#include "calib/residuals/gnss_prior.h"
#include "calib/residuals/prior.h"
#include "calib/residuals/rotation_prior.h"
#include "triangulation/adjustment/block_adjustment_storage.h"
#include "triangulation/adjustment/determinability.h"
#include "triangulation/adjustment/forward_intersection.h"
#include "triangulation/adjustment/plausibility.h"
#include "triangulation/sensor/frame_camera.h"
#include "triangulation/sensor/make_imaging_model.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_map>

namespace aerocal::triangulation {
namespace {

using calib::BlockId;
using calib::BlockKind;

const std::vector<std::string> kCenterNames = {"X", "Y", "Z"};
const std::vector<std::string> kAngleNames = {"omega", "phi", "kappa"};
// Owner of the weighted platform parameters (lever arm, boresight, GNSS time offset): their priors
// are in group calib::PriorGroup(kPlatformOwner), "platform_prior".
constexpr const char* kPlatformOwner = "platform";
// The two survey observations of a control point (labels "control <id> plan" / "... height").
constexpr const char* kSurveyPlan = "plan";
constexpr const char* kSurveyHeight = "height";

bool PlatformEstimated(const PlatformSpec& p) {
  return p.lever_arm != PlatformParamMode::kFixed || p.boresight != PlatformParamMode::kFixed ||
         p.time_offset != PlatformParamMode::kFixed;
}

}  // namespace

BlockAdjustment::BlockAdjustment(const Project& project,
                                 const AdjustOptions& options,
                                 std::vector<std::unique_ptr<ImagingModel>> sensors,
                                 const calib::LossOptions& image_loss)
    : project_(project),
      options_(options),
      storage_(std::make_unique<Storage>(project, options_, builder_)) {
  options_.Validate();
  ChooseModels(std::move(sensors));
  BuildExposures();
  BuildPoints();
  AddImageResiduals(image_loss);
  AddPriors();
  for (auto& sensor : storage_->sensors) sensor->AddOwnResiduals(storage_->context);
  DefineDatum();
}

const SensorContext& BlockAdjustment::context() const { return storage_->context; }

BlockAdjustment::~BlockAdjustment() = default;

BlockId BlockAdjustment::InteriorBlock(const std::string& camera) const {
  return project_.cameras.count(camera)
             ? storage_->frame.InteriorBlock(storage_->index.Camera(camera))
             : -1;
}
BlockId BlockAdjustment::RotationBlock(const std::string& image) const {
  const ExposureIndex e = storage_->index.FindExposure(image);
  return e < 0 ? -1 : storage_->exposures[e].opk_block;
}
BlockId BlockAdjustment::CenterBlock(const std::string& image) const {
  const ExposureIndex e = storage_->index.FindExposure(image);
  return e < 0 ? -1 : storage_->exposures[e].center_block;
}
PlatformEstimate BlockAdjustment::PlatformResult(const calib::CovarianceReport& cov) const {
  const Storage& s = *storage_;
  PlatformEstimate out;
  out.spec = project_.platform;
  out.gnss = s.lever_block >= 0;
  out.imu = s.boresight_block >= 0;
  out.lever_arm_m = s.lever_arm;
  out.boresight_rad = s.boresight;
  out.time_offset_s = s.time_offset;
  if (!cov.ok) return out;
  if (out.gnss && !builder_.IsBlockFixed(s.lever_block))
    out.lever_arm_sigma_m = cov.BlockSigma(s.lever_block, 3);
  if (out.gnss && !builder_.IsBlockFixed(s.time_block))
    out.time_offset_sigma_s = cov.BlockSigma(s.time_block, 1)(0);
  if (out.imu && !builder_.IsBlockFixed(s.boresight_block))
    out.boresight_sigma_rad = cov.BlockSigma(s.boresight_block, 3);
  return out;
}

BlockId BlockAdjustment::PointBlock(const std::string& point) const {
  const PointIndex p = storage_->FindPoint(point);
  return p < 0 ? -1 : storage_->points[p].block;
}

BlockId BlockAdjustment::AddPoint(PointIndex point, const Eigen::Vector3d& start_m) {
  auto& state = storage_->points[point];
  if (state.block >= 0) return state.block;
  state.xyz = start_m;
  state.block = builder_.AddBlock("point " + storage_->point_ids[point],
                                  state.xyz.data(),
                                  3,
                                  BlockKind::kGroundPoint,
                                  kCenterNames);
  return state.block;
}

void BlockAdjustment::BuildExposures() {
  // The sensor kinds' own blocks first (the frame camera's interiors), then the platform poses.
  storage_->frame.RegisterBlocks(storage_->context);
  for (auto& sensor : storage_->sensors) sensor->RegisterBlocks(storage_->context);
  Storage& s = *storage_;
  const int n = s.index.NumExposures();
  s.poses.resize(n);
  s.exposures.resize(n);  // once: the builder keeps pointers into the states
  s.exposure_order.resize(n);
  for (ExposureIndex k = 0; k < n; ++k) s.exposure_order[k] = k;
  std::sort(
      s.exposure_order.begin(), s.exposure_order.end(), [&](ExposureIndex a, ExposureIndex b) {
        return project_.exposures[a].image < project_.exposures[b].image;
      });
  s.exposure_rank.resize(n);
  for (int rank = 0; rank < n; ++rank) s.exposure_rank[s.exposure_order[rank]] = rank;
  for (const auto& e : project_.exposures) {
    const ExposureIndex index = s.index.Exposure(e.image);
    auto& state = s.exposures[index];
    state.exposure = &e;
    state.index = index;
    state.camera = &project_.cameras.at(e.camera);
    state.rotation = calib::QuaternionFromOpk(e.opk_rad);
    state.center = e.center_m;
    state.opk_block = builder_.AddRotationBlock(
        "image " + e.image + " angles", state.rotation.data(), kAngleNames);
    state.center_block = builder_.AddBlock(
        "image " + e.image + " centre", state.center.data(), 3, BlockKind::kCenter, kCenterNames);
    storage_->poses[state.index] = {state.opk_block, state.center_block};
  }
}

void BlockAdjustment::ChooseModels(std::vector<std::unique_ptr<ImagingModel>> given) {
  Storage& s = *storage_;
  s.model_of_kind[static_cast<int>(SensorKind::kFrame)] = &s.frame;
  s.sensors = std::move(given);
  for (const auto& model : s.sensors) {
    ImagingModel*& slot = s.model_of_kind[static_cast<int>(model->Kind())];
    AEROCAL_CHECK(slot == nullptr)
        << "two models of the " << SensorKindName(model->Kind()) << " kind";
    slot = model.get();
  }
  // The kinds the block observes and no caller configured: their default (MakeImagingModel);
  // a kind without one is named at its first observation (BuildPoints).
  for (SensorKind kind : kSensorKinds) {
    ImagingModel*& slot = s.model_of_kind[static_cast<int>(kind)];
    if (slot || !s.platform.Observes(kind)) continue;
    if (auto made = MakeImagingModel(kind)) {
      slot = made.get();
      s.sensors.push_back(std::move(made));
    }
  }
}

ImagingModel* BlockAdjustment::ModelOf(size_t source) const {
  const Sensor& sensor = storage_->platform.sensors[storage_->platform.observations[source].sensor];
  ImagingModel* model = storage_->model_of_kind[static_cast<int>(sensor.kind)];
  if (!model) {
    const ImageObservation& o = project_.observations[source];
    ThrowInputError({project_.observations_file, o.line},
                    "image " + o.image + " " + sensor.name + ": " +
                        std::string(UnconfiguredReason(sensor.kind)));
  }
  return model;
}

std::optional<Eigen::Vector2d> BlockAdjustment::ResidualAtCurrentValues(
    const ImageObservation& observation) {
  const ExposureIndex exposure = storage_->index.FindExposure(observation.image);
  const BlockId point = PointBlock(observation.point);
  if (exposure < 0 || point < 0 || storage_->exposures[exposure].opk_block < 0) return std::nullopt;
  ImagingModel* model = storage_->model_of_kind[static_cast<int>(ObservationKind(observation))];
  if (!model) return std::nullopt;
  const ObservationTerm term =
      model->Observe(storage_->context, model->AsAdjusted(storage_->context, observation), point);
  std::vector<const double*> values;
  for (BlockId b : term.blocks) values.push_back(builder_.BlockValues(b));
  if (term.cost->num_residuals() != 2) return std::nullopt;
  Eigen::Vector2d v;
  if (!term.cost->Evaluate(values.data(), v.data(), nullptr) || !v.allFinite()) return std::nullopt;
  return v;
}

void BlockAdjustment::BuildPoints() {
  CollectObservations();
  IndexPoints();
  NoteUnobservedExposures();
  // Leaving out an exposure can leave a point with one ray, so repeat until nothing changes.
  while (DropUndeterminedExposures()) {
  }
  StartPoints();
}

void BlockAdjustment::CollectObservations() {
  // Each observation with the model of its sensor's kind (the platform's word), as that model
  // keeps it (AsAdjusted).
  Storage& s = *storage_;
  for (size_t source = 0; source < project_.observations.size(); ++source) {
    const PlatformObservation& x = s.platform.observations[source];
    ImagingModel* model = ModelOf(source);
    s.source_of_observation.push_back(static_cast<int>(source));
    s.exposure_of_observation.push_back(x.exposure);
    s.point_of_observation.push_back(x.point);
    s.observations.push_back(model->AsAdjusted(s.context, project_.observations[source]));
    s.sensor_of_observation.push_back(model);
  }
}

void BlockAdjustment::IndexPoints() {
  // The points: a dense index per observed point id (sorted ids), assigned once.
  Storage& s = *storage_;
  s.point_ids = s.platform.point_ids;
  s.points.resize(s.point_ids.size());  // once: the builder keeps pointers into the states
  // Project::FindPoint's first match, without its linear search (quadratic at 180,000 points).
  std::unordered_map<std::string_view, const GroundPoint*> ground_of_id;
  for (const auto& g : project_.points) ground_of_id.emplace(g.id, &g);
  for (PointIndex p = 0; p < static_cast<PointIndex>(s.points.size()); ++p) {
    const auto ground = ground_of_id.find(s.point_ids[p]);
    s.points[p].ground = ground == ground_of_id.end() ? nullptr : ground->second;
  }
}

void BlockAdjustment::NoteUnobservedExposures() {
  // An exposure that no observation names is named, never silently unused (issue 28).
  Storage& s = *storage_;
  std::vector<bool> observed(s.index.NumExposures(), false);
  for (ExposureIndex e : s.exposure_of_observation) observed[e] = true;
  for (ExposureIndex k : s.exposure_order) {
    if (observed[k]) continue;
    const Exposure& e = *s.exposures[k].exposure;
    const bool held = options_.use_eo_priors && e.center_sigma_m && e.opk_sigma_rad;
    const std::string where =
        project_.exposures_file.empty()
            ? ""
            : " (" + SourceRef{project_.exposures_file, e.line}.ToString() + ")";
    s.notes.push_back("image " + e.image + where + " has no image observation: " +
                      (held ? "its orientation is its GNSS/IMU priors only"
                            : "not adjusted, no orientation written"));
  }
}

bool BlockAdjustment::DropUndeterminedExposures() {
  // An exposure seeing fewer than three points (and not held by GNSS and IMU priors) cannot be
  // oriented; with it go the points it leaves with one ray (not control points).
  Storage& s = *storage_;
  const int n_exposures = s.index.NumExposures();
  const int n_points = static_cast<int>(s.points.size());
  std::vector<std::set<PointIndex>> points_of_image(n_exposures);
  std::vector<std::set<ExposureIndex>> images_of_point(n_points);
  for (size_t i = 0; i < s.observations.size(); ++i) {
    points_of_image[s.exposure_of_observation[i]].insert(s.point_of_observation[i]);
    images_of_point[s.point_of_observation[i]].insert(s.exposure_of_observation[i]);
  }
  std::vector<bool> dropped(n_exposures, false);
  bool any_dropped = false;
  for (ExposureIndex k : s.exposure_order) {
    const std::set<PointIndex>& points = points_of_image[k];
    if (points.empty()) continue;  // not observed
    const Exposure& e = *s.exposures[k].exposure;
    const bool held = options_.use_eo_priors && e.center_sigma_m && e.opk_sigma_rad;
    if (points.size() >= 3 || held) continue;
    dropped[k] = any_dropped = true;
    s.notes.push_back("image " + e.image + " sees " + std::to_string(points.size()) +
                      " point(s) only: its orientation cannot be determined; left out");
  }
  std::vector<bool> single(n_points, false);
  for (PointIndex p = 0; p < n_points; ++p)
    single[p] = images_of_point[p].size() == 1 && !s.points[p].Control();
  const size_t before = s.observations.size();
  std::vector<ImageObservation> kept;
  std::vector<ImagingModel*> kept_sensors;
  std::vector<int> kept_sources;
  std::vector<ExposureIndex> kept_exposures;
  std::vector<PointIndex> kept_points;
  for (size_t i = 0; i < before; ++i) {
    const ExposureIndex e = s.exposure_of_observation[i];
    const PointIndex p = s.point_of_observation[i];
    if (dropped[e] || (any_dropped && single[p])) continue;
    kept.push_back(s.observations[i]);
    kept_sensors.push_back(s.sensor_of_observation[i]);
    kept_sources.push_back(s.source_of_observation[i]);
    kept_exposures.push_back(e);
    kept_points.push_back(p);
  }
  s.observations = std::move(kept);
  s.sensor_of_observation = std::move(kept_sensors);
  s.source_of_observation = std::move(kept_sources);
  s.exposure_of_observation = std::move(kept_exposures);
  s.point_of_observation = std::move(kept_points);
  return s.observations.size() != before;
}

void BlockAdjustment::StartPoints() {
  Storage& s = *storage_;
  const int n_points = static_cast<int>(s.points.size());
  std::vector<std::vector<ImageRay>> rays(n_points);
  for (size_t i = 0; i < s.observations.size(); ++i)
    rays[s.point_of_observation[i]].push_back(
        s.sensor_of_observation[i]->StartingRay(s.context, s.observations[i]));
  // Fallback height for points whose rays do not intersect: mean height of the control (and of
  // approximate tie) points, else 0. Check surveys never enter the adjustment, not even here.
  double height_sum = 0.0;
  int height_n = 0;
  for (const auto& p : project_.points)
    if (p.xyz_m && p.role != PointRole::kCheck) {  // never the check survey
      height_sum += p.xyz_m->z();
      ++height_n;
    }
  const double fallback_height = height_n > 0 ? height_sum / height_n : 0.0;
  for (PointIndex p = 0; p < n_points; ++p) {
    const std::vector<ImageRay>& point_rays = rays[p];
    if (point_rays.empty()) continue;  // its observations were left out
    const std::string& id = s.point_ids[p];
    const GroundPoint* ground = s.points[p].ground;
    const bool control = s.points[p].Control();
    if (point_rays.size() < 2 && !control) {
      storage_->notes.push_back("point " + id + " is seen in " + std::to_string(point_rays.size()) +
                                " image only and left out");
      continue;
    }
    Eigen::Vector3d start;
    if (ground && ground->xyz_m && ground->role != PointRole::kCheck) {
      start = *ground->xyz_m;  // control survey, or an approximation given for a tie point
    } else if (auto x = IntersectRays(point_rays)) {
      start = *x;
    } else {
      start = IntersectWithHeight(point_rays, fallback_height);
    }
    AddPoint(p, start);
    s.points[p].rays = static_cast<int>(point_rays.size());
  }
  for (const auto& p : project_.points)
    if (p.role != PointRole::kTie &&
        (s.FindPoint(p.id) < 0 || s.points[s.FindPoint(p.id)].block < 0))
      storage_->notes.push_back(PointRoleName(p.role) + " point " + p.id +
                                " has too few image observations and is not used");
}

void BlockAdjustment::AddImageResiduals(const calib::LossOptions& loss) {
  for (size_t i = 0; i < storage_->observations.size(); ++i) {
    const auto& o = storage_->observations[i];
    const BlockId point = storage_->points[storage_->point_of_observation[i]].block;
    if (point < 0) continue;
    ImagingModel* model = storage_->sensor_of_observation[i];
    ObservationTerm term = model->Observe(storage_->context, o, point);
    storage_->snooped_groups.insert(term.group);
    const auto id = builder_.AddResidual(
        term.group, std::move(term.cost), term.blocks, model->Describe(o), loss);
    storage_->observation_of_residual[id] = i;
  }
}

void BlockAdjustment::ScaleControlWeights(double weight) {
  AEROCAL_CHECK(weight > 0) << "control weight factor " << weight;
  const double k = 1.0 / std::sqrt(weight);
  std::map<calib::ResidualId, std::pair<PointIndex, const char*>> scaled;
  for (const auto& [id, survey] : storage_->control_of_residual) {
    if (!builder_.IsActive(id)) {  // left out by snooping: stays out
      scaled[id] = survey;
      continue;
    }
    const auto& state = storage_->points[survey.first];
    const Eigen::Vector3d& xyz = *state.ground->xyz_m;
    const Eigen::Vector3d s = state.ground->sigma_m * k;
    const bool plan = survey.second == kSurveyPlan;
    auto cost =
        plan
            ? std::make_unique<calib::PriorCostFunction>(3,
                                                         std::vector<int>{0, 1},
                                                         std::vector<double>{xyz.x(), xyz.y()},
                                                         std::vector<double>{s.x(), s.y()})
            : std::make_unique<calib::PriorCostFunction>(
                  3, std::vector<int>{2}, std::vector<double>{xyz.z()}, std::vector<double>{s.z()});
    const std::string label = builder_.ResidualLabel(id);
    builder_.RemoveResidual(id);
    scaled[builder_.AddResidual(calib::kGroupControl, std::move(cost), {state.block}, label)] =
        survey;
  }
  storage_->control_of_residual = std::move(scaled);
}

void BlockAdjustment::AddPriors() {
  for (PointIndex p = 0; p < static_cast<PointIndex>(storage_->points.size()); ++p) {
    const auto& state = storage_->points[p];
    if (state.block < 0 || !state.Control()) continue;
    const Eigen::Vector3d& xyz = *state.ground->xyz_m;
    const Eigen::Vector3d& s = state.ground->sigma_m;
    // Plan and height are two observations: snooping tests each with its own redundancy and
    // leaves out only the failing one (a wrong height must not take a good plan survey along).
    const calib::ResidualId plan = builder_.AddResidual(
        calib::kGroupControl,
        std::make_unique<calib::PriorCostFunction>(3,
                                                   std::vector<int>{0, 1},
                                                   std::vector<double>{xyz.x(), xyz.y()},
                                                   std::vector<double>{s.x(), s.y()}),
        {state.block},
        "control " + storage_->point_ids[p] + " plan");
    const calib::ResidualId height = builder_.AddResidual(
        calib::kGroupControl,
        std::make_unique<calib::PriorCostFunction>(
            3, std::vector<int>{2}, std::vector<double>{xyz.z()}, std::vector<double>{s.z()}),
        {state.block},
        "control " + storage_->point_ids[p] + " height");
    storage_->control_of_residual[plan] = {p, kSurveyPlan};
    storage_->control_of_residual[height] = {p, kSurveyHeight};
  }
  if (options_.use_eo_priors) {
    AddPlatformBlocks();
    Storage& s = *storage_;
    for (ExposureIndex k : s.exposure_order) {
      const auto& state = s.exposures[k];
      const Exposure& e = *state.exposure;
      const std::string& image = e.image;
      if (e.center_sigma_m)
        builder_.AddResidual(
            calib::kGroupEoPrior,
            calib::GnssPriorResidual::Create(
                e.center_m, *e.center_sigma_m, e.velocity_mps.value_or(Eigen::Vector3d::Zero())),
            {state.opk_block, state.center_block, s.lever_block, s.time_block},
            "GNSS " + image);
      if (e.opk_sigma_rad)
        builder_.AddResidual(calib::kGroupEoPrior,
                             calib::OpkPriorResidual::Create(e.opk_rad, *e.opk_sigma_rad),
                             {state.opk_block, s.boresight_block},
                             "IMU " + image);
    }
  } else if (PlatformEstimated(project_.platform)) {
    storage_->notes.push_back("platform parameters ignored: the GNSS/IMU priors are off");
  }
  if (options_.use_interior_sigma) {
    for (CameraIndex k = 0; k < storage_->index.NumCameras(); ++k) {
      const std::string& id = storage_->index.CameraId(k);
      if (auto prior = InteriorPriorOf(project_.cameras.at(id), options_.free_interior))
        builder_.AddResidual(calib::kGroupInteriorPrior,
                             std::move(prior),
                             {storage_->frame.InteriorBlock(k)},
                             "interior prior " + id);
    }
  }
}

void BlockAdjustment::AddPlatformBlocks() {
  const PlatformSpec& p = project_.platform;
  Storage& s = *storage_;
  bool gnss = false, imu = false;
  for (const auto& e : project_.exposures) {
    gnss |= e.center_sigma_m.has_value();
    imu |= e.opk_sigma_rad.has_value();
  }
  const std::string where = p.source.empty() ? "platform" : p.source + ": platform";
  if (!gnss &&
      (p.lever_arm != PlatformParamMode::kFixed || p.time_offset != PlatformParamMode::kFixed))
    throw ConfigError(where +
                      ": the lever arm and the GNSS time offset are estimated from GNSS "
                      "priors, but exposures.csv has no sigma_X/Y/Z columns");
  if (!imu && p.boresight != PlatformParamMode::kFixed)
    throw ConfigError(where +
                      ": the boresight is estimated from IMU priors, but exposures.csv has "
                      "no sigma_omega/phi/kappa columns");
  // How one platform block enters: held, free, or its value as a weighted observation
  // (calib/problem/mounted_block.h; group platform_prior).
  auto enter = [&](BlockId block,
                   PlatformParamMode mode,
                   const std::vector<double>& values,
                   double sigma,
                   const std::string& label) {
    calib::ApplyBlockMode(builder_, block, mode);
    calib::AddBlockPrior(builder_,
                         block,
                         mode,
                         values,
                         std::vector<double>(values.size(), sigma),
                         kPlatformOwner,
                         label);
  };
  if (gnss) {
    const bool timed = p.time_offset != PlatformParamMode::kFixed || p.time_offset_s != 0.0;
    for (const auto& e : project_.exposures)
      if (timed && e.center_sigma_m && !e.velocity_mps)
        ThrowInputError({project_.exposures_file, e.line},
                        "image " + e.image +
                            ": the GNSS time offset needs the platform velocity "
                            "(columns vX, vY, vZ, m/s)");
    s.lever_arm = p.lever_arm_m;
    s.time_offset = p.time_offset_s;
    s.lever_block = builder_.AddBlock(
        "platform lever_arm", s.lever_arm.data(), 3, BlockKind::kOther, {"x", "y", "z"});
    s.time_block =
        builder_.AddBlock("platform time_offset", &s.time_offset, 1, BlockKind::kOther, {"dt"});
    enter(s.lever_block,
          p.lever_arm,
          {s.lever_arm.x(), s.lever_arm.y(), s.lever_arm.z()},
          p.lever_arm_sigma_m,
          "lever arm prior");
    enter(s.time_block, p.time_offset, {s.time_offset}, p.time_offset_sigma_s, "time offset prior");
  }
  if (imu) {
    s.boresight = p.boresight_rad;
    s.boresight_block = builder_.AddBlock(
        "platform boresight", s.boresight.data(), 3, BlockKind::kOther, kAngleNames);
    enter(s.boresight_block,
          p.boresight,
          {s.boresight.x(), s.boresight.y(), s.boresight.z()},
          p.boresight_sigma_rad,
          "boresight prior");
  }
}

void BlockAdjustment::DefineDatum() {
  int control = 0;
  for (const auto& state : storage_->points) control += state.block >= 0 && state.Control();
  bool gnss = false;
  for (const auto& state : storage_->exposures)
    gnss |= options_.use_eo_priors && state.exposure->center_sigma_m.has_value();
  if (control > 0 || gnss) {
    storage_->datum = std::to_string(control) + " control point(s) as weighted observations" +
                      (gnss ? " and GNSS camera centres" : "");
    return;
  }
  if (!options_.free_network_datum) {
    storage_->datum = "none: no control points and no GNSS (free network, datum defect)";
    return;
  }
  // Dependent relative orientation: first exposure fixed, one base component of the farthest.
  std::vector<bool> observed(storage_->exposures.size(), false);
  for (ExposureIndex e : storage_->exposure_of_observation) observed[e] = true;
  const Exposure* first = nullptr;
  for (ExposureIndex k = 0; k < static_cast<ExposureIndex>(observed.size()) && !first; ++k)
    if (observed[k]) first = &project_.exposures[k];
  if (!first) return;
  const auto& a = storage_->exposures[storage_->index.Exposure(first->image)];
  const Exposure* far = nullptr;
  ExposureIndex far_index = -1;
  double far_distance = 0.0;
  for (ExposureIndex k = 0; k < static_cast<ExposureIndex>(observed.size()); ++k) {
    if (!observed[k]) continue;
    const Exposure& e = project_.exposures[k];
    const double d = (e.center_m - first->center_m).norm();
    if (d > far_distance) {
      far_distance = d;
      far = &e;
      far_index = k;
    }
  }
  builder_.FixBlock(a.opk_block);
  builder_.FixBlock(a.center_block);
  storage_->free_network = true;
  std::string text = "free network: image " + first->image + " fixed at its starting orientation";
  if (far) {
    int axis = 0;
    (far->center_m - first->center_m).cwiseAbs().maxCoeff(&axis);
    builder_.FixEntries(storage_->exposures[far_index].center_block, {axis});
    text += ", image " + far->image + " centre " + kCenterNames[axis] + " fixed (scale)";
  }
  storage_->datum = text;
}

std::string BlockAdjustment::Describe(calib::ResidualId id) const {
  const auto it = storage_->observation_of_residual.find(id);
  if (it == storage_->observation_of_residual.end()) return builder_.ResidualLabel(id);
  return storage_->sensor_of_observation[it->second]->Describe(storage_->observations[it->second]);
}

}  // namespace aerocal::triangulation
