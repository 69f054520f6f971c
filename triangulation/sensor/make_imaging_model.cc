#include "triangulation/sensor/make_imaging_model.h"

#include "triangulation/sensor/frame_camera.h"
#include "triangulation/sensor/mapped_subimage_camera.h"

namespace aerocal::triangulation {

std::unique_ptr<ImagingModel> MakeImagingModel(SensorKind kind,
                                               const ImagingModelOptions& options) {
  switch (kind) {
    case SensorKind::kFrame:
      return std::make_unique<FrameCamera>();
    case SensorKind::kSubimage:
      if (options.joint) return std::make_unique<SubimageCamera>(*options.joint);
      return std::make_unique<MappedSubimageCamera>();
    case SensorKind::kRigHead:
      if (options.rig) return std::make_unique<RigHeadCamera>(*options.rig);
      return nullptr;
    case SensorKind::kLine:
      if (options.line)
        return std::make_unique<LineScanCamera>(
            *options.line->camera, *options.line->pos, options.line->options);
      return nullptr;
  }
  return nullptr;
}

std::string_view UnconfiguredReason(SensorKind kind) {
  switch (kind) {
    case SensorKind::kRigHead:
      return "rig head observations are adjusted by the rig bundle (aerocal adjust without "
             "--joint-stitching)";
    case SensorKind::kLine:
      return "line camera observations are adjusted by aerocal pushbroom calibrate";
    case SensorKind::kFrame:
    case SensorKind::kSubimage:
      break;
  }
  return "";
}

}  // namespace aerocal::triangulation
