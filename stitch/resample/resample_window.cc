#include "stitch/resample/resample_window.h"

#include <algorithm>
#include <cmath>

namespace aerocal::stitch::internal {

// With [x y w]^T = M [U V 1]^T and w > 0, u >= 0 <=> x >= 0, u <= W-1 <=> (W-1) w - x >= 0, ...:
// each bound is a U + b >= 0.
bool CoveredColumns(const Window& win, double V, int virtual_width, int* first, int* last) {
  const Eigen::Matrix3d& m = win.sub_from_virtual;
  double lo = 0.0, hi = virtual_width - 1.0;
  auto bound = [&](double a, double b) {  // a U + b >= 0
    if (std::abs(a) < 1e-15) {
      if (b < 0) hi = -1.0;
      return;
    }
    const double root = -b / a;
    if (a > 0)
      lo = std::max(lo, root);
    else
      hi = std::min(hi, root);
  };
  const double W = win.width_px - 1.0, H = win.height_px - 1.0;
  const double xa = m(0, 0), xb = m(0, 1) * V + m(0, 2);
  const double ya = m(1, 0), yb = m(1, 1) * V + m(1, 2);
  const double wa = m(2, 0), wb = m(2, 1) * V + m(2, 2);
  bound(wa, wb - 1e-12);
  bound(xa, xb);
  bound(W * wa - xa, W * wb - xb);
  bound(ya, yb);
  bound(H * wa - ya, H * wb - yb);
  // Rounding at the bounds: keep pixels within 1e-9 px of the edge (bounds clamped to the row
  // first, so that a far root never overflows the int).
  lo = std::max(lo, -1.0);
  hi = std::min(hi, static_cast<double>(virtual_width));
  *first = static_cast<int>(std::ceil(lo - 1e-9));
  *last = static_cast<int>(std::floor(hi + 1e-9));
  *first = std::max(*first, 0);
  *last = std::min(*last, virtual_width - 1);
  return *first <= *last;
}

}  // namespace aerocal::stitch::internal
