// TIFF reading and writing of the resampler (tiff_raster.h): round trips of 8/16 bit, 1/3 bands,
// classic and BigTIFF, windowed reads across strips, metadata, atomic output.
#include "stitch/resample/tiff_raster.h"

#include "calib/core/error.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

namespace aerocal::stitch {
namespace {

MemoryRaster RandomRaster(const RasterInfo& info, unsigned seed) {
  MemoryRaster raster(info);
  std::mt19937 rng(seed);
  for (auto& b : raster.bytes()) b = static_cast<std::uint8_t>(rng());
  return raster;
}

TEST(TiffRaster, RoundTripsEveryDepthAndBandCountWithWindowedReads) {
  testing::TempDir tmp;
  for (int bits : {8, 16})
    for (int bands : {1, 3})
      for (bool big : {false, true}) {
        const RasterInfo info{301, 203, bands, bits};
        MemoryRaster raster = RandomRaster(info, bits * 10 + bands);
        const std::string path = tmp.File("r" + std::to_string(bits) + "_" + std::to_string(bands) +
                                          (big ? "_big" : "") + ".tif");
        TiffWriteOptions options;
        options.description = "mapping I affine 1 0 0.5 0 1 -0.25";
        options.force_bigtiff = big;
        options.rows_per_strip = 16;
        {
          TiffWriter writer(path, info, options);
          // Rows in chunks that do not match the strips.
          for (int y = 0; y < info.height; y += 37) {
            const int rows = std::min(37, info.height - y);
            writer.WriteRows(y, rows, raster.bytes().data() + y * info.RowBytes());
          }
          writer.Commit();
        }
        EXPECT_EQ(IsBigTiff(path), big);
        EXPECT_EQ(ReadTiffDescription(path), options.description);
        const auto source = OpenTiff(path);
        EXPECT_EQ(source->Info().width, 301);
        EXPECT_EQ(source->Info().bits, bits);
        EXPECT_EQ(source->Info().bands, bands);
        // A window straddling several strips.
        const int x0 = 17, y0 = 29, w = 100, h = 60;
        std::vector<std::uint8_t> window(w * h * bands * bits / 8);
        source->ReadWindow(x0, y0, w, h, window.data());
        std::vector<std::uint8_t> expected(window.size());
        raster.ReadWindow(x0, y0, w, h, expected.data());
        EXPECT_EQ(window, expected) << bits << " bit, " << bands << " bands";
      }
}

// Tiled output (issue 13: `rig convert --tile-px`): 64 px tiles over 301 x 203 px leave partial
// tiles on the right and bottom edges; every pixel reads back, through our windowed reader (tile
// by tile) and through OpenCV (libtiff's whole-image read), for each depth, band count and BigTIFF.
TEST(TiffRaster, TiledRoundTripsEveryDepthBandCountAndBigTiff) {
  testing::TempDir tmp;
  for (int bits : {8, 16})
    for (int bands : {1, 3})
      for (bool big : {false, true}) {
        SCOPED_TRACE(::testing::Message() << bits << " bit, " << bands << " bands, big " << big);
        const RasterInfo info{301, 203, bands, bits};
        MemoryRaster raster = RandomRaster(info, bits * 100 + bands);
        const std::string path = tmp.File("t" + std::to_string(bits) + "_" + std::to_string(bands) +
                                          (big ? "_big" : "") + ".tif");
        TiffWriteOptions options;
        options.force_bigtiff = big;
        options.tile_px = 64;
        {
          TiffWriter writer(path, info, options);
          for (int y = 0; y < info.height; y += 37)  // row chunks that do not match the tiles
            writer.WriteRows(
                y, std::min(37, info.height - y), raster.bytes().data() + y * info.RowBytes());
          writer.Commit();
        }
        EXPECT_EQ(IsBigTiff(path), big);
        EXPECT_EQ(TiffTileWidth(path), 64);
        const auto source = OpenTiff(path);
        ASSERT_EQ(source->Info().width, info.width);
        ASSERT_EQ(source->Info().height, info.height);
        std::vector<std::uint8_t> all(info.RowBytes() * info.height);
        source->ReadWindow(0, 0, info.width, info.height, all.data());
        EXPECT_EQ(all, raster.bytes());
        const int x0 = 250, y0 = 150, w = 51, h = 53;  // the bottom-right partial tiles
        std::vector<std::uint8_t> window(w * h * bands * bits / 8), expected(window.size());
        source->ReadWindow(x0, y0, w, h, window.data());
        raster.ReadWindow(x0, y0, w, h, expected.data());
        EXPECT_EQ(window, expected);
        if (!big) {  // OpenCV 4.6 reads classic TIFF only
          const MemoryRaster read = ReadImageFile(path);
          EXPECT_EQ(read.bytes(), raster.bytes());
        }
      }
  // A stripped file says 0; a tile size that TIFF does not allow is a caller's error.
  TiffWriter strips(tmp.File("s.tif"), {16, 16, 1, 8}, {});
  std::vector<std::uint8_t> rows(16 * 16, 7);
  strips.WriteRows(0, 16, rows.data());
  strips.Commit();
  EXPECT_EQ(TiffTileWidth(tmp.File("s.tif")), 0);
  TiffWriteOptions bad;
  bad.tile_px = 100;
  EXPECT_THROW(TiffWriter(tmp.File("b.tif"), {16, 16, 1, 8}, bad), LogicError);
}

TEST(TiffRaster, LeavesNothingBehindWithoutCommit) {
  testing::TempDir tmp;
  const std::string path = tmp.File("partial.tif");
  {
    TiffWriter writer(path, {10, 10, 1, 8}, {});
    std::vector<std::uint8_t> row(10 * 5, 1);
    writer.WriteRows(0, 5, row.data());
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".part"));
}

TEST(TiffRaster, RejectsAMissingFile) { EXPECT_THROW(OpenTiff("/nonexistent/x.tif"), InputError); }

}  // namespace
}  // namespace aerocal::stitch
