// Rasters for resampling: 8- or 16-bit samples, 1 or 3 bands interleaved (band-interleaved by
// pixel), row-major, pixel (col, row) per CONVENTIONS.md. A source gives random access to windows
// so that a 14000 x 12000 virtual image is made strip by strip without whole-image copies of the
// sources; a sink takes the output rows top to bottom.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace aerocal::stitch {

struct RasterInfo {
  int width = 0, height = 0;  // px
  int bands = 1;              // 1 or 3
  int bits = 8;               // 8 or 16 (unsigned)
  int BytesPerSample() const { return bits / 8; }
  size_t RowBytes() const { return static_cast<size_t>(width) * bands * BytesPerSample(); }
};

class RasterSource {
 public:
  virtual ~RasterSource() = default;
  virtual RasterInfo Info() const = 0;
  /// Copies the window [x0, x0 + w) x [y0, y0 + h), which lies inside the raster, into `out`
  /// (w * h * bands samples of the raster's type, rows of w * bands samples). One object is
  /// not thread-safe; distinct sources may be read concurrently.
  virtual void ReadWindow(int x0, int y0, int w, int h, void* out) = 0;
  /// The whole raster when it is held in memory (rows of Info().RowBytes() bytes), which the
  /// resampling then reads in place instead of copying windows; null otherwise.
  virtual const std::uint8_t* Samples() const { return nullptr; }
};

class RasterSink {
 public:
  virtual ~RasterSink() = default;
  /// Takes `rows` full rows starting at `y0`; calls come in increasing, gap-free order.
  virtual void WriteRows(int y0, int rows, const void* data) = 0;
};

/// A raster held in memory (tests, benchmarks, small images); both source and sink.
class MemoryRaster : public RasterSource, public RasterSink {
 public:
  MemoryRaster() = default;
  explicit MemoryRaster(const RasterInfo& info);
  RasterInfo Info() const override { return info_; }
  void ReadWindow(int x0, int y0, int w, int h, void* out) override;
  const std::uint8_t* Samples() const override { return bytes_.data(); }
  void WriteRows(int y0, int rows, const void* data) override;
  /// Sample of band `band` at (col, row), as a number.
  double At(int col, int row, int band = 0) const;
  void Set(int col, int row, int band, double value);  // rounded and clamped to the type
  std::vector<std::uint8_t>& bytes() { return bytes_; }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  RasterInfo info_;
  std::vector<std::uint8_t> bytes_;
};

}  // namespace aerocal::stitch
