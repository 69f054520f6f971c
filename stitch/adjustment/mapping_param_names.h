// Names of the plain mapping parameters in FORMATS.md order (for reports and JSON), indexed by
// model: translation [Tx, Ty]; conformal [a, b, Tx, Ty]; affine [a1, a2, a0, b1, b2, b0];
// projective [a1, a2, a3, b1, b2, b3, c1, c2].
#pragma once

#include "calib/camera/subimage_mapping.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

std::vector<std::string> MappingParamNames(calib::MappingModel model);

}  // namespace aerocal::stitch
