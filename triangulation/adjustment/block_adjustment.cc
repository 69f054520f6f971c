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
// The automatic rejection cap (AdjustOptions::max_rejections 0): 10 % of the tested image
// observations, at least this many.
constexpr int kMinAutomaticCap = 100;
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
  // The points: a dense index per observed point id (sorted ids), assigned once.
  s.point_ids = s.platform.point_ids;
  s.points.resize(s.point_ids.size());  // once: the builder keeps pointers into the states
  // Project::FindPoint's first match, without its linear search (quadratic at 180,000 points).
  std::unordered_map<std::string_view, const GroundPoint*> ground_of_id;
  for (const auto& g : project_.points) ground_of_id.emplace(g.id, &g);
  for (PointIndex p = 0; p < static_cast<PointIndex>(s.points.size()); ++p) {
    const auto ground = ground_of_id.find(s.point_ids[p]);
    s.points[p].ground = ground == ground_of_id.end() ? nullptr : ground->second;
  }
  const int n_exposures = s.index.NumExposures();
  const int n_points = static_cast<int>(s.points.size());
  // An exposure that no observation names is named, never silently unused (issue 28).
  std::vector<bool> observed(n_exposures, false);
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
  // An exposure seeing fewer than three points (and not held by GNSS and IMU priors) cannot be
  // oriented; leaving it out can leave a point with one ray, so repeat until nothing changes.
  for (bool changed = true; changed;) {
    changed = false;
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
    changed = s.observations.size() != before;
  }
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

namespace {

// Whitened image residuals of `ids` with the point block (values at `xyz`) set to `at`.
std::vector<Eigen::VectorXd> ResidualsWithPointAt(const calib::ProblemBuilder& builder,
                                                  const std::vector<calib::ResidualId>& ids,
                                                  Eigen::Vector3d* xyz,
                                                  const Eigen::Vector3d& at) {
  *xyz = at;
  std::vector<Eigen::VectorXd> out;
  for (calib::ResidualId id : ids) {
    const std::vector<double> v = builder.EvaluateResidual(id);
    out.push_back(Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<int>(v.size())));
  }
  return out;
}

// Least squares of the point alone (the poses and the camera held) on the rays `use` of `ids`,
// Gauss-Newton from `start` with a central-difference Jacobian; nullopt when the rays do not
// determine the point.
std::optional<Eigen::Vector3d> FitPoint(const calib::ProblemBuilder& builder,
                                        const std::vector<calib::ResidualId>& ids,
                                        const std::vector<bool>& use,
                                        Eigen::Vector3d* xyz,
                                        Eigen::Vector3d start) {
  constexpr double kStepM = 1e-3;  // central differences of residuals linear at this scale
  std::vector<calib::ResidualId> rays;
  for (size_t i = 0; i < ids.size(); ++i)
    if (use[i]) rays.push_back(ids[i]);
  for (int iteration = 0; iteration < 8; ++iteration) {
    const auto at = ResidualsWithPointAt(builder, rays, xyz, start);
    int m = 0;
    for (const auto& v : at) m += static_cast<int>(v.size());
    Eigen::VectorXd r(m);
    Eigen::MatrixXd j(m, 3);
    for (int c = 0, row = 0; c < static_cast<int>(at.size());
         row += static_cast<int>(at[c].size()), ++c)
      r.segment(row, at[c].size()) = at[c];
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d plus = start, minus = start;
      plus(k) += kStepM;
      minus(k) -= kStepM;
      const auto vp = ResidualsWithPointAt(builder, rays, xyz, plus);
      const auto vm = ResidualsWithPointAt(builder, rays, xyz, minus);
      for (int c = 0, row = 0; c < static_cast<int>(at.size());
           row += static_cast<int>(at[c].size()), ++c)
        j.block(row, k, at[c].size(), 1) = (vp[c] - vm[c]) / (2 * kStepM);
    }
    const Eigen::Matrix3d n = j.transpose() * j;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(n);
    if (!(eig.eigenvalues()(0) > 1e-9 * eig.eigenvalues()(2))) return std::nullopt;
    const Eigen::Vector3d step = -n.ldlt().solve(j.transpose() * r);
    start += step;
    if (step.norm() < 1e-6) break;
  }
  return start;
}

}  // namespace

