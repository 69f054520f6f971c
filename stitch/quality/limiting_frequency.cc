#include "stitch/quality/limiting_frequency.h"

#include <cmath>
#include <limits>

namespace aerocal::stitch {

LimitingFrequency FindLimitingFrequency(const std::vector<double>& f,
                                        const std::vector<double>& ct,
                                        double t) {
  LimitingFrequency out;
  out.frequency_cy_px = std::numeric_limits<double>::quiet_NaN();
  for (size_t i = 0; i < f.size(); ++i) {
    if (ct[i] >= t) continue;
    if (i == 0) return out;  // nothing resolved
    const double w = (ct[i - 1] - t) / (ct[i - 1] - ct[i]);
    out.frequency_cy_px = std::exp(std::log(f[i - 1]) + w * (std::log(f[i]) - std::log(f[i - 1])));
    return out;
  }
  if (!f.empty()) {
    out.frequency_cy_px = f.back();
    out.in_range = false;
  }
  return out;
}

}  // namespace aerocal::stitch
