// Nominal multi-CCD cameras with a rows x cols grid of sub-images (inner-FOV optical splitting):
// equal sub-images, neighbours overlapping by a given strip width, each sub-image mapped onto the
// virtual focal plane by a pure shift (the nominal mapping, in the chosen model's parameter form).
// Sub-image ids are Roman numerals I, II, III, ... row by row from the top left.
#pragma once

#include "calib/camera/camera.h"

#include <string>
#include <vector>

namespace aerocal::stitch {

enum class ReferencePlacement {
  kBaseCorners,   // four points near the corners of every base sub-image
  kOuterCorners,  // points near the outer corners of the virtual format, on the sub-images there
};

struct GridLayoutOptions {
  std::string name = "grid camera";
  int rows = 3, cols = 2;  // sub-image grid
  int virtual_width_px = 14000, virtual_height_px = 12000;
  int overlap_px = 200;  // overlap strip width between neighbours, px
  double pixel_size_mm = 0.009;
  double c_mm = 170.0;
  calib::MappingModel model = calib::MappingModel::kAffine;
  std::vector<std::string> base_ids;  // sub-images sitting on the focal plane (datum)
  ReferencePlacement reference_placement = ReferencePlacement::kBaseCorners;
  double reference_inset_px = 30.0;  // distance of reference points from the edges
  double reference_sigma_px = 0.05;
};

/// Roman numeral of 1-based n ("I", "II", ..., "XII", ...).
std::string RomanNumeral(int n);

/// Builds the nominal camera: sub-image formats, shift-only mappings and reference points whose
/// (u, v) and (U, V) agree under the nominal mapping. Throws ConfigError for impossible layouts.
calib::Camera MakeGridCamera(const GridLayoutOptions& options);

}  // namespace aerocal::stitch
