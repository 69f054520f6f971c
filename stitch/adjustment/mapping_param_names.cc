#include "stitch/adjustment/mapping_param_names.h"

#include <array>

namespace aerocal::stitch {

std::vector<std::string> MappingParamNames(calib::MappingModel model) {
  // Indexed by the model's frozen enum value (subimage_mapping.h).
  static const std::array<std::vector<std::string>, 4> kNames = {{
      {"Tx", "Ty"},
      {"a", "b", "Tx", "Ty"},
      {"a1", "a2", "a0", "b1", "b2", "b0"},
      {"a1", "a2", "a3", "b1", "b2", "b3", "c1", "c2"},
  }};
  return kNames.at(static_cast<size_t>(model));
}

}  // namespace aerocal::stitch
