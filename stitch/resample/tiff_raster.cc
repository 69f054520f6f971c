#include "stitch/resample/tiff_raster.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "stitch/image_io/image_codecs.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <tiffio.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <vector>

namespace aerocal::stitch {
namespace {

void SilenceLibtiff() {
  // libtiff prints warnings (unknown tags, ...) to stderr by default; errors become exceptions
  // here.
  TIFFSetWarningHandler(nullptr);
  TIFFSetErrorHandler(nullptr);
}

class TiffReader : public RasterSource {
 public:
  explicit TiffReader(const std::string& path) : path_(path) {
    SilenceLibtiff();
    CheckInputFile(path);                  // a FIFO or device is refused before libtiff opens it
    tiff_ = TIFFOpen(path.c_str(), "rm");  // no memory mapping: windows are read as needed
    if (!tiff_) throw InputError(path + ": cannot open as TIFF");
    uint32_t width = 0, height = 0;
    uint16_t bits = 8, bands = 1, format = SAMPLEFORMAT_UINT, planar = PLANARCONFIG_CONTIG;
    TIFFGetField(tiff_, TIFFTAG_IMAGEWIDTH, &width);
    TIFFGetField(tiff_, TIFFTAG_IMAGELENGTH, &height);
    TIFFGetFieldDefaulted(tiff_, TIFFTAG_BITSPERSAMPLE, &bits);
    TIFFGetFieldDefaulted(tiff_, TIFFTAG_SAMPLESPERPIXEL, &bands);
    TIFFGetFieldDefaulted(tiff_, TIFFTAG_SAMPLEFORMAT, &format);
    TIFFGetFieldDefaulted(tiff_, TIFFTAG_PLANARCONFIG, &planar);
    if ((bits != 8 && bits != 16) || format != SAMPLEFORMAT_UINT || (bands != 1 && bands != 3) ||
        (bands == 3 && planar != PLANARCONFIG_CONTIG)) {
      TIFFClose(tiff_);
      throw InputError(path +
                       ": expected 8- or 16-bit unsigned samples, 1 or 3 interleaved bands (got " +
                       std::to_string(bits) + " bit, " + std::to_string(bands) + " bands)");
    }
    info_ = {static_cast<int>(width), static_cast<int>(height), bands, bits};
    tiled_ = TIFFIsTiled(tiff_);
    if (tiled_) {
      TIFFGetField(tiff_, TIFFTAG_TILEWIDTH, &block_w_);
      TIFFGetField(tiff_, TIFFTAG_TILELENGTH, &block_h_);
    } else {
      block_w_ = width;
      TIFFGetFieldDefaulted(tiff_, TIFFTAG_ROWSPERSTRIP, &block_h_);
      block_h_ = std::min<uint32_t>(block_h_, height);
    }
  }
  ~TiffReader() override { TIFFClose(tiff_); }
  RasterInfo Info() const override { return info_; }

  void ReadWindow(int x0, int y0, int w, int h, void* out) override {
    const size_t sample = info_.bands * info_.BytesPerSample();
    const size_t block_row = block_w_ * sample;
    auto* dst = static_cast<std::uint8_t*>(out);
    for (uint32_t by = y0 / block_h_ * block_h_; by < static_cast<uint32_t>(y0 + h); by += block_h_)
      for (uint32_t bx = x0 / block_w_ * block_w_; bx < static_cast<uint32_t>(x0 + w);
           bx += block_w_) {
        const std::vector<std::uint8_t>& block = Block(bx, by);
        const int r0 = std::max<int>(y0, by), r1 = std::min<int>(y0 + h, by + block_h_);
        const int c0 = std::max<int>(x0, bx), c1 = std::min<int>(x0 + w, bx + block_w_);
        for (int r = r0; r < r1; ++r)
          std::memcpy(dst + ((r - y0) * static_cast<size_t>(w) + (c0 - x0)) * sample,
                      block.data() + (r - by) * block_row + (c0 - bx) * sample,
                      (c1 - c0) * sample);
      }
  }

 private:
  // Decoded strip or tile at (bx, by); the last one is kept (windows of consecutive strips of the
  // virtual image overlap by a few rows).
  const std::vector<std::uint8_t>& Block(uint32_t bx, uint32_t by) {
    if (cached_ && cached_x_ == bx && cached_y_ == by) return cache_;
    cache_.assign(static_cast<size_t>(block_w_) * block_h_ * info_.bands * info_.BytesPerSample(),
                  0);
    const tmsize_t n =
        tiled_ ? TIFFReadEncodedTile(
                     tiff_, TIFFComputeTile(tiff_, bx, by, 0, 0), cache_.data(), cache_.size())
               : TIFFReadEncodedStrip(
                     tiff_, TIFFComputeStrip(tiff_, by, 0), cache_.data(), cache_.size());
    if (n < 0) throw InputError(path_ + ": cannot decode the block at row " + std::to_string(by));
    cached_ = true;
    cached_x_ = bx;
    cached_y_ = by;
    return cache_;
  }

