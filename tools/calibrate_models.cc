#include "tools/calibrate_models.h"

#include "calib/camera/convert_camera.h"
#include "calib/core/error.h"
#include "calib/core/finding.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace aerocal::tools {

double RmsPx(const triangulation::AdjustmentResult& r) {
  double sum2 = 0;
  int n = 0;
  for (const auto& o : r.residuals)
    if (o.used) {
      sum2 += o.residual_px.squaredNorm();
      ++n;
    }
  return n > 0 ? std::sqrt(sum2 / n) : 0.0;
}

calib::CameraModelId ModelOfOption(const std::string& name) {
  const auto model = calib::CameraModelFromName(name == "brown10" ? "brown_fraser_10" : name);
  if (!model)
    throw ConfigError("--model: unknown camera model '" + name + "' (expected brown10, " +
                      calib::CameraModelNames() + ")");
  return *model;
}

std::string DefaultSelfCalibration(calib::CameraModelId model) {
  return std::string(calib::DefaultFreeInterior(model));  // the model struct's kDefaultFree
}

calib::Camera StartInModel(const calib::Camera& camera,
                           calib::CameraModelId model,
                           const std::vector<std::string>& free) {
  calib::ConvertOptions convert;
  for (const calib::ParamInfo& info : calib::CameraModelParams(model))
    if (std::find(free.begin(), free.end(), info.name) == free.end())
      if (info.group != calib::ParamGroup::kPrincipalDistance &&
          info.group != calib::ParamGroup::kPrincipalPoint)
        convert.zero.emplace_back(info.name);
  const calib::ConversionResult start =
      calib::ConvertCamera(camera.AsModelCamera(), model, convert);
  std::printf("start: the camera file's %s camera as %s: %s\n",
              std::string(calib::CameraModelName(camera.model)).c_str(),
              std::string(calib::CameraModelName(model)).c_str(),
              start.Summary().c_str());
  return camera.WithModelCamera(start.camera);
}

void AddStabilityWarnings(const triangulation::StabilityReport& stability, nlohmann::json* json) {
  for (const auto& f : stability.flagged) {
    std::printf("warning: group_stability: %s\n", f.c_str());
    (*json)["warnings"].push_back(
        FindingToJson({"group_stability", f.substr(0, f.find(':')), NAN, NAN, f}));
  }
}

std::vector<double> DefaultCertifiedRadiiMm(const calib::Camera& camera) {
  const double half_diagonal =
      0.5 * camera.pixel_size_mm * std::hypot(camera.width_px, camera.height_px);
  std::vector<double> radii;
  for (int i = 1; i <= 4; ++i) radii.push_back(std::round(half_diagonal * i / 4 * 10) / 10);
  return radii;
}

}  // namespace aerocal::tools
