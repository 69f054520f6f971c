// `quality mtf --targets --sub-image ID --mapping STITCH.json [--virtual-image FILE]`: an edge
// target measured in a raw sub-image, set against the same edge in the virtual image resampled
// from it (issue 36 item 3, "the loss due to resampling stated" per edge).
//
// Per edge: the virtual region's pixels mapped into the sub-image (SubFromVirtual) give the
// sub-pixel shifts bilinear interpolation weighs by; the predicted virtual MTF50 is the raw MTF
// times bilinear interpolation's transfer at those shifts
// (stitch::PredictResampledMtf50AtShifts, stitch/quality/README.md "Resampling"), and at phases
// spread uniformly over the pixel (sinc^2 per axis, stitch::PredictResampledMtf50) for comparison.
// With the virtual image's file the same edge is measured there too: the measured loss
// raw - virtual with U = 2 sqrt(u_raw^2 + u_virtual^2), and measured - predicted with the same U
// (the prediction carries the raw edge's u, to first order one for one).
#pragma once

#include "calib/camera/camera.h"
#include "stitch/image_io/gray_image.h"
#include "stitch/quality/slanted_edge.h"
#include "tools/edge_target_regions.h"

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include <string>

namespace aerocal::tools {

/// The virtual image's file to measure the same edges in (`--virtual-image`, `--virtual-origin`):
/// a window of the virtual image whose top-left pixel is `origin_px`; `image` null when not given.
struct VirtualWindow {
  const stitch::GrayImage* image = nullptr;
  std::string path;
  Eigen::Vector2i origin_px = Eigen::Vector2i::Zero();
};

/// The `resampling` block of an edge `raw` measured in raw sub-image `sub` at `found` (keys in
/// stitch/quality/README.md; a value not determined is null).
nlohmann::json ResamplingComparisonJson(const stitch::SlantedEdgeResult& raw,
                                        const FoundEdgeRegion& found,
                                        const calib::SubimageMapping& sub,
                                        const VirtualWindow& window,
                                        const stitch::SlantedEdgeOptions& options);

/// The centre of `region` (px of one image) as [col, row]: where the map of MTF50 across the
/// format draws an edge (`position_virtual_px`).
nlohmann::json RegionCentreJson(const stitch::PixelRegion& region,
                                const Eigen::Vector2i& origin_px);

}  // namespace aerocal::tools