  std::string path_;
  TIFF* tiff_ = nullptr;
  RasterInfo info_;
  bool tiled_ = false;
  uint32_t block_w_ = 0, block_h_ = 0;
  bool cached_ = false;
  uint32_t cached_x_ = 0, cached_y_ = 0;
  std::vector<std::uint8_t> cache_;
};

}  // namespace

std::unique_ptr<RasterSource> OpenTiff(const std::string& path) {
  return std::make_unique<TiffReader>(path);
}

struct TiffWriter::Impl {
  std::string path, temp_path;
  TIFF* tiff = nullptr;
  RasterInfo info;
  int rows_per_strip = 64;
  int tile_px = 0;  // > 0: tiled
  int next_row = 0;
  std::vector<std::uint8_t> pending;  // rows of the current strip or tile row
  std::vector<std::uint8_t> tile;     // one tile (tiled only)
  bool committed = false;

  // Writes the block of `rows` rows starting at image row y0 from `src` (rows_per_strip or
  // tile_px rows, fewer at the bottom): one strip, or one row of tiles.
  void WriteBlock(int y0, int rows, const std::uint8_t* src) {
    const size_t row_bytes = info.RowBytes();
    if (tile_px == 0) {
      if (TIFFWriteEncodedStrip(
              tiff, y0 / rows_per_strip, const_cast<std::uint8_t*>(src), rows * row_bytes) < 0)
        throw Error(path + ": cannot write the TIFF (disk full?)");
      return;
    }
    const size_t pixel_bytes = static_cast<size_t>(info.bands) * info.BytesPerSample();
    const size_t tile_row_bytes = tile_px * pixel_bytes;
    for (int x0 = 0; x0 < info.width; x0 += tile_px) {
      std::fill(tile.begin(), tile.end(), 0);
      const size_t n = std::min(tile_px, info.width - x0) * pixel_bytes;
      for (int r = 0; r < rows; ++r)
        std::memcpy(tile.data() + r * tile_row_bytes, src + r * row_bytes + x0 * pixel_bytes, n);
      if (TIFFWriteEncodedTile(
              tiff, TIFFComputeTile(tiff, x0, y0, 0, 0), tile.data(), tile.size()) < 0)
        throw Error(path + ": cannot write the TIFF (disk full?)");
    }
  }
};

TiffWriter::TiffWriter(const std::string& path,
                       const RasterInfo& info,
                       const TiffWriteOptions& options)
    : impl_(std::make_unique<Impl>()) {
  SilenceLibtiff();
  impl_->path = path;
  impl_->info = info;
  impl_->rows_per_strip = std::max(1, options.rows_per_strip);
  impl_->tile_px = options.tile_px;
  AEROCAL_CHECK(options.tile_px == 0 ||
                (options.tile_px % 16 == 0 && options.tile_px >= 16 && options.tile_px <= 4096))
      << "tile_px must be 0 or a multiple of 16 in 16..4096 (got " << options.tile_px << ")";
  const std::filesystem::path target(path);
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path());
  impl_->temp_path = path + ".part";
  // Classic TIFF offsets are 32-bit: beyond ~4 GiB (with room for the tags) BigTIFF is needed.
  // (Tiles pad the right and bottom edges.)
  const auto padded = [&](int n) {
    return options.tile_px > 0 ? (n + options.tile_px - 1) / options.tile_px * options.tile_px : n;
  };
  const double bytes =
      static_cast<double>(info.RowBytes()) / info.width * padded(info.width) * padded(info.height);
  bigtiff_ = options.force_bigtiff || bytes > 3.9e9;
  impl_->tiff = TIFFOpen(impl_->temp_path.c_str(), bigtiff_ ? "w8" : "w");
  if (!impl_->tiff) throw Error(path + ": cannot create the TIFF");
  TIFF* t = impl_->tiff;
  TIFFSetField(t, TIFFTAG_IMAGEWIDTH, static_cast<uint32_t>(info.width));
  TIFFSetField(t, TIFFTAG_IMAGELENGTH, static_cast<uint32_t>(info.height));
  TIFFSetField(t, TIFFTAG_BITSPERSAMPLE, static_cast<uint16_t>(info.bits));
  TIFFSetField(t, TIFFTAG_SAMPLESPERPIXEL, static_cast<uint16_t>(info.bands));
  TIFFSetField(t, TIFFTAG_SAMPLEFORMAT, SAMPLEFORMAT_UINT);
  TIFFSetField(t, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
  TIFFSetField(t, TIFFTAG_PHOTOMETRIC, info.bands == 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK);
  TIFFSetField(t, TIFFTAG_COMPRESSION, COMPRESSION_NONE);
  if (impl_->tile_px > 0) {
    TIFFSetField(t, TIFFTAG_TILEWIDTH, static_cast<uint32_t>(impl_->tile_px));
    TIFFSetField(t, TIFFTAG_TILELENGTH, static_cast<uint32_t>(impl_->tile_px));
    impl_->tile.resize(static_cast<size_t>(impl_->tile_px) * impl_->tile_px * info.bands *
                       info.BytesPerSample());
  } else {
    TIFFSetField(t, TIFFTAG_ROWSPERSTRIP, static_cast<uint32_t>(impl_->rows_per_strip));
  }
  TIFFSetField(t, TIFFTAG_SOFTWARE, "aerocal");
  if (!options.description.empty())
    TIFFSetField(t, TIFFTAG_IMAGEDESCRIPTION, options.description.c_str());
}

TiffWriter::~TiffWriter() {
  if (impl_->tiff) TIFFClose(impl_->tiff);
  if (!impl_->committed) std::remove(impl_->temp_path.c_str());
}

void TiffWriter::WriteRows(int y0, int rows, const void* data) {
  AEROCAL_CHECK(y0 == impl_->next_row)
      << "rows must come in order: " << y0 << " after " << impl_->next_row;
  const size_t row_bytes = impl_->info.RowBytes();
  const auto* src = static_cast<const std::uint8_t*>(data);
  impl_->pending.insert(impl_->pending.end(), src, src + rows * row_bytes);
  impl_->next_row += rows;
  // Emit every complete strip or tile row (and the last, short one at the end of the image).
  const int block_rows = impl_->tile_px > 0 ? impl_->tile_px : impl_->rows_per_strip;
  const size_t block_bytes = block_rows * row_bytes;
  int block_y0 = impl_->next_row - static_cast<int>(impl_->pending.size() / row_bytes);
  size_t offset = 0;
  while (impl_->pending.size() - offset >= block_bytes ||
         (impl_->next_row == impl_->info.height && offset < impl_->pending.size())) {
    const size_t n = std::min(block_bytes, impl_->pending.size() - offset);
    impl_->WriteBlock(block_y0, static_cast<int>(n / row_bytes), impl_->pending.data() + offset);
    block_y0 += block_rows;
    offset += n;
  }
  impl_->pending.erase(impl_->pending.begin(), impl_->pending.begin() + offset);
}

void TiffWriter::Commit() {
  AEROCAL_CHECK(impl_->next_row == impl_->info.height)
      << impl_->next_row << " of " << impl_->info.height << " rows written";
  TIFFClose(impl_->tiff);
  impl_->tiff = nullptr;
  std::error_code ec;
  std::filesystem::rename(impl_->temp_path, impl_->path, ec);
  if (ec) throw Error(impl_->path + ": cannot rename the finished TIFF: " + ec.message());
  impl_->committed = true;
}

std::string ReadTiffDescription(const std::string& path) {
  SilenceLibtiff();
  TIFF* tiff = TIFFOpen(path.c_str(), "r");
  if (!tiff) throw InputError(path + ": cannot open as TIFF");
  char* text = nullptr;
  std::string out;
  if (TIFFGetField(tiff, TIFFTAG_IMAGEDESCRIPTION, &text) && text) out = text;
  TIFFClose(tiff);
  return out;
}

bool IsBigTiff(const std::string& path) {
  SilenceLibtiff();
  TIFF* tiff = TIFFOpen(path.c_str(), "r");
  if (!tiff) throw InputError(path + ": cannot open as TIFF");
  const bool big = TIFFIsBigTIFF(tiff);
  TIFFClose(tiff);
  return big;
}

int TiffTileWidth(const std::string& path) {
  SilenceLibtiff();
  TIFF* tiff = TIFFOpen(path.c_str(), "r");
  if (!tiff) throw InputError(path + ": cannot open as TIFF");
  uint32_t width = 0;
  if (TIFFIsTiled(tiff)) TIFFGetField(tiff, TIFFTAG_TILEWIDTH, &width);
  TIFFClose(tiff);
  return static_cast<int>(width);
}

MemoryRaster ReadImageFile(const std::string& path, bool gray) {
  CheckInputFile(path);
  cv::Mat image = DecodeImageFile(path, cv::IMREAD_UNCHANGED | cv::IMREAD_IGNORE_ORIENTATION);
  if (image.empty()) throw InputError(path + ": cannot read the image");
  if (image.depth() != CV_8U && image.depth() != CV_16U)
    throw InputError(path + ": expected 8- or 16-bit unsigned samples");
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_BGRA2BGR);
  if (image.channels() == 3)
    cv::cvtColor(image, image, gray ? cv::COLOR_BGR2GRAY : cv::COLOR_BGR2RGB);
  if (image.channels() != 1 && image.channels() != 3)
    throw InputError(path + ": expected 1 or 3 bands (got " + std::to_string(image.channels()) +
                     ")");
  MemoryRaster raster({image.cols, image.rows, image.channels(), image.depth() == CV_8U ? 8 : 16});
  const size_t row_bytes = raster.Info().RowBytes();
  for (int r = 0; r < image.rows; ++r)
    std::memcpy(raster.bytes().data() + r * row_bytes, image.ptr(r), row_bytes);
  return raster;
}

}  // namespace aerocal::stitch
