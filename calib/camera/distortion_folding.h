// Where a camera's distortion folds (issue 37 class 6): along a ray from the principal point, the
// ideal radius must grow with the measured radius (and back); where it stops growing, two measured
// points share one ideal direction and the model is no lens any more. A lens whose distortion folds
// INSIDE its format gives `camera show` a jumping table and the adjustment a camera that maps two
// image points to one ray: the commands warn (or refuse) with the radius.
//
// Model-generic: sampled through ModelCamera::IdealFromPixel / PixelFromIdeal (every registered
// model), in 16 directions, at steps of 1/2000 of the format's half diagonal up to 1.5 times it.
#pragma once

#include "calib/camera/camera_model.h"

#include <optional>

namespace aerocal::calib {

struct DistortionFolding {
  /// Smallest measured radius (mm from the principal point, photo frame) at which the ideal radius
  /// stops growing or the model cannot be inverted; nullopt when none up to 1.5 half diagonals.
  std::optional<double> radius_mm;
  double direction_deg = 0;     // direction of that radius (photo frame, from +x towards +y)
  double half_diagonal_mm = 0;  // of the format, from the format centre
  bool inside_format = false;   // the folding point lies inside the image format
};

/// The folding radius of `camera` (its format must be positive: LogicError otherwise).
DistortionFolding FindDistortionFolding(const ModelCamera& camera);

/// "the distortion folds at r = 21.3 mm (direction 45 deg), inside the format (half diagonal
/// 24.6 mm): ..." or "" when it does not fold inside the format. The one-line warning of
/// `camera show` and the readers' callers.
std::string DistortionFoldingWarning(const DistortionFolding& folding);

}  // namespace aerocal::calib
