// Siemens stars: the contrast modulation per radius, turned into a frequency, and the limiting
// frequency at a stated modulation threshold (issue 36 item 2), as the star's "blur circle" is
// read in field resolution tests, but measured instead of judged by eye.
//
// A star of n cycles (n bright and n dark sectors) has, on the circle of radius r about its
// centre, the tangential frequency f = n / (2 pi r) cycles/px. On the ring of pixels whose centres
// lie within half a pixel of r, the linearised grey values v (DN^gamma) are fitted by least squares
// with v(theta) = m + a cos(n theta) + b sin(n theta): the fundamental's modulation is
// M1(r) = sqrt(a^2 + b^2) / m. A square-wave star of large-area modulation M0 = (B - D) / (B + D)
// has the fundamental 4 / pi M0 at frequencies the system passes unchanged, so the modulation
// transfer at f is CT(f) = M1 / (4 / pi M0): the system's MTF at f (averaged over the tangential
// directions round the circle), not Coltman's square-wave response of bar targets. Fitting the
// pixels where they are (no interpolation onto the circle) adds no interpolation blur. Stars with
// bright and dark sectors (painted field targets) only: a sinusoidal star has no large areas to
// normalise with.
//
// M0 is measured on the star's outermost ring: the means B and D of the middle third of every
// bright and every dark sector (their positions from the fitted fundamental's phase); this needs
// kMinSectorPx = 12 px or more per sector there (pi r_outer / n >= 12), so that the middle third
// lies 4 px or more from the sector's edges (4 sigma of a 1 px blur).
//
// Radii go from the outer radius inward in `steps_per_octave` geometric steps of the frequency
// until f reaches 0.5 cycles/px or the inner radius. The limiting frequency is where CT falls to
// the threshold: linear in log(frequency) between the last radius at or above it and the first
// below (as bar_target.h). ToGroundResolution (slanted_edge.h) gives lp/mm and the ground
// resolved distance.
#pragma once

#include "stitch/image_io/gray_image.h"

#include <Eigen/Core>

#include <vector>

namespace aerocal::stitch {

struct SiemensStar {
  Eigen::Vector2d centre_px = Eigen::Vector2d::Zero();  // (col, row), sub-pixel, pixel frame
  int cycles = 0;                // bright + dark sector pairs round the star, >= 4
  double outer_radius_px = 0.0;  // the largest radius measured (inside the star), px
  double inner_radius_px = 0.0;  // the smallest radius measured, px (>= 0; 0: down to f = 0.5)
};

/// Arc length of one sector on the outer ring below which M0 is not measured, px.
inline constexpr double kMinSectorPx = 12.0;

struct SiemensStarOptions {
  double gamma = 1.0;         // linearisation: value = DN^gamma, (0, 10]
  double threshold = 0.1;     // modulation transfer defining the limiting frequency, (0, 1)
  int steps_per_octave = 12;  // radii per halving of the radius, [2, 96]
  void Validate() const;      // throws ConfigError naming the field
};

struct StarRing {
  double radius_px = 0.0;
  double frequency_cy_px = 0.0;    // n / (2 pi r)
  double modulation = 0.0;         // M1: the fundamental's amplitude over the ring's mean
  double contrast_transfer = 0.0;  // M1 / (4 / pi M0)
  int pixels = 0;                  // pixels of the ring
};

struct SiemensStarResult {
  double reference_modulation = 0.0;  // M0 = (B - D) / (B + D) on the outermost ring
  double step_ratio = 0.0;            // frequency ratio of neighbouring rings, 2^(1/steps)
  std::vector<StarRing> rings;        // by increasing frequency (decreasing radius)
  // Frequency (cycles/px) where the contrast transfer falls to the threshold; NaN when already the
  // outermost ring is below it. When no ring falls below it, the highest ring's frequency with
  // limit_in_range = false (the limit lies beyond the measured radii).
  double limiting_frequency_cy_px = 0.0;
  bool limit_in_range = true;
};

/// Measures the star. InputError naming the star when it leaves the image, has fewer than 4
/// cycles, too few pixels per sector on its outer ring, or no contrast there.
SiemensStarResult MeasureSiemensStar(const GrayImage& image,
                                     const SiemensStar& star,
                                     const SiemensStarOptions& options = {});

}  // namespace aerocal::stitch
