// aerocal import images on real DJI JPEGs: eight images of the Brighton Beach flight (DJI Phantom 3
// Advanced, camera FC300S, 2016; tests/data/images_brighton, PROVENANCE.md) whose EXIF and XMP
// segments are the drone's bytes, unaltered (the pixels are downscaled). The centres are checked
// against the EXIF GPS rationals as Pillow (an independent reader) printed them, the altitude and
// gimbal angles against the XMP text (a regular expression), the attitude against what the gimbal
// angles mean (nadir within 0.1 deg, image top along the yaw), the camera against the EXIF focal
// lengths. These images have no DewarpData (the FC300S does not write it): that path is tested on
// the constructed fixtures (import_images_cli_test.cc).
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"
#include "triangulation/import/gimbal_attitude.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

namespace aerocal {
namespace {

using testing::RunAerocal;
constexpr double kDeg = M_PI / 180.0;

const std::string kImages = std::string(AEROCAL_TEST_DATA_DIR) + "/images_brighton";

double XmpValue(const std::string& bytes, const std::string& name) {
  return testing::XmpAttribute(bytes, name);
}

// EXIF GPSLatitude / GPSLongitude of two images as rationals (degrees, minutes, seconds), with
// their refs N / W, printed by Pillow 9.4 (PIL.Image.getexif().get_ifd(0x8825)).
struct ExifGps {
  double lat_d, lat_m, lat_s, lon_d, lon_m, lon_s, altitude_m;
};
const std::map<std::string, ExifGps> kExifGps = {
    {"DJI_0019.JPG", {46, 50, 336864 / 10000.0, 91, 59, 399382 / 10000.0, 198609 / 1000.0}},
    {"DJI_0032.JPG", {46, 50, 328504 / 10000.0, 91, 59, 377855 / 10000.0, 198609 / 1000.0}},
};

TEST(ImportImagesReal, DjiPhantom3JpegsGiveTheExifCentresAndGimbalAttitudes) {
  testing::TempDir tmp("aerocal_import_real");
  const auto r = RunAerocal("import images " + kImages + " --out " + tmp.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("imported 8 exposures, 1 cameras"), std::string::npos) << r.output;
  const triangulation::Project p = triangulation::ReadProject(tmp.File("out"));
  EXPECT_EQ(p.frame.crs, "EPSG:4326+5773");  // EXIF altitudes: above sea level (EGM96)
  ASSERT_EQ(p.exposures.size(), 8u);
  for (const triangulation::Exposure& e : p.exposures) {
    SCOPED_TRACE(e.image);
    const std::string bytes = ReadTextFile(kImages + "/" + e.image);
    // The XMP has no GpsLatitude: the EXIF GPS IFD gives the position; the altitude is the XMP's
    // AbsoluteAltitude (the reader's documented preference), within 1 cm of EXIF GPSAltitude.
    EXPECT_DOUBLE_EQ(e.center_m.z(), XmpValue(bytes, "AbsoluteAltitude"));
    if (const auto it = kExifGps.find(e.image); it != kExifGps.end()) {
      const ExifGps& g = it->second;
      // exposures.csv holds 10 decimals of degrees (11 um): the tolerance.
      EXPECT_NEAR(e.center_m.y(), g.lat_d + g.lat_m / 60 + g.lat_s / 3600, 1e-10);
      EXPECT_NEAR(e.center_m.x(), -(g.lon_d + g.lon_m / 60 + g.lon_s / 3600), 1e-10);
      EXPECT_NEAR(e.center_m.z(), g.altitude_m, 0.01);
    }
    const double yaw = XmpValue(bytes, "GimbalYawDegree"),
                 pitch = XmpValue(bytes, "GimbalPitchDegree");
    const Eigen::Vector3d expected =
        triangulation::OpkOfGimbal(yaw, pitch, XmpValue(bytes, "GimbalRollDegree"));
    EXPECT_LT((e.opk_rad - expected).norm(), 3e-10);  // 8 decimals of degrees in the file
    // Pitch -89.90 (-90.00 in some): 0.1 deg from nadir; kappa = -yaw (the image top points
    // along the yaw) up to the coupling of the 0.1 deg tilt, below 1e-6 rad (7.6e-7 here).
    EXPECT_NEAR(std::hypot(e.opk_rad.x(), e.opk_rad.y()), (90 + pitch) * kDeg, 1e-6);
    EXPECT_NEAR(std::remainder(e.opk_rad.z() + yaw * kDeg, 2 * M_PI), 0, 1e-6);
    EXPECT_FALSE(e.center_sigma_m);  // no RTK values and no --gnss-sigma-m: not weighted
  }
  EXPECT_NEAR(p.exposures.front().opk_rad.z(), -42.8 * kDeg, 1e-6);  // DJI_0019: yaw +42.80
  // One camera (no serial in these files: make and model), c = EXIF FocalLength 3.61 mm, the pixel
  // size from FocalLengthIn35mmFilm 20 mm over the 640 x 360 px the JPEG's SOF gives.
  ASSERT_EQ(p.cameras.size(), 1u);
  const calib::Camera& c = p.cameras.begin()->second;
  EXPECT_EQ(c.width_px, 640);
  EXPECT_EQ(c.height_px, 360);
  EXPECT_DOUBLE_EQ(c.c_mm(), 3.61);
  EXPECT_NEAR(c.pixel_size_mm, 43.2666 * 3.61 / 20 / std::hypot(640, 360), 1e-9);
  const std::string tags = ReadTextFile(tmp.File("out/tags.csv"));
  for (const char* row :
       {"DJI_0019.JPG,latitude_deg,EXIF GPSLatitude + EXIF GPSLatitudeRef,46 50 33.6864 N",
        "DJI_0019.JPG,longitude_deg,EXIF GPSLongitude + EXIF GPSLongitudeRef,91 59 39.9382 W",
        "DJI_0019.JPG,altitude_m,XMP drone-dji:AbsoluteAltitude,+198.61",
        "DJI_0019.JPG,gimbal_yaw_deg,XMP drone-dji:GimbalYawDegree,+42.80",
        "DJI_0019.JPG,focal_length_mm,EXIF FocalLength,3.61",
        "DJI_0019.JPG,capture_time,EXIF DateTimeOriginal,2016:06:23"})
    EXPECT_NE(tags.find(row), std::string::npos) << row << "\n" << tags;
  const std::string not_used = ReadTextFile(tmp.File("out/images_not_used.csv"));
  EXPECT_NE(not_used.find("PROVENANCE.md,not a .jpg"), std::string::npos) << not_used;
}

}  // namespace
}  // namespace aerocal
