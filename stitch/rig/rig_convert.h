// The images of one rig exposure -> the single-centre virtual image (`aerocal rig convert`), by
// inverse mapping through stitch/resample (ResampleVirtualImage: strips, bilinear/bicubic,
// overlaps averaged, uncovered pixels filled, 8/16 bit, 1 or 3 bands).
//
// Over the rectification plane, virtual pixel -> head pixel is the plane-induced homography
//   head ~ K_k R_k^T [ (O - O_k) n^T + h I ] R_v A_v [U V 1]^T,   h = offset - n . O
// (A_v: virtual pixel -> virtual ray, K_k: head ray -> measured pixel, both the pinhole parts: c
// and principal point). It is exact for heads and a virtual camera without lens distortion. A
// head with distortion terms, or any head when the virtual camera has them, enters the resampler
// with the same homography plus a correction grid (resample/virtual_image.h MapCorrectionGrid): at
// grid nodes the exact head pixel (the virtual camera's and the head's models,
// RigConverter::HeadFromVirtual) minus the homography's; the step is halved from 64 px until the
// bilinear interpolation of the grid reproduces the exact map at every cell centre inside the head
// to `tolerance_px` (or the step reaches 2 px; the error reached is reported).
#pragma once

#include "calib/camera/camera.h"
#include "calib/camera/rig.h"
#include "stitch/resample/raster.h"
#include "stitch/resample/virtual_image.h"
#include "stitch/rig/dem_grid.h"
#include "stitch/rig/rig_conversion.h"

#include <Eigen/Core>

#include <vector>

namespace aerocal::stitch {

/// Homography (virtual pixel -> measured pixel of head k) of the converter's exposure and plane,
/// ignoring the head's and the virtual camera's distortion terms (exact when they are zero).
Eigen::Matrix3d HeadFromVirtualHomography(const RigConverter& converter, int head);

/// The rig exposure as a multi-CCD camera for ResampleVirtualImage: the virtual camera (model,
/// interior, format), one projective sub-image per head (id, format, head pixel -> virtual pixel,
/// distortion ignored).
/// InputError naming the head when its homography degenerates.
calib::Camera RigExposureAsSubimageCamera(const RigConverter& converter);

/// Correction grids of every head (step 0 for a head without distortion terms under a virtual
/// camera without them) and the largest
/// interpolation error of the grids against the exact map (px) at their cell centres inside the
/// head formats.
struct HeadMapCorrections {
  std::vector<MapCorrectionGrid> grids;
  double max_error_px = 0.0;
  int finest_step_px = 0;  // 0: no head needed a grid
};
/// With `dem`, the exact map intersects the virtual ray with the DEM (IntersectDem) instead of the
/// plane, and every head gets a grid (the homography of the converter's plane stays the base:
/// choose the plane near the DEM's mean height). Virtual pixels whose ray misses the DEM keep the
/// plane's map.
HeadMapCorrections MakeHeadMapCorrections(const RigConverter& converter,
                                          double tolerance_px = 0.01,
                                          const DemGrid* dem = nullptr);

/// Converts the head images (`sources`, one per head, rig order) to the virtual image in `sink`.
/// Heads with distortion, every head under a virtual camera with distortion and every head over a
/// DEM go through MakeHeadMapCorrections (its
/// report in `corrections` when given).
ResampleReport ConvertRigExposure(const RigConverter& converter,
                                  const std::vector<RasterSource*>& sources,
                                  RasterSink* sink,
                                  const ResampleOptions& options,
                                  HeadMapCorrections* corrections = nullptr,
                                  const DemGrid* dem = nullptr);

}  // namespace aerocal::stitch