std::vector<BlockAdjustment::Screened> BlockAdjustment::ScreenRobustly(double reject) {
  std::vector<calib::ResidualId> ids;
  for (const auto& [id, index] : storage_->observation_of_residual)
    if (builder_.IsActive(id) && builder_.ResidualGroup(id) == calib::kGroupImage)
      ids.push_back(id);
  const calib::ObservationCofactors cof = builder_.ComputeObservationCofactors(ids, false);
  std::vector<double> scaled;  // |v| / sqrt(r) of the testable components
  std::map<calib::ResidualId, std::vector<double>> values;
  for (calib::ResidualId id : ids) {
    values[id] = builder_.EvaluateResidual(id);
    const auto& r = cof.redundancy.at(id);
    for (size_t k = 0; k < r.size(); ++k)
      if (r[k] > 1e-6) scaled.push_back(std::abs(values[id][k]) / std::sqrt(r[k]));
  }
  std::vector<Screened> out;
  if (scaled.empty()) return out;
  const double scale = std::max(1e-12, 1.4826 * Median(scaled));
  std::map<calib::ResidualId, double> w_of;
  std::map<PointIndex, std::vector<calib::ResidualId>> rays_of_point;  // by point (id order)
  for (calib::ResidualId id : ids) {
    const auto& r = cof.redundancy.at(id);
    const auto& v = values.at(id);
    double w = 0.0;
    for (size_t k = 0; k < r.size(); ++k)
      if (r[k] > 1e-6) w = std::max(w, std::abs(v[k]) / (scale * std::sqrt(r[k])));
    w_of[id] = w;
    rays_of_point[storage_->point_of_observation[storage_->observation_of_residual.at(id)]]
        .push_back(id);
  }
  // A point of three or more rays with a ray beyond `reject` is judged on its own, the poses and
  // the camera held at the robust solution: the Cauchy solution can settle a point on its
  // blunder and one good ray (a local minimum), which makes the good rays look like the gross
  // errors. The point is fitted to every pair of its rays; the fit that most rays agree with
  // (|v| / s <= reject on every component; ties by the truncated sum of squares), refitted to
  // those rays, judges every ray by its residual there. When two fits with different sets of
  // rays agree equally well, the rays cannot be told apart here: none is excluded, and the final
  // adjustment's snooping judges them with their correlated group. A control point keeps the
  // one-pass cut, except when every one of its rays is beyond it: then its survey is the suspect
  // (a wrong survey makes all its good rays look like gross errors), and the rays go to the final
  // adjustment, which tests the survey first.
  std::map<calib::ResidualId, double> judged;  // per-point verdicts: the ray's |v| / s there
  for (const auto& point_rays : rays_of_point) {
    // (a lambda may not capture a structured binding in C++17)
    Storage::PointState& state = storage_->points[point_rays.first];
    const auto& rays = point_rays.second;
    const int n = static_cast<int>(rays.size());
    const bool control = state.Control();
    bool suspect = false;
    for (calib::ResidualId id : rays) suspect |= w_of.at(id) > reject;
    if (!suspect) continue;
    if (control) {  // every ray beyond the cut: its survey is suspect, not its rays
      bool all = n >= 2;
      for (calib::ResidualId id : rays) all &= w_of.at(id) > reject;
      if (all)
        for (calib::ResidualId id : rays) judged[id] = 0.0;  // the final adjustment tests both
      continue;
    }
    if (n < 3) continue;
    Eigen::Vector3d* xyz = &state.xyz;
    const Eigen::Vector3d robust = *xyz;
    const auto judge = [&](const Eigen::Vector3d& at, std::vector<bool>* agree, double* cost) {
      const auto v = ResidualsWithPointAt(builder_, rays, xyz, at);
      int count = 0;
      *cost = 0.0;
      for (int i = 0; i < n; ++i) {
        const double worst = v[i].cwiseAbs().maxCoeff() / scale;
        (*agree)[i] = worst <= reject;
        count += (*agree)[i];
        *cost += std::min(v[i].squaredNorm() / (scale * scale), reject * reject);
      }
      return count;
    };
    int best_count = -1;
    double best_cost = 0.0;
    std::vector<bool> best(n, false), agree(n, false);
    bool ambiguous = false;
    const auto consider = [&](const Eigen::Vector3d& at) {
      double cost = 0.0;
      const int count = judge(at, &agree, &cost);
      if (count > best_count || (count == best_count && cost < best_cost)) {
        ambiguous = count == best_count && agree != best;
        best_count = count;
        best_cost = cost;
        best = agree;
      } else if (count == best_count && agree != best) {
        ambiguous = true;
      }
    };
    consider(robust);
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) {
        std::vector<bool> pair(n, false);
        pair[a] = pair[b] = true;
        if (const auto fit = FitPoint(builder_, rays, pair, xyz, robust)) consider(*fit);
      }
    if (!ambiguous && best_count >= 2) {
      if (const auto fit = FitPoint(builder_, rays, best, xyz, robust)) {
        const auto v = ResidualsWithPointAt(builder_, rays, xyz, *fit);
        for (int i = 0; i < n; ++i) judged[rays[i]] = v[i].cwiseAbs().maxCoeff() / scale;
      }
    } else {
      for (calib::ResidualId id : rays) judged[id] = 0.0;  // left to the final snooping
    }
    *xyz = robust;
  }
  for (calib::ResidualId id : ids) {
    const auto by_point = judged.find(id);
    const double w = by_point != judged.end() ? by_point->second : w_of.at(id);
    if (w <= reject) continue;
    const auto& v = values.at(id);
    const size_t index = storage_->observation_of_residual.at(id);
    const ImageObservation& o = storage_->observations.at(index);
    out.push_back(
        {o, storage_->source_of_observation[index], Eigen::Vector2d(v[0], v[1]) * o.sigma_px, w});
  }
  return out;
}

