// TIFF rasters through libtiff: windowed reading of stripped or tiled TIFF (any compression
// libtiff decodes, contiguous bands), and writing of the virtual image in strips or square tiles
// (rows arrive in order; a tile row is written once its rows are in), as BigTIFF when
// the classic 4 GiB offsets could overflow (or when forced), with a text ImageDescription (the
// mapping model and parameters of every sub-image) and the Software tag.
#pragma once

#include "stitch/resample/raster.h"

#include <memory>
#include <string>

namespace aerocal::stitch {

/// Opens a TIFF for windowed reading. InputError("PATH: ...") when it is missing, not 8/16-bit
/// unsigned, not 1 or 3 bands, or planar-separate.
std::unique_ptr<RasterSource> OpenTiff(const std::string& path);

struct TiffWriteOptions {
  std::string description;  // ImageDescription (ASCII)
  bool force_bigtiff = false;
  int rows_per_strip = 64;
  /// > 0: square tiles of tile_px x tile_px instead of strips (a multiple of 16, the TIFF rule,
  /// 16..4096; edge tiles are padded with zeros, as TIFF readers expect).
  int tile_px = 0;
};

/// Writes a TIFF of `info` row-strip by row-strip to a temporary file beside `path`; Commit()
/// renames it over `path` (nothing is left when the writer is destroyed without Commit()).
class TiffWriter : public RasterSink {
 public:
  TiffWriter(const std::string& path, const RasterInfo& info, const TiffWriteOptions& options);
  ~TiffWriter() override;
  void WriteRows(int y0, int rows, const void* data) override;
  void Commit();
  bool bigtiff() const { return bigtiff_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool bigtiff_ = false;
};

/// ImageDescription of a TIFF ("" when absent); InputError when it cannot be opened.
std::string ReadTiffDescription(const std::string& path);
/// True when the file is a BigTIFF.
bool IsBigTiff(const std::string& path);
/// The tile width of a tiled TIFF, 0 for a stripped one.
int TiffTileWidth(const std::string& path);

/// Reads a whole image file as a raster (through OpenCV: TIFF, JPEG, PNG, ...; colour as R, G, B;
/// 8 or 16 bit kept). InputError("PATH: ...") when unreadable. `gray` converts to one band.
MemoryRaster ReadImageFile(const std::string& path, bool gray = false);

}  // namespace aerocal::stitch
