// What one image's metadata says (image_import.h lists the tags and their precedence): its
// position, GNSS sigmas, gimbal angles and camera evidence, each with the tag it came from.
#pragma once

#include "calib/core/error.h"
#include "calib/metadata/image_metadata.h"
#include "triangulation/import/image_import.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace aerocal::triangulation::internal {

struct ImageRecord {
  std::string image;
  std::optional<Eigen::Vector3d> lon_lat_alt;  // deg, deg, m
  std::string no_position;                     // why there is none ("" when there is)
  std::optional<Eigen::Vector3d> sigma_enu_m;  // RtkStdLon, RtkStdLat, RtkStdHgt
  std::optional<Eigen::Vector3d> gimbal_ypr_deg;
  // camera evidence
  std::string camera_key, make_model;
  int width_px = 0, height_px = 0;
  std::optional<double> focal_mm, focal_35mm, focal_plane_pixel_mm;
  std::string dewarp_data;  // "" when absent
  SourceRef dewarp_where;
  std::vector<UsedTag> tags;
};

/// The record of `meta` (read from `path`, named `image`). InputError for values that are present
/// and wrong (a number that is none, a latitude beyond 90, a GPS ref other than N/S/E/W, two
/// spellings of the longitude that differ).
ImageRecord ReadImageRecord(const calib::ImageMetadata& meta,
                            const std::string& path,
                            const std::string& image);

}  // namespace aerocal::triangulation::internal
