// `quality mtf --targets`: the edge regions of one image found from the edge targets' ground ends
// (targets.csv, docs/formats.md "Edge target patches") and the adjusted orientation of the image
// (an adjust or flight result.json and the camera file), rather than given with --roi.
//
// Each edge is projected with stitch::RegionOfEdgeTarget (collinearity and the camera's
// distortion, in the virtual image's pixels); the image file may be a window of that image whose
// top-left pixel is `origin_px` (the simulator's patch mosaics), so a region is shifted by
// -origin_px and must lie inside the file. Targets outside the image or too near its border are
// skipped and counted by name, never measured on the wrong pixels.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/quality/edge_targets.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::tools {

/// targets.csv: `id,start_x,start_y,start_z,end_x,end_y,end_z` (m, object frame), '#' comments;
/// InputError FILE:LINE for a missing column, a value that is not a finite number, an empty or
/// repeated id, or an edge of zero length.
std::vector<stitch::EdgeTarget> ReadEdgeTargets(const std::string& path);

struct ExposureOrientation {
  Eigen::Vector3d opk_rad = Eigen::Vector3d::Zero();
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  std::string adjustment;  // which adjustment of a flight result it came from ("" in an adjust's)
};

/// The exterior orientation of `image` in an adjust result (its `exposures`) or a flight result
/// (the exposures of the adjustment `camera_written_from.adjustment` names, else of the last
/// adjustment that has exposures). InputError naming the file for another kind of file and for an
/// image it does not hold.
ExposureOrientation ReadExposureOrientation(const std::string& result_path,
                                            const std::string& image);

struct FoundEdgeRegion {
  stitch::EdgeTargetRegion target;      // projected in the full image (virtual, or the sub-image)
  stitch::EdgeTargetRegion in_virtual;  // the same edge in the virtual image (= target there)
  stitch::PixelRegion region;           // in the file's pixels (shifted by -origin)
  double projected_offset_px = 0.0;     // the projected edge across `region` at its middle line
};

struct FoundEdgeRegions {
  std::vector<FoundEdgeRegion> found;
  std::vector<std::pair<std::string, std::string>> skipped;  // target id, reason
};

/// The regions of `targets` (all when `only` is empty, else those named; an unknown name is a
/// ConfigError naming --target) in an image file of `file_cols` x `file_rows` px whose top-left
/// pixel is `origin_px` in the camera's (virtual) image, or with `subimage` in that raw sub-image:
/// the edge's ends projected into the virtual image are mapped by SubFromVirtual (a projectivity
/// keeps the edge straight) and the region is built there; a target whose region leaves the
/// sub-image is skipped ("not in sub-image ID: ...").
FoundEdgeRegions FindEdgeRegions(const calib::Camera& camera,
                                 const ExposureOrientation& orientation,
                                 const std::vector<stitch::EdgeTarget>& targets,
                                 const std::vector<std::string>& only,
                                 const Eigen::Vector2i& origin_px,
                                 int file_cols,
                                 int file_rows,
                                 const stitch::EdgeTargetRegionOptions& options,
                                 const calib::SubimageMapping* subimage = nullptr);

/// The camera with the mappings of `path`: a stitch result (`aerocal stitch`, as `resample
/// --mapping` reads it) or a flight result, whose `stitching` is one; those of frame `frame`, or
/// the top level's (the flight's mean) when empty. InputError naming the file when it does not
/// match the camera (a sub-image missing on either side, a frame it lacks).
calib::Camera CameraWithMappings(const calib::Camera& camera,
                                 const std::string& path,
                                 const std::string& frame);

}  // namespace aerocal::tools
