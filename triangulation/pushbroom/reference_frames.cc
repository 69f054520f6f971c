#include "triangulation/pushbroom/reference_frames.h"

#include "calib/core/error.h"
#include "calib/core/result_file.h"

#include <cmath>

namespace aerocal::triangulation {

std::vector<Exposure> ReadAdjustedExposures(const std::string& result_path, int* skipped) {
  const nlohmann::json doc = ReadResult(result_path, {"adjust"}, "`aerocal adjust`");
  if (doc.contains("valid") && doc["valid"].is_boolean() && !doc["valid"].get<bool>())
    throw InputError(result_path +
                     ": the block adjustment is not valid (valid: false): its "
                     "orientations cannot serve as the reference");
  if (!doc.contains("exposures") || !doc["exposures"].is_array())
    throw InputError(result_path + ": no exposures array");
  constexpr double kDegToRad = M_PI / 180.0;
  std::vector<Exposure> out;
  *skipped = 0;
  const auto& list = doc["exposures"];
  for (size_t k = 0; k < list.size(); ++k) {
    const auto& x = list[k];
    const std::string where = result_path + ": exposures[" + std::to_string(k) + "]";
    if (!x.is_object()) throw InputError(where + ": not an object");
    if (x.contains("used") && x["used"].is_boolean() && !x["used"].get<bool>()) {
      ++*skipped;
      continue;
    }
    if (!x.contains("image") || !x["image"].is_string() || x["image"].get<std::string>().empty())
      throw InputError(where + ": image must be a non-empty string");
    auto number = [&](const char* key) {
      if (!x.contains(key) || !x[key].is_number() || !std::isfinite(x[key].get<double>()))
        throw InputError(where + " (" + x["image"].get<std::string>() + "): " + key +
                         " must be a finite number");
      return x[key].get<double>();
    };
    Exposure e;
    e.image = x["image"].get<std::string>();
    e.center_m = Eigen::Vector3d(number("X"), number("Y"), number("Z"));
    e.opk_rad = Eigen::Vector3d(number("omega"), number("phi"), number("kappa")) * kDegToRad;
    e.line = int(k) + 1;
    out.push_back(e);
  }
  if (out.empty()) throw InputError(result_path + ": no used exposure (nothing is oriented)");
  return out;
}

}  // namespace aerocal::triangulation
