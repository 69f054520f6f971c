// Importer of a COLMAP text model (cameras.txt, images.txt, points3D.txt) into a block
// (FORMATS.md "Imports"). Conventions converted here, in one place (CONVENTIONS.md):
// - Pixels: COLMAP puts the centre of the top-left pixel at (0.5, 0.5): col = x - 0.5.
// - Camera frame: COLMAP x right, y down, z forward (x_cam = R X + t); aerocal's image space is
//   (U, V, W) = (x, -y, -z), so object_from_image = R^T diag(1, -1, -1), centre = -R^T t.
// - Intrinsics: c = f * pixel_size (fy for two focal lengths), x0 = (cx - W/2) p,
//   y0 = -(cy - H/2) p. COLMAP's distortion is a FORWARD model (ideal -> distorted) while the
//   10-parameter model corrects measured coordinates; K1, K2, K3, P1, P2, B1 are fitted by linear
//   least squares on a dense grid over the format (the fit RMS in pixels is reported), B1 takes
//   fy / fx - 1. Models: SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV.
// - Points3D become tie points with their coordinates as approximations; COLMAP's frame is kept
//   (a similarity of the world unless the model was georeferenced), so the adjustment defines a
//   free-network datum.
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <string>
#include <vector>

namespace aerocal::triangulation {

struct ColmapImportOptions {
  std::string folder;            // holding cameras.txt, images.txt, points3D.txt
  double pixel_size_mm = 0.001;  // COLMAP has no pixel size; any value gives the same geometry
  double sigma_px = 1.0;         // a-priori sigma of the image measurements, > 0
};

struct ColmapImportReport {
  Project project;
  std::vector<std::string> notes;  // one per camera: model and distortion-fit RMS (px)
};

ColmapImportReport ImportColmapModel(const ColmapImportOptions& options);

/// COLMAP's projection of a point in COLMAP camera coordinates to COLMAP pixels (x, y), for the
/// supported models with their params; the round-trip tests compare it with aerocal's camera.
Eigen::Vector2d ColmapProject(const std::string& model,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& point_in_camera);

}  // namespace aerocal::triangulation
