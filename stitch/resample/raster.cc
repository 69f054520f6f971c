#include "stitch/resample/raster.h"

#include "calib/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace aerocal::stitch {

MemoryRaster::MemoryRaster(const RasterInfo& info) : info_(info) {
  AEROCAL_CHECK(info.width > 0 && info.height > 0 && (info.bands == 1 || info.bands == 3) &&
                (info.bits == 8 || info.bits == 16))
      << info.width << " x " << info.height << " x " << info.bands << " bands, " << info.bits
      << " bit";
  bytes_.assign(info.RowBytes() * info.height, 0);
}

void MemoryRaster::ReadWindow(int x0, int y0, int w, int h, void* out) {
  const size_t sample = info_.BytesPerSample() * info_.bands;
  auto* dst = static_cast<std::uint8_t*>(out);
  for (int r = 0; r < h; ++r)
    std::memcpy(dst + r * w * sample,
                bytes_.data() + (y0 + r) * info_.RowBytes() + x0 * sample,
                w * sample);
}

void MemoryRaster::WriteRows(int y0, int rows, const void* data) {
  std::memcpy(bytes_.data() + y0 * info_.RowBytes(), data, rows * info_.RowBytes());
}

double MemoryRaster::At(int col, int row, int band) const {
  const size_t index = (static_cast<size_t>(row) * info_.width + col) * info_.bands + band;
  if (info_.bits == 8) return bytes_[index];
  std::uint16_t v;
  std::memcpy(&v, bytes_.data() + 2 * index, 2);
  return v;
}

void MemoryRaster::Set(int col, int row, int band, double value) {
  const size_t index = (static_cast<size_t>(row) * info_.width + col) * info_.bands + band;
  const double max = info_.bits == 8 ? 255.0 : 65535.0;
  const double v = std::clamp(std::round(value), 0.0, max);
  if (info_.bits == 8) {
    bytes_[index] = static_cast<std::uint8_t>(v);
  } else {
    const std::uint16_t s = static_cast<std::uint16_t>(v);
    std::memcpy(bytes_.data() + 2 * index, &s, 2);
  }
}

}  // namespace aerocal::stitch
