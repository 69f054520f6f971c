// A real photograph laid on the ground as the texture of a simulated scene (the image modes of
// `aerocal simulate`: `--pushbroom --render-images`, pushbroom/line_images.h, and `--rig uav4
// --render-images`, rig_flight_simulator.h). The photograph is averaged over 2 x 2 pixels; texel
// (u, v) lies at X = x_c + (u - W/2) gsd, Y = y_c - (v - H/2) gsd (object frame, m; W x H texels),
// mirrored beyond the edges so that any ground position has a grey value; grey values are bilinear
// in the texels (digital numbers of the photograph).
#pragma once

#include "stitch/image_io/gray_image.h"

#include <string>

namespace aerocal::triangulation {

struct TexturedGround {
  stitch::GrayImage texels;  // the photograph averaged over 2 x 2 pixels
  double x_c = 0, y_c = 0;   // object position of the texture centre, m
  double gsd_m = 1;          // ground size of a texel, m, > 0
  /// Position u in 0 .. n-1 mirrored at the edges (period 2 (n - 1)).
  static double Mirror(double u, int n);
  /// Bilinear grey value at the ground position (x, y), m.
  float At(double x, double y) const;
};

/// The photograph averaged over 2 x 2 pixels (odd last row/column dropped).
stitch::GrayImage AverageTwoByTwo(const stitch::GrayImage& photo);

/// Reads the photograph (any format ReadGrayImage reads) into `ground->texels`, averaged over 2 x 2
/// pixels; InputError naming the file when it is smaller than 32 x 32 px. Centre and GSD are the
/// caller's.
void ReadGroundTexture(const std::string& photo_path, TexturedGround* ground);

}  // namespace aerocal::triangulation
