// The images of one rig exposure -> the single-centre virtual image (`aerocal rig convert`), by
// inverse mapping through stitch/resample (ResampleVirtualImage: strips, bilinear/bicubic,
// overlaps averaged, uncovered pixels filled, 8/16 bit, 1 or 3 bands).
//
// Over the rectification plane, virtual pixel -> head pixel is the plane-induced homography
//   head ~ K_k R_k^T [ (O - O_k) n^T + h I ] R_v A_v [U V 1]^T,   h = offset - n . O
// (A_v: virtual pixel -> virtual ray, K_k: head ray -> measured pixel). It is exact for heads
// without lens distortion, so each head enters the resampler as a projective sub-image mapping
// (head pixel -> virtual pixel); a head with distortion terms is refused by name (its per-pixel
// map is not a homography; follow-up of issue 13).
#pragma once

#include <vector>

#include <Eigen/Core>

#include "calib/camera/camera.h"
#include "calib/camera/rig.h"
#include "stitch/resample/raster.h"
#include "stitch/resample/virtual_image.h"
#include "stitch/rig/rig_conversion.h"

namespace aerocal::stitch {

/// Homography (virtual pixel -> measured pixel of head k) of the converter's exposure and plane,
/// ignoring the head's distortion terms (exact when they are zero).
Eigen::Matrix3d HeadFromVirtualHomography(const RigConverter& converter, int head);

/// The rig exposure as a multi-CCD camera for ResampleVirtualImage: the virtual format, one
/// projective sub-image per head (id, format, head pixel -> virtual pixel). InputError naming the
/// head when it has distortion terms or its homography degenerates.
calib::Camera RigExposureAsSubimageCamera(const RigConverter& converter);

/// Converts the head images (`sources`, one per head, rig order) to the virtual image in `sink`.
ResampleReport ConvertRigExposure(const RigConverter& converter,
                                  const std::vector<RasterSource*>& sources, RasterSink* sink,
                                  const ResampleOptions& options);

}  // namespace aerocal::stitch
