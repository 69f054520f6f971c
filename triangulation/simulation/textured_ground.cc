#include "triangulation/simulation/textured_ground.h"

#include "calib/core/error.h"
#include "stitch/image_io/image_io.h"
#include "triangulation/pushbroom/line_rectification.h"

#include <cmath>

namespace aerocal::triangulation {

double TexturedGround::Mirror(double u, int n) {
  const double period = 2.0 * (n - 1);
  double m = std::fmod(u, period);
  if (m < 0) m += period;
  return m <= n - 1 ? m : period - m;
}

float TexturedGround::At(double x, double y) const {
  const double u = Mirror((x - x_c) / gsd_m + 0.5 * texels.cols(), int(texels.cols()));
  const double v = Mirror((y_c - y) / gsd_m + 0.5 * texels.rows(), int(texels.rows()));
  return SampleBilinear(texels, u, v);
}

stitch::GrayImage AverageTwoByTwo(const stitch::GrayImage& photo) {
  stitch::GrayImage out(photo.rows() / 2, photo.cols() / 2);
  for (int r = 0; r < out.rows(); ++r)
    for (int c = 0; c < out.cols(); ++c)
      out(r, c) = 0.25f * (photo(2 * r, 2 * c) + photo(2 * r, 2 * c + 1) + photo(2 * r + 1, 2 * c) +
                           photo(2 * r + 1, 2 * c + 1));
  return out;
}

void ReadGroundTexture(const std::string& photo_path, TexturedGround* ground) {
  ground->texels = AverageTwoByTwo(stitch::ReadGrayImage(photo_path));
  if (ground->texels.rows() < 16 || ground->texels.cols() < 16)
    throw InputError(photo_path + ": the photograph is too small for a texture (< 32 px)");
}

}  // namespace aerocal::triangulation
