#include "calib/camera/camera_model.h"

#include <type_traits>

namespace aerocal::calib {

std::optional<CameraModelId> CameraModelFromName(std::string_view name) {
  std::optional<CameraModelId> found;
  ForEachCameraModel([&](auto model) {
    if (decltype(model)::kName == name) found = decltype(model)::kId;
  });
  return found;
}

namespace {
using ColmapModels = CameraModelList<ColmapSimplePinholeModel,
                                     ColmapPinholeModel,
                                     ColmapSimpleRadialModel,
                                     ColmapRadialModel,
                                     ColmapOpenCvModel,
                                     ColmapFullOpenCvModel>;
}  // namespace

std::optional<CameraModelId> CameraModelFromColmapName(std::string_view colmap_name) {
  std::optional<CameraModelId> found;
  internal::ForEachIn(
      [&](auto model) {
        if (decltype(model)::kColmapName == colmap_name) found = decltype(model)::kId;
      },
      ColmapModels{});
  return found;
}

std::string_view ColmapName(CameraModelId id) {
  std::string_view name;
  internal::ForEachIn(
      [&](auto model) {
        if (decltype(model)::kId == id) name = decltype(model)::kColmapName;
      },
      ColmapModels{});
  return name;
}

std::string_view CameraModelName(CameraModelId id) {
  return VisitCameraModel(id, [](auto model) { return decltype(model)::kName; });
}

std::string CameraModelNames() {
  std::string names;
  ForEachCameraModel([&](auto model) {
    names += (names.empty() ? "" : ", ") + std::string(decltype(model)::kName);
  });
  return names;
}

std::string_view DefaultFreeInterior(CameraModelId id) {
  return VisitCameraModel(id, [](auto model) { return decltype(model)::kDefaultFree; });
}

namespace {
// Whether Model defines its distortion profile at a radius (RadialDistortionUm).
template <typename Model, typename = void>
struct HasRadiusProfile : std::false_type {};
template <typename Model>
struct HasRadiusProfile<Model, std::void_t<decltype(&Model::RadialDistortionUm)>> : std::true_type {
};
}  // namespace

std::optional<DistortionAtRadius> ModelDistortionAtRadius(CameraModelId id,
                                                          const double* params,
                                                          double r_mm) {
  return VisitCameraModel(id, [&](auto model) -> std::optional<DistortionAtRadius> {
    using Model = decltype(model);
    if constexpr (HasRadiusProfile<Model>::value)
      return DistortionAtRadius{Model::RadialDistortionUm(params, r_mm),
                                Model::DecentringDistortionUm(params, r_mm)};
    else
      return std::nullopt;
  });
}

bool HasDistortionAtRadius(CameraModelId id) {
  return VisitCameraModel(id, [](auto model) { return HasRadiusProfile<decltype(model)>::value; });
}

int CameraModelParamCount(CameraModelId id) {
  return VisitCameraModel(id, [](auto model) { return int(decltype(model)::kNumParams); });
}

std::vector<ParamInfo> CameraModelParams(CameraModelId id) {
  return VisitCameraModel(id, [](auto model) {
    const auto& table = decltype(model)::kParams;
    return std::vector<ParamInfo>(table.begin(), table.end());
  });
}

std::string JoinParamNames(const std::vector<ParamInfo>& table) {
  std::string names;
  for (const ParamInfo& info : table) names += (names.empty() ? "" : ", ") + std::string(info.name);
  return names;
}

bool ModelCamera::IdealFromPixel(const Eigen::Vector2d& pixel, Eigen::Vector2d* ideal_mm) const {
  AEROCAL_CHECK(static_cast<int>(params.size()) == CameraModelParamCount(model));
  const Eigen::Vector2d xy = frame.PhotoFromPixel(pixel);
  return VisitCameraModel(model, [&](auto m) {
    return decltype(m)::IdealFromMeasured(params.data(), frame, xy.data(), ideal_mm->data());
  });
}

bool ModelCamera::PixelFromIdeal(const Eigen::Vector2d& ideal_mm, Eigen::Vector2d* pixel) const {
  AEROCAL_CHECK(static_cast<int>(params.size()) == CameraModelParamCount(model));
  Eigen::Vector2d xy;
  const bool ok = VisitCameraModel(model, [&](auto m) {
    return decltype(m)::MeasuredFromIdeal(params.data(), frame, ideal_mm.data(), xy.data());
  });
  if (ok) *pixel = frame.PixelFromPhoto(xy);
  return ok;
}

double ModelCamera::PrincipalDistanceMm() const {
  return VisitCameraModel(
      model, [&](auto m) { return decltype(m)::PrincipalDistanceMm(params.data(), frame); });
}

}  // namespace aerocal::calib
