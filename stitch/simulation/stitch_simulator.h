// Simulated stitching measurements of a multi-CCD camera: for each frame (exposure), tie points in
// every overlap strip (each point measured in every sub-image that sees it) and the maker
// reference points, measured in sub-image pixels through the TRUE mappings plus Gaussian noise.
// Deterministic for a given seed. Also makes a "true" camera from a nominal one by small
// misplacements of the non-base sub-images.
#pragma once

#include "calib/camera/camera.h"

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace aerocal::stitch {

/// One row of stitch_obs.csv (FORMATS.md "Stitching measurements").
struct StitchObservation {
  std::string frame, point, subimage;
  double u = 0, v = 0;    // sub-image pixel
  double sigma_px = 0.1;  // a-priori sigma
  int line = 0;           // source line in stitch_obs.csv (0: not read from a file)
};

struct MisplacementOptions {
  double shift_sigma_px = 3.0;       // translation misplacement
  double rotation_sigma_rad = 1e-4;  // conformal rotation
  double scale_sigma = 1e-4;         // conformal scale - 1
  double shear = 0.0;                // affine part: x-scale minus y-scale and skew, each ~ this
};

/// The true camera: `nominal` with every non-base sub-image misplaced (random, seeded), mappings
/// kept in the nominal model's form (affine when shear != 0 and the model is lower).
calib::Camera MakeMisplacedCamera(const calib::Camera& nominal,
                                  const std::vector<std::string>& base_ids,
                                  const MisplacementOptions& options,
                                  std::mt19937_64& rng);

struct FrameSimulationOptions {
  int ties_per_frame = 900;          // spread over all overlap strips, proportional to strip area
  double noise_px = 0.1;             // matching noise, px (Gaussian, per coordinate)
  double sigma_px = 0.1;             // a-priori sigma written to the file
  double reference_noise_px = 0.05;  // measurement noise of reference points in sub-images
  double edge_margin_px = 5.0;       // ties stay this far inside every sub-image that sees them
};

/// Measurements of one frame seen by `truth`. Point ids: "t<k>" for ties, the reference point ids
/// for reference points.
std::vector<StitchObservation> SimulateFrame(const calib::Camera& truth,
                                             const std::string& frame,
                                             const FrameSimulationOptions& options,
                                             std::mt19937_64& rng);

/// Writes rows as stitch_obs.csv (header frame,point,subimage,u,v,sigma_px), atomically: u, v to
/// 1e-4 px and sigma_px to 4 digits, or with `exact` every number in the shortest text that reads
/// back to the same double (a file handed between processes that must agree to the last bit).
void WriteStitchObservations(const std::string& path,
                             const std::vector<StitchObservation>& rows,
                             bool exact = false);
/// Reads stitch_obs.csv; `default_sigma_px` where the column is missing or empty.
std::vector<StitchObservation> ReadStitchObservations(const std::string& path,
                                                      double default_sigma_px);

}  // namespace aerocal::stitch
