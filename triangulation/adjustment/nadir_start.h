// Starting exterior orientation of near-nadir images from their control points: a 2D similarity
// between photo coordinates and ground (X, Y). For omega = phi = 0, R = Rz(kappa) and
//   [X Y] - [X0 Y0] = lambda Rz(kappa) [xb yb],  lambda = (Z0 - Z) / c,
// so a complex least-squares fit  g = a p + t  (g = X + iY, p = xb + i yb) gives kappa = arg a,
// Z0 = mean(Z) + |a| c and (X0, Y0) = t. The worst point is dropped while its residual exceeds
// five times the median (gross errors), keeping at least three points.
#pragma once

#include "triangulation/block/block.h"

#include <vector>

namespace aerocal::triangulation {

/// One exposure per image of `project.observations` that sees >= 2 points with coordinates
/// (control or check survey); `camera` is used for every image. InputError when an image
/// sees fewer than two.
std::vector<Exposure> NadirStartFromControl(const Project& project, const std::string& camera);

}  // namespace aerocal::triangulation
