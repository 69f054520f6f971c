// Importer of a COLMAP text model (cameras.txt, images.txt, points3D.txt) into a block
// (FORMATS.md "Imports"). Conventions converted here, in one place (CONVENTIONS.md):
// - Pixels: COLMAP puts the centre of the top-left pixel at (0.5, 0.5): col = x - 0.5.
// - Camera frame: COLMAP x right, y down, z forward (x_cam = R X + t); aerocal's image space is
//   (U, V, W) = (x, -y, -z), so object_from_image = R^T diag(1, -1, -1), centre = -R^T t.
// - Intrinsics: the camera is read into the registry's COLMAP model (calib/camera/models/colmap.h:
//   SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV as exact subsets of the
//   OpenCV model, COLMAP's pixel origin converted there) and converted into the 10-parameter model
//   by calib::ConvertCamera: exact without distortion (c = fy p, x0 = (cx - W/2) p,
//   y0 = -(cy - H/2) p, B1 = fy / fx - 1), otherwise a least-squares fit of all ten parameters
//   over the format (COLMAP's distortion is FORWARD, ours a correction); the note per camera gives
//   the residual RMS and max in pixels.
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
  /// CRS of a georeferenced model (model_aligner: ECEF "EPSG:4978", or a projected CRS); the
  /// project gets frame: {crs: ...} and attitudes are relative to that CRS's axes. A geographic
  /// CRS is refused (a COLMAP model is Cartesian). Empty: the model frame as given.
  std::string crs;
};

struct ColmapImportReport {
  Project project;
  std::vector<std::string> notes;  // one per camera: model and conversion residual RMS / max (px)
};

ColmapImportReport ImportColmapModel(const ColmapImportOptions& options);

/// COLMAP's projection of a point in COLMAP camera coordinates to COLMAP pixels (x, y), for the
/// supported models with their params; the round-trip tests compare it with aerocal's camera.
Eigen::Vector2d ColmapProject(const std::string& model,
                              const std::vector<double>& params,
                              const Eigen::Vector3d& point_in_camera);

}  // namespace aerocal::triangulation
