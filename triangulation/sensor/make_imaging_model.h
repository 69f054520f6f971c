// The factory of the sensor kinds: MakeImagingModel is the one switch on SensorKind
// (triangulation/block/platform.h) that creates an ImagingModel, one case per kind. A kind that
// needs a configuration (the rig bundle's options, a line camera and its POS) is made only when
// the caller gives it; otherwise the factory says which command adjusts it
// (UnconfiguredReason), and the block adjustment names that for the first observation of the
// kind (exit 2). docs/architecture.md "How to add a sensor kind".
#pragma once

#include "calib/camera/line_camera.h"
#include "triangulation/block/platform.h"
#include "triangulation/pushbroom/pos_trajectory.h"
#include "triangulation/sensor/imaging_model.h"
#include "triangulation/sensor/line_scan_camera.h"
#include "triangulation/sensor/rig_head_camera.h"
#include "triangulation/sensor/subimage_camera.h"

#include <memory>
#include <optional>
#include <string_view>

namespace aerocal::triangulation {

/// The configuration of the kinds that need one; each unset one gets the kind's default.
struct ImagingModelOptions {
  /// Sub-image kind: the mappings refined in the bundle (SubimageCamera, the joint adjustment);
  /// unset: the camera file's mappings (MappedSubimageCamera).
  std::optional<SubimageCameraOptions> joint;
  /// Rig-head kind: the rig bundle (RigHeadCamera); unset: not adjustable (UnconfiguredReason).
  std::optional<RigAdjustOptions> rig;
  /// Line kind: the line camera and its POS trajectory (both must outlive the model) and what is
  /// estimated; unset: not adjustable.
  struct Line {
    const calib::LineCamera* camera = nullptr;
    const PosTrajectory* pos = nullptr;
    LineScanOptions options;
  };
  std::optional<Line> line;
};

/// The model of `kind` with `options`; nullptr when the kind needs a configuration `options`
/// does not hold.
std::unique_ptr<ImagingModel> MakeImagingModel(SensorKind kind,
                                               const ImagingModelOptions& options = {});
/// The model of a platform's sensor (its kind).
inline std::unique_ptr<ImagingModel> MakeImagingModel(const Sensor& sensor,
                                                      const ImagingModelOptions& options = {}) {
  return MakeImagingModel(sensor.kind, options);
}
/// Why MakeImagingModel(kind) without options gives no model, naming the command that adjusts
/// the kind; empty when it gives one.
std::string_view UnconfiguredReason(SensorKind kind);

}  // namespace aerocal::triangulation
