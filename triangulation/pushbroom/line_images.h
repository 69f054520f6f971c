// Image mode of `aerocal simulate --pushbroom --render-images` (issue 17, module README "Image
// mode"): the scene of the simulated flight (line_simulation.h: its terrain) textured with a real
// photograph, rendered
// - through the TRUE line camera and the TRUE per-line poses into the line image (row r = scan
//   line r, column = detector; pixel centres at integer positions), and
// - through a distortion-free frame camera into reference frame images of one strip along the
//   flight (forward overlap `forward_overlap`), whose orientation (exposures.csv, the camera file)
//   stands for the block result of `aerocal adjust` (here: exact).
// The texture: the photograph averaged over 2 x 2 pixels, laid on the ground centred on the swath
// with `texture_gsd_m` per texel (default: half the finer of the two images' ground sampling) and
// mirrored beyond its edges; grey values bilinear in the texture, plus Gaussian grey-value noise.
#pragma once

#include "calib/camera/camera.h"
#include "stitch/image_io/gray_image.h"
#include "triangulation/block/block.h"
#include "triangulation/pushbroom/line_simulation.h"

#include <cstdint>
#include <string>
#include <vector>

namespace aerocal::triangulation {

/// Bounds of the rendered sizes (issue 37 class 7), checked before anything is allocated: a
/// reference frame (two double grids of its format while rendered) and the line image (two
/// double grids of lines x all detectors).
inline constexpr double kMaxReferencePixels = 2.5e7;
inline constexpr double kMaxLineImagePixels = 5e7;

struct LineImageOptions {
  std::string texture_path;       // the photograph (any format ReadGrayImage reads), required
  double texture_gsd_m = 0.0;     // ground size of a texel (2 x 2 photo pixels); 0: automatic
  int reference_width_px = 2000;  // frame image format, 100 .. 20000, at most kMaxReferencePixels
  int reference_height_px = 1500;
  double reference_pixel_mm = 0.006;  // > 0
  double reference_gsd_m = 0.0;       // nadir ground sampling of the frames; 0: 0.6 x line spacing
  double forward_overlap = 0.6;       // of the reference strip, 0.5 .. 0.9
  double grey_noise_dn = 1.0;         // Gaussian noise added to every rendered grey value, >= 0
  std::uint64_t seed = 1;
  void Validate() const;  // ConfigError naming the option
};

struct LineImageSimulation {
  stitch::GrayImage line_image;  // rows = scan lines, columns = detectors
  calib::Camera reference_camera;
  std::vector<Exposure> reference_exposures;
  std::vector<stitch::GrayImage> reference_images;  // one per exposure
  double mean_height_m = 0.0;                       // mean terrain height under the swath
  double texture_gsd_m = 0.0;
};

LineImageSimulation RenderLineImages(const LineSimulation& simulation,
                                     const LineSimulationOptions& options,
                                     const LineImageOptions& image_options);

/// Writes line_image.png and reference/{camera.yaml, exposures.csv, <image>.png} into `folder`.
void WriteLineImages(const LineImageSimulation& images, const std::string& folder);

}  // namespace aerocal::triangulation
