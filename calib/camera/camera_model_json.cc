#include "calib/camera/camera_model_json.h"

#include <string>

namespace aerocal::calib {

nlohmann::json CameraModelTableToJson(CameraModelId model) {
  nlohmann::json parameters = nlohmann::json::array();
  for (const ParamInfo& p : CameraModelParams(model))
    parameters.push_back({{"name", std::string(p.name)},
                          {"unit", std::string(p.unit)},
                          {"group", std::string(ParamGroupName(p.group))}});
  return {{"name", std::string(CameraModelName(model))},
          {"id", static_cast<int>(model)},
          {"parameters", parameters}};
}

}  // namespace aerocal::calib
