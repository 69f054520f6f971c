// The state of a BlockAdjustment (its dense indices, blocks and bookkeeping), private to
// triangulation/adjustment: shared by the block's construction (block_adjustment.cc) and its run
// (block_adjustment_run.cc). Not an interface; nothing outside those files includes it.
#pragma once

#include "triangulation/adjustment/block_adjustment.h"
#include "triangulation/sensor/frame_camera.h"

#include <Eigen/Core>

#include <algorithm>
#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

struct BlockAdjustment::Storage {
  Storage(const Project& project, const AdjustOptions& options, calib::ProblemBuilder& builder)
      : platform(BuildPlatform(project)),
        index(platform.index),
        context{project, options, builder, index, poses, frame, &platform} {}
  struct ExposureState {
    const Exposure* exposure = nullptr;
    const calib::Camera* camera = nullptr;
    // The rotation as a unit quaternion [w, x, y, z] (the solver's block, calib/camera/rotation.h);
    // omega-phi-kappa only when read and written.
    Eigen::Vector4d rotation = Eigen::Vector4d(1, 0, 0, 0);
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    calib::BlockId opk_block = -1, center_block = -1;
    ExposureIndex index = -1;
  };
  struct PointState {
    Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
    calib::BlockId block = -1;            // -1: not in the adjustment (too few rays)
    const GroundPoint* ground = nullptr;  // nullptr: a tie point absent from points.csv
    int rays = 0;                         // virtual-image rays
    bool Control() const { return ground && ground->role == PointRole::kControl; }
  };
  /// The point of `id`, -1 when no observation names it (strings only at the boundary).
  PointIndex FindPoint(const std::string& id) const {
    const auto it = std::lower_bound(point_ids.begin(), point_ids.end(), id);
    return it != point_ids.end() && *it == id ? static_cast<PointIndex>(it - point_ids.begin())
                                              : -1;
  }
  Platform platform;              // sensors and observations as dense indices (block/platform.h)
  const DenseIndex& index;        // platform.index
  std::vector<PoseBlocks> poses;  // by ExposureIndex
  FrameCamera frame;              // the interiors of every camera, the frame kind's model
  std::vector<std::unique_ptr<ImagingModel>> sensors;  // the other kinds' models: given, then made
  // The model of each kind (by SensorKind), null when the kind cannot be adjusted here.
  std::array<ImagingModel*, kSensorKinds.size()> model_of_kind{};
  SensorContext context;
  // Dense indices, assigned once when the block is built; ids are strings only when read and in
  // reports. Both vectors are sized once and never grow afterwards: the builder holds pointers
  // into their elements.
  std::vector<ExposureState> exposures;       // by ExposureIndex (Project::exposures order)
  std::vector<ExposureIndex> exposure_order;  // by image id: the order of priors and reports
  std::vector<int> exposure_rank;             // by ExposureIndex: position in exposure_order
  std::vector<std::string> point_ids;         // by PointIndex: the observed points, sorted ids
  std::vector<PointState> points;             // by PointIndex
  // Observations used in the adjustment (sub-image ones no kind measures mapped to the virtual
  // image), the kind that measures each, their exposure and point, and their residuals.
  std::vector<ImageObservation> observations;
  std::vector<ImagingModel*> sensor_of_observation;
  std::vector<int> source_of_observation;  // its index in Project::observations
  std::vector<ExposureIndex> exposure_of_observation;
  std::vector<PointIndex> point_of_observation;
  std::map<calib::ResidualId, size_t> observation_of_residual;
  std::set<std::string> snooped_groups;  // the groups of the image observations' terms
  // Surveyed coordinates: two residuals per control point, its plan (X, Y) and its height (Z).
  std::map<calib::ResidualId, std::pair<PointIndex, const char*>> control_of_residual;
  // Snooping left them out: the components ("plan", "height") with the w of their test.
  std::map<PointIndex, std::vector<std::pair<std::string, double>>> survey_left_out;
  std::map<calib::ResidualId, ObservationTest> tests;  // data snooping's last word on each
  std::vector<std::string> notes;
  // The GNSS/IMU platform (Project::platform): lever arm, GNSS time offset (when exposures carry
  // GNSS priors) and boresight (with IMU priors); -1 when absent.
  Eigen::Vector3d lever_arm = Eigen::Vector3d::Zero(), boresight = Eigen::Vector3d::Zero();
  double time_offset = 0.0;
  calib::BlockId lever_block = -1, boresight_block = -1, time_block = -1;
  std::string datum;
  bool free_network = false;  // datum by a dependent relative orientation, not by the survey
  std::vector<calib::ResidualId> unresolved_ids;  // failing surveys snooping could not leave out
};

}  // namespace aerocal::triangulation