std::string BlockAdjustment::Describe(calib::ResidualId id) const {
  const auto it = storage_->observation_of_residual.find(id);
  if (it == storage_->observation_of_residual.end()) return builder_.ResidualLabel(id);
  return storage_->sensor_of_observation[it->second]->Describe(storage_->observations[it->second]);
}

calib::SnoopingOutcome BlockAdjustment::Snoop(AdjustmentResult* result) {
  // The datum guard: no control point below two rays, no exposure below three points (unless
  // GNSS and IMU priors hold it). Counts of the active rays, kept up to date on every approval.
  Storage& st = *storage_;
  std::vector<int> point_rays(st.points.size(), 0), image_rays(st.exposures.size(), 0);
  for (const auto& [id, index] : st.observation_of_residual)
    if (builder_.IsActive(id)) {
      ++point_rays[st.point_of_observation[index]];
      ++image_rays[st.exposure_of_observation[index]];
    }
  calib::SnoopingOptions snooping;
  // The image groups the kinds' terms came in (AddImageResiduals), and the control surveys.
  snooping.groups.assign(st.snooped_groups.begin(), st.snooped_groups.end());
  snooping.groups.push_back(calib::kGroupControl);
  snooping.report_only_groups = {calib::kGroupControl};
  snooping.alpha = options_.snooping_alpha;
  snooping.critical_value = options_.snooping_critical_value;
  snooping.power = options_.snooping_power;
  snooping.min_redundancy = options_.min_redundancy;
  snooping.group_correlation = options_.group_correlation;
  int tested_images = 0;
  for (int n : image_rays) tested_images += n;
  snooping.max_rejections = options_.max_rejections > 0
                                ? options_.max_rejections
                                : std::max(kMinAutomaticCap, tested_images / 10);
  snooping.model_error_sigma0 = options_.model_error_sigma0;
  snooping.leave_out_report_only = options_.leave_out_failing_control;
  // Without GNSS centres the surveys hold the datum: at least three plan and three height
  // surveys stay.
  bool gnss = false;
  for (const auto& state : st.exposures)
    gnss |= options_.use_eo_priors && state.exposure->center_sigma_m.has_value();
  snooping.veto = [&](const std::vector<calib::ResidualId>& ids) -> std::string {
    std::map<std::string, std::pair<int, int>> kept_leaving;  // by component: active, leaving
    for (const auto& [id, survey] : st.control_of_residual) {
      auto& [surveys, leaving] = kept_leaving[survey.second];
      surveys += builder_.IsActive(id);
      leaving += std::find(ids.begin(), ids.end(), id) != ids.end();
    }
    for (const auto& [component, count] : kept_leaving)
      if (count.second > 0 && !gnss && count.first - count.second < 3)
        return "leaving out the survey would leave " + std::to_string(count.first - count.second) +
               " control point(s) with a " + component +
               " survey and no GNSS centres: the datum needs 3";
    // Keyed by point index (id order) and by exposure rank (image id order): the first veto
    // found is the one named.
    std::map<PointIndex, int> lose_point;
    std::map<int, int> lose_image;
    for (calib::ResidualId id : ids) {
      const auto it = st.observation_of_residual.find(id);
      if (it == st.observation_of_residual.end()) continue;
      ++lose_point[st.point_of_observation[it->second]];
      ++lose_image[st.exposure_rank[st.exposure_of_observation[it->second]]];
    }
    for (const auto& [point, n] : lose_point) {
      if (st.points[point].Control() && point_rays[point] - n < 2)
        return "control point " + st.point_ids[point] + " would keep " +
               std::to_string(point_rays[point] - n) +
               " ray(s): its rays are kept, check its measurements";
    }
    for (const auto& [rank, n] : lose_image) {
      const ExposureIndex image = st.exposure_order[rank];
      const Exposure& e = *st.exposures[image].exposure;
      const bool held = options_.use_eo_priors && e.center_sigma_m && e.opk_sigma_rad;
      if (!held && image_rays[image] - n < 3)
        return "image " + e.image + " would keep " + std::to_string(image_rays[image] - n) +
               " point(s) and be under-determined";
    }
    for (const auto& [point, n] : lose_point) point_rays[point] -= n;
    for (const auto& [rank, n] : lose_image) image_rays[st.exposure_order[rank]] -= n;
    return "";
  };
  const calib::SolveReport first = result->solve;
  calib::SnoopingOutcome out =
      calib::SolveWithDataSnooping(builder_, options_.solver, snooping, &first);
  for (const auto& x : out.left_out) {
    const auto it = st.control_of_residual.find(x.id);
    if (it != st.control_of_residual.end())
      st.survey_left_out[it->second.first].emplace_back(it->second.second, x.w_full);
  }
  result->solve = out.report;
  if (out.solves > 0) {
    result->solve.iterations += first.iterations;  // the first solve, before snooping
    result->solve.initial_cost = first.initial_cost;
  }

  SnoopingSummary& s = result->snooping;
  s.run = true;
  s.alpha = out.alpha;
  s.alpha0 = out.alpha0;
  s.critical_value = out.critical_value;
  s.power = out.power;
  s.delta0 = out.delta0;
  s.delta0_joint = out.delta0_joint;
  s.min_redundancy = out.min_redundancy;
  s.group_correlation = out.group_correlation;
  s.reference_sigma = out.reference_sigma;
  s.cofactor_method = out.cofactor_method;
  s.cofactors_ok = out.cofactors_ok;
  s.cofactor_message = out.cofactor_message;
  s.n_tested_components = out.n_tested_components;
  s.rounds = out.rounds;
  s.max_rejections = snooping.max_rejections;
  s.cap_reached = out.cap_reached;
  s.remaining_above_critical = out.remaining_above_critical;
  s.model_error_suspected = out.model_error_suspected;
  s.model_error_evidence = out.model_error_evidence;
  s.findings = out.findings;
  s.unresolved_reason = out.unresolved_reason;
  for (const auto& x : out.unresolved) {
    storage_->unresolved_ids.push_back(x.id);
    UnresolvedSurvey u;
    u.survey = x.label;
    u.w = x.w_full;
    u.redundancy = *std::min_element(x.redundancy.begin(), x.redundancy.end());
    for (double v : x.v) u.residual_sigma = std::max(u.residual_sigma, std::abs(v));
    s.unresolved_surveys.push_back(u);
  }
  s.seconds_testing = out.seconds_testing;
  if (out.model_error_suspected) {
    int control = 0;
    for (const auto& state : storage_->points) control += state.block >= 0 && state.Control();
    if (!options_.free_interior.empty())
      s.suggestion =
          "the run already self-calibrates: check the camera model, the control survey and the "
          "a-priori sigmas";
    else if (storage_->exposures.size() >= 3 && (control >= 3 || !storage_->free_network))
      s.suggestion =
          "self-calibration with --self-calibration auto (it frees only what this block "
          "determines and what is significant, and names what it holds) may absorb it: the "
          "block has " +
          std::to_string(storage_->exposures.size()) + " exposures and " + std::to_string(control) +
          " control point(s)";
    else
      s.suggestion = "the block is too weak to self-calibrate: more control or GNSS is needed";
  }

  const auto to_test = [&](const calib::TestedObservation& x, double sigma_px) {
    ObservationTest t;
    t.tested = true;
    for (int k = 0; k < 2 && k < static_cast<int>(x.v.size()); ++k) {
      t.redundancy(k) = x.redundancy[k];
      t.w(k) = x.w[k];
      t.mdb_sigma(k) = x.mdb_sigma[k];
      t.mdb_px(k) = x.mdb_sigma[k] * sigma_px;
    }
    t.group_size = x.group_size;
    t.verdict = calib::VerdictName(x.verdict);
    t.reason = x.reason;
    return t;
  };
  for (const auto& x : out.tested) {
    const auto it = storage_->observation_of_residual.find(x.id);
    const bool image = it != storage_->observation_of_residual.end();
    if (image) {
      const ObservationTest t = to_test(x, storage_->observations[it->second].sigma_px);
      storage_->tests[x.id] = t;
      s.n_weakly_controlled += t.redundancy.minCoeff() < options_.min_redundancy;
      s.n_untestable += t.redundancy.minCoeff() < 1e-6;
      s.n_in_groups += t.group_size > 1;
    }
    if (x.verdict == calib::SnoopingVerdict::kAccepted) continue;
    FlaggedObservation f;
    f.what = image ? Describe(x.id) : x.label;
    f.verdict = calib::VerdictName(x.verdict);
    f.reason = x.reason;
    f.w = x.verdict == calib::SnoopingVerdict::kWeaklyControlled ? x.w_weak : x.w_max;
    if (x.component >= 0) {
      f.redundancy = x.redundancy[x.component];
      f.mdb_sigma = x.mdb_sigma[x.component];
    }
    f.group_size = x.group_size;
    s.flagged.push_back(f);
  }
  for (const auto& x : out.rejected) {
    const auto it = storage_->observation_of_residual.find(x.id);
    if (it == storage_->observation_of_residual.end()) continue;
    const auto& o = storage_->observations[it->second];
    RejectedObservation r;
    r.image = o.image;
    r.point = o.point;
    r.measured_px = o.pixel;
    storage_->sensor_of_observation[it->second]->Annotate(o, &r);
    r.w = x.w_max;
    if (x.v.size() == 2) r.residual_px = Eigen::Vector2d(x.v[0], x.v[1]) * o.sigma_px;
    r.test = to_test(x, o.sigma_px);
    for (calib::ResidualId member : x.correlated) {
      const auto m = storage_->observation_of_residual.find(member);
      if (m != storage_->observation_of_residual.end())
        r.group.push_back(storage_->observations[m->second].image);
    }
    storage_->tests[x.id] = r.test;
    result->rejected.push_back(r);
  }
  return out;
}

}  // namespace aerocal::triangulation
