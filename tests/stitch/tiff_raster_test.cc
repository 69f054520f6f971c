// TIFF reading and writing of the resampler (tiff_raster.h): round trips of 8/16 bit, 1/3 bands,
// classic and BigTIFF, windowed reads across strips, metadata, atomic output.
#include "stitch/resample/tiff_raster.h"

#include <filesystem>
#include <random>

#include <gtest/gtest.h>

#include "calib/core/error.h"
#include "tests/support/test_support.h"

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

TEST(TiffRaster, RejectsAMissingFile) {
  EXPECT_THROW(OpenTiff("/nonexistent/x.tif"), InputError);
}

}  // namespace
}  // namespace aerocal::stitch
