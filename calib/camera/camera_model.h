// The camera-model registry: every registered model in one type list, ONE dispatch from a model id
// (VisitCameraModel, as VisitMappingModel does for the mappings and COLMAP's
// CAMERA_MODEL_SWITCH_CASES in src/colmap/sensor/models.h), and ModelCamera, a camera in any
// registered model: {model, params} plus its image format.
//
// Every model (calib/camera/brown_fraser10.h, calib/camera/models/*.h) is a struct with
//   kId (a frozen CameraModelId), kName (the YAML/JSON string), an Index enum, kNumParams,
//   kParams (constexpr table: name, unit, group), kCorrectionForm, and the uniform functions in
//   photo mm (models/model_common.h):
//     template <T> bool IdealFromMeasured(const T* params, const PixelFrame&, const T* xy, T*
//     ideal) template <T> bool MeasuredFromIdeal(const T* params, const PixelFrame&, const T*
//     ideal, T* xy) template <T> T PrincipalDistanceMm(const T* params, const PixelFrame&) bool
//     ToOpenCv(const double*, const PixelFrame&, OpenCvParams*)      // true: exact bool
//     FromOpenCv(const OpenCvParams&, const PixelFrame&, double*)    // true: exact
// The templated functions work with ceres::Jet; one formula serves the solver and the
// double-precision code.
#pragma once

#include "calib/camera/brown_fraser10.h"
#include "calib/camera/models/colmap.h"
#include "calib/camera/models/metashape.h"
#include "calib/camera/models/opencv.h"
#include "calib/camera/models/pix4d.h"
#include "calib/camera/pixel_frame.h"
#include "calib/core/error.h"

#include <Eigen/Core>

#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace aerocal::calib {

template <typename... Models>
struct CameraModelList {};

/// Every registered model. Adding a model: its header, one entry here (and its CameraModelId).
using RegisteredCameraModels = CameraModelList<BrownFraser10Model,
                                               OpenCvModel,
                                               OpenCvFisheyeModel,
                                               ColmapSimplePinholeModel,
                                               ColmapPinholeModel,
                                               ColmapSimpleRadialModel,
                                               ColmapRadialModel,
                                               ColmapOpenCvModel,
                                               ColmapFullOpenCvModel,
                                               MetashapeFrameModel,
                                               Pix4dPerspectiveModel>;

namespace internal {
template <typename Visitor, typename First, typename... Rest>
decltype(auto) VisitIn(CameraModelId id, Visitor&& visitor, CameraModelList<First, Rest...>) {
  if constexpr (sizeof...(Rest) == 0) {
    if (id != First::kId)
      throw LogicError("unregistered camera model id " + std::to_string(static_cast<int>(id)));
    return visitor(First{});
  } else {
    if (id == First::kId) return visitor(First{});
    return VisitIn(id, std::forward<Visitor>(visitor), CameraModelList<Rest...>{});
  }
}
template <typename Visitor, typename... Models>
void ForEachIn(Visitor&& visitor, CameraModelList<Models...>) {
  (visitor(Models{}), ...);
}
}  // namespace internal

/// THE dispatch on a model id: calls visitor(Model{}) for the model with that id (every branch
/// must return the same type). No other switch on model ids anywhere.
template <typename Visitor>
decltype(auto) VisitCameraModel(CameraModelId id, Visitor&& visitor) {
  return internal::VisitIn(id, std::forward<Visitor>(visitor), RegisteredCameraModels{});
}

/// Calls visitor(Model{}) for every registered model (tables, name lookup, typed tests).
template <typename Visitor>
void ForEachCameraModel(Visitor&& visitor) {
  internal::ForEachIn(std::forward<Visitor>(visitor), RegisteredCameraModels{});
}

/// COLMAP's models (models/colmap.h) by their COLMAP name ("OPENCV", ...); nullopt when the
/// name is not one of SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV.
std::optional<CameraModelId> CameraModelFromColmapName(std::string_view colmap_name);
std::string_view ColmapName(CameraModelId id);  // "" for a model COLMAP does not have

/// The model with this stable name ("brown_fraser_10", "opencv", ...); nullopt when unknown.
std::optional<CameraModelId> CameraModelFromName(std::string_view name);
std::string_view CameraModelName(CameraModelId id);
/// The registered names, comma separated (for messages).
std::string CameraModelNames();
int CameraModelParamCount(CameraModelId id);
/// The model's free set of a calibration when none is given (its kDefaultFree: comma-separated
/// table names, or "all").
std::string_view DefaultFreeInterior(CameraModelId id);
/// The distortion profile at a radius r (mm from the principal point), um, of a model that defines
/// one with its own terms (static RadialDistortionUm / DecentringDistortionUm in its struct:
/// brown_fraser_10); nullopt for any other model (DistortionOverFormat measures those).
struct DistortionAtRadius {
  double radial_um = 0.0, decentring_um = 0.0;
};
std::optional<DistortionAtRadius> ModelDistortionAtRadius(CameraModelId id,
                                                          const double* params,
                                                          double r_mm);
bool HasDistortionAtRadius(CameraModelId id);
std::vector<ParamInfo> CameraModelParams(CameraModelId id);
/// The names of a parameter table, comma separated (for messages).
std::string JoinParamNames(const std::vector<ParamInfo>& table);

/// A camera in any registered model: the model, its parameters in table order and units, and the
/// image format the parameters refer to.
struct ModelCamera {
  CameraModelId model = CameraModelId::kBrownFraser10;
  std::vector<double> params;
  PixelFrame frame;

  /// Ideal photo coordinates (mm, reduced to the principal point, at the principal distance)
  /// of a measured pixel; false where the model's inversion does not converge.
  bool IdealFromPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* ideal_mm) const;
  /// Measured pixel of ideal photo coordinates; false where the inversion does not converge.
  bool PixelFromIdeal(const Eigen::Vector2d& ideal_mm, Eigen::Vector2d* pixel) const;
  double PrincipalDistanceMm() const;
};

}  // namespace aerocal::calib
