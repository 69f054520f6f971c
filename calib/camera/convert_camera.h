// ConvertCamera: a camera of one registered model (camera_model.h) expressed in another.
// - Exact (closed form) where the models are equivalent: every model maps to and from OpenCV's
//   12 parameters and says whether that mapping is exact (COLMAP's models, OpenCV, Metashape
//   without b2/k4/p3/p4, Pix4D with fx = fy; ours only without distortion). Exact means the
//   mapping is algebraic; the residual over the format is still measured and reported.
// - Otherwise the target's parameters are fitted by least squares over a dense grid of the format
//   through ProblemBuilder: per grid pixel the source's ideal ray; the residual in the target's
//   closed-form direction (measured px for forward models, ideal px for our correction form),
//   whitened with 1 px. Starting values: the pinhole part of the closed-form mapping.
// Either way the result carries the residual over a (denser) check grid: the measured-pixel
// difference of the same rays, RMS, max and where it is, and the max within 80 % of the
// half-diagonal. A fit that leaves more than ConvertOptions::max_residual_px is not `acceptable`.
#pragma once

#include "calib/camera/camera_model.h"

#include <Eigen/Core>

#include <limits>
#include <string>
#include <vector>

namespace aerocal::calib {

struct ConvertOptions {
  int fit_grid = 41;     // fit points per format side (>= 5)
  int check_grid = 101;  // residual points per format side (>= 2)
  /// Target parameters (table names) held at their starting values in a fit.
  std::vector<std::string> fixed;
  /// Target parameters the caller's file format cannot hold: set to 0 and held there (a closed
  /// form that gives one of them a non-zero value is then not exact and the rest is fitted).
  std::vector<std::string> zero;
  double max_residual_px = std::numeric_limits<double>::infinity();
};

struct ConversionResidual {
  int points = 0;
  int failed_points = 0;  // where a model's inversion did not converge (counted, not hidden)
  double rms_px = 0.0;
  double max_px = 0.0;
  Eigen::Vector2d max_at_px{0.0, 0.0};  // pixel (col, row) of the max
  double max_inner80_px = 0.0;          // within 80 % of the half-diagonal from the format centre
};

struct ConversionResult {
  ModelCamera camera;
  bool exact = false;
  bool acceptable = false;  // residual.max_px <= max_residual_px and no failed points
  ConversionResidual residual;
  int fit_iterations = 0;  // 0 for an exact conversion
  std::string Summary() const;
};

/// `from` expressed in model `to` over the same format.
ConversionResult ConvertCamera(const ModelCamera& from,
                               CameraModelId to,
                               const ConvertOptions& options = {});

/// n x n pixel centres over the format, corners included, row by row.
std::vector<Eigen::Vector2d> FormatGrid(const PixelFrame& frame, int n);

/// The measured-pixel difference between two cameras of the same format over a grid x grid of
/// pixels: per pixel, a's ideal ray re-imaged by b.
ConversionResidual CompareCameras(const ModelCamera& a, const ModelCamera& b, int grid);

}  // namespace aerocal::calib
