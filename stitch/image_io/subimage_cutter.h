// Cuts a (virtual) frame image into the sub-images of a multi-CCD camera: sub-image pixel (u, v)
// gets the grey value of the frame at VirtualFromSub(u, v) of the given (true) mappings, bicubic
// (OpenCV warpAffine / warpPerspective, which place the sample with 1/32 px fixed-point steps),
// then a per-sub-image radiometric gain and offset, then Gaussian sensor noise (seeded). This turns
// one real photograph into a multi-CCD frame with a known geometric truth.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/image_io/gray_image.h"

#include <cstdint>
#include <vector>

namespace aerocal::stitch {

struct CutOptions {
  std::vector<double> gains;    // per sub-image, multiplies grey values (empty: all 1)
  std::vector<double> offsets;  // per sub-image, added after the gain, DN (empty: all 0)
  double noise_dn = 0.0;        // sensor noise standard deviation, DN, >= 0
  std::uint64_t seed = 1;       // noise seed; the same seed gives the same images
};

/// One image per sub-image of `camera`, in camera order, of that sub-image's format.
std::vector<GrayImage> CutSubimages(const GrayImage& frame,
                                    const calib::Camera& camera,
                                    const CutOptions& options);

}  // namespace aerocal::stitch
