// The tie points of a COLMAP reconstruction added to a block imported from a flight's images
// (`aerocal import images DIR --match colmap`, issue 34 item 3: matching after the import, so that
// the adjustment can follow).
//
// COLMAP's model frame is arbitrary; its model_aligner maps it (a similarity, RANSAC) onto the
// images' GNSS centres given in ECEF (EcefCentres), and `import colmap --crs EPSG:4978` reads that
// model. AddColmapTies then keeps the exposures and cameras of the image import (GNSS centres and
// their sigmas, gimbal attitudes, the EXIF / DewarpData camera) and takes from the model only what
// matching found: the image observations (pixels of the same files, already in aerocal's pixel
// convention) and the tie points, whose coordinates (approximations for the adjustment) are
// converted by PROJ from ECEF into the project's CRS. COLMAP's poses and camera are not used: the
// adjustment re-estimates everything from the observations, the GNSS priors and our camera model.
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

/// The exposures' centres in ECEF (EPSG:4978, m) through PROJ, by image file name: the reference
/// positions for COLMAP's model_aligner. `images` is a crs: project (ImportImages).
std::vector<std::pair<std::string, Eigen::Vector3d>> EcefCentres(const Project& images);

struct ColmapTiesReport {
  Project project;
  std::vector<std::string> notes;  // images COLMAP did not register, points left with one ray
};

/// `images` (ImportImages) with the observations and tie points of `model` (ImportColmapModel of
/// the aligned model with crs EPSG:4978). A model image is matched to an exposure by its file name
/// (the model's ids are the names' stems). InputError when an image's size in the model is not
/// its camera's, or when the model has no image of the import; images without observations are
/// left out (UsableImportedBlock), a point with one remaining ray is dropped.
ColmapTiesReport AddColmapTies(const Project& images, const Project& model);

}  // namespace aerocal::triangulation
