// aerocal import images on the metadata-only DJI JPEGs of tests/data/images (values of public DJI
// metadata, PROVENANCE.md) and on JPEGs rebuilt here with one XMP value changed or broken: centres
// and attitudes against the values read independently from the XMP text, the camera from
// DewarpData, the tags listed, unused files named, --crs, and every option's bad values.
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tests/support/test_support.h"
#include "triangulation/block/block_io.h"
#include "triangulation/georef/crs.h"
#include "triangulation/import/gimbal_attitude.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace aerocal {
namespace {

using testing::RunAerocal;
namespace fs = std::filesystem;
constexpr double kDeg = M_PI / 180.0;

const std::string kImages = std::string(AEROCAL_TEST_DATA_DIR) + "/images";

double XmpValue(const std::string& bytes, const std::string& name) {
  return testing::XmpAttribute(bytes, name);
}

// The fixture with its XMP text passed through `edit` (the APP1 length rewritten).
std::string WithXmp(const std::string& jpeg, const std::function<std::string(std::string)>& edit) {
  const size_t header = jpeg.find("http://ns.adobe.com/xap/1.0/");
  const size_t start = header - 4;
  const size_t length = (static_cast<unsigned char>(jpeg[start + 2]) << 8) |
                        static_cast<unsigned char>(jpeg[start + 3]);
  const size_t body = header + 29;
  const std::string xmp = edit(jpeg.substr(body, start + 2 + length - body));
  const size_t new_length = 2 + 29 + xmp.size();
  std::string out = jpeg.substr(0, start + 2);
  out += static_cast<char>(new_length >> 8);
  out += static_cast<char>(new_length & 0xFF);
  return out + jpeg.substr(header, 29) + xmp + jpeg.substr(start + 2 + length);
}

std::string Replace(std::string s, const std::string& from, const std::string& to) {
  const size_t at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}

struct Flight {
  testing::TempDir tmp{"aerocal_import_images"};
  std::string dir = tmp.File("flight");
  Flight() {
    fs::create_directories(dir);
    fs::copy_file(kImages + "/dji_constructed.jpg", dir + "/DJI_0001.JPG");
    fs::copy_file(kImages + "/dji_prefix.jpg", dir + "/DJI_0002.JPG");
    WriteFileAtomically(dir + "/flight_log.txt", "not an image\n");
  }
};

TEST(ImportImages, DjiXmpGivesCentresAttitudesSigmasAndTheDewarpCamera) {
  Flight f;
  const std::string bytes = ReadTextFile(kImages + "/dji_constructed.jpg");
  const auto r =
      RunAerocal("import images " + f.dir + " --pixel-size-mm 0.00241 --out " + f.tmp.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("imported 2 exposures, 1 cameras"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("1 files not used (images_not_used.csv): flight_log.txt"),
            std::string::npos)
      << r.output;
  const triangulation::Project p = triangulation::ReadProject(f.tmp.File("out"));
  EXPECT_EQ(p.frame.crs, "EPSG:4326+5773");
  ASSERT_EQ(p.exposures.size(), 2u);
  for (const triangulation::Exposure& e : p.exposures) {
    SCOPED_TRACE(e.image);
    EXPECT_DOUBLE_EQ(e.center_m.x(), XmpValue(bytes, "GpsLongtitude"));
    EXPECT_DOUBLE_EQ(e.center_m.y(), XmpValue(bytes, "GpsLatitude"));
    EXPECT_DOUBLE_EQ(e.center_m.z(), XmpValue(bytes, "AbsoluteAltitude"));
    // yaw -90.10 (west), pitch -80: 10 deg from nadir toward the west, image top to the west.
    const Eigen::Vector3d expected =
        triangulation::OpkOfGimbal(XmpValue(bytes, "GimbalYawDegree"),
                                   XmpValue(bytes, "GimbalPitchDegree"),
                                   XmpValue(bytes, "GimbalRollDegree"));
    EXPECT_LT((e.opk_rad - expected).norm(), 1e-9);  // 8 decimals of degrees in the file
    EXPECT_NEAR(e.opk_rad.z(), 90.10 * kDeg, 0.01 * kDeg);
    EXPECT_NEAR(std::hypot(e.opk_rad.x(), e.opk_rad.y()), 10 * kDeg, 0.01 * kDeg);
    ASSERT_TRUE(e.center_sigma_m);
    EXPECT_NEAR(e.center_sigma_m->x(), XmpValue(bytes, "RtkStdLon"), 1e-4);
    EXPECT_NEAR(e.center_sigma_m->y(), XmpValue(bytes, "RtkStdLat"), 1e-4);
    EXPECT_NEAR(e.center_sigma_m->z(), XmpValue(bytes, "RtkStdHgt"), 1e-4);
    EXPECT_FALSE(e.opk_sigma_rad);
  }
  ASSERT_EQ(p.cameras.size(), 1u);
  const calib::Camera& c = p.cameras.begin()->second;
  EXPECT_EQ(p.cameras.begin()->first, "FIXTURE0001");  // EXIF BodySerialNumber
  const calib::ModelCamera m = c.AsModelCamera();
  EXPECT_EQ(m.model, calib::CameraModelId::kOpenCv);
  EXPECT_DOUBLE_EQ(m.params[0], 3684.48);          // fx of the DewarpData text
  EXPECT_DOUBLE_EQ(m.params[2], 64 / 2.0 + 2.24);  // cx = W / 2 + 2.24
  EXPECT_DOUBLE_EQ(c.pixel_size_mm, 0.00241);
  // Which tag gave which value: the prefix as written in each file.
  const std::string tags = ReadTextFile(f.tmp.File("out/tags.csv"));
  EXPECT_NE(tags.find("DJI_0001.JPG,latitude_deg,XMP drone-dji:GpsLatitude,-8.2942500"),
            std::string::npos)
      << tags;
  EXPECT_NE(tags.find("DJI_0002.JPG,latitude_deg,XMP dji:GpsLatitude,-8.2942500"),
            std::string::npos);
  EXPECT_NE(tags.find("DJI_0001.JPG,capture_time,EXIF DateTimeOriginal,2025:10:02 12:08:47"),
            std::string::npos);
  const std::string not_used = ReadTextFile(f.tmp.File("out/images_not_used.csv"));
  EXPECT_NE(not_used.find("flight_log.txt,not a .jpg/.jpeg/.tif/.tiff file"), std::string::npos)
      << not_used;
}

TEST(ImportImages, ExifGpsWithRefsWhenTheXmpHasNoPosition) {
  Flight f;
  // Without the XMP position the EXIF GPS IFD is used: 8 deg 17' 39.30" S, 115 deg 27' 42.59" E.
  const std::string jpeg =
      WithXmp(ReadTextFile(kImages + "/dji_constructed.jpg"), [](std::string x) {
        x = Replace(x, "drone-dji:GpsLatitude=\"-8.2942500\"", "");
        x = Replace(x, "drone-dji:GpsLongtitude=\"115.4618306\"", "");
        x = Replace(x, "drone-dji:AbsoluteAltitude=\"+1131.876\"", "");
        return Replace(x, "drone-dji:RtkStdLon=\"0.01234\"", "");
      });
  fs::remove(f.dir + "/DJI_0002.JPG");
  WriteFileAtomically(f.dir + "/DJI_0001.JPG", WithXmp(jpeg, [](std::string x) {
                        x = Replace(x, "drone-dji:RtkStdLat=\"0.01456\"", "");
                        return Replace(x, "drone-dji:RtkStdHgt=\"0.02789\"", "");
                      }));
  const auto r = RunAerocal("import images " + f.dir +
                            " --pixel-size-mm 0.00241 --gnss-sigma-m 2,5 "
                            "--attitude-sigma-deg 3 --out " +
                            f.tmp.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const triangulation::Project p = triangulation::ReadProject(f.tmp.File("out"));
  ASSERT_EQ(p.exposures.size(), 1u);
  const triangulation::Exposure& e = p.exposures[0];
  EXPECT_NEAR(e.center_m.y(), -(8 + 17 / 60.0 + 39.30 / 3600), 1e-9);
  EXPECT_NEAR(e.center_m.x(), 115 + 27 / 60.0 + 42.59 / 3600, 1e-9);
  EXPECT_NEAR(e.center_m.z(), 1131.876, 1e-9);
  ASSERT_TRUE(e.center_sigma_m && e.opk_sigma_rad);
  EXPECT_EQ(*e.center_sigma_m, Eigen::Vector3d(2, 2, 5));
  EXPECT_NEAR(e.opk_sigma_rad->x(), 3 * kDeg, 1e-9);
  const std::string tags = ReadTextFile(f.tmp.File("out/tags.csv"));
  EXPECT_NE(tags.find("latitude_deg,EXIF GPSLatitude + EXIF GPSLatitudeRef,8 17 39.3 S"),
            std::string::npos)
      << tags;
}

TEST(ImportImages, CrsTurnsCentresAndAttitudesIntoTheProjection) {
  Flight f;
  const auto r = RunAerocal("import images " + f.dir +
                            " --pixel-size-mm 0.00241 --crs EPSG:32750 --out " + f.tmp.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const triangulation::Project p = triangulation::ReadProject(f.tmp.File("out"));
  EXPECT_EQ(p.frame.crs, "EPSG:32750");
  const triangulation::CrsConverter images({"EPSG:4326+5773", "", "", "test"});
  const triangulation::CrsConverter utm({"EPSG:32750", "", "", "test"});
  const Eigen::Vector3d expected = utm.FromPivot(images.ToPivot({115.4618306, -8.29425, 1131.876}));
  const triangulation::Exposure& e = p.exposures[0];
  EXPECT_LT((e.center_m - expected).norm(), 2e-3);  // the file's digits (mm)
  // Grid north differs from true north by the meridian convergence, about
  // (lon - 117 deg) sin(lat) = +0.222 deg here: kappa turns by it.
  const double gamma_deg = (115.4618306 - 117) * std::sin(-8.29425 * kDeg);
  const Eigen::Vector3d enu = triangulation::OpkOfGimbal(-90.10, -80, 0);
  EXPECT_NEAR(std::abs(e.opk_rad.z() - enu.z()) / kDeg, std::abs(gamma_deg), 0.01);
  // 2D UTM takes ellipsoidal heights: the EGM96 undulation at Bali (tens of metres) was added.
  EXPECT_GT(std::abs(e.center_m.z() - 1131.876), 1.0);
  EXPECT_LT(std::abs(e.center_m.z() - 1131.876), 100.0);
}

TEST(ImportImages, BrokenMetadataIsExitTwoNamingTheFileAndWritesNothing) {
  const std::string good = ReadTextFile(kImages + "/dji_constructed.jpg");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {good.substr(0, good.size() / 2), "DJI_0001.JPG: truncated JPEG"},
      {WithXmp(good,
               [](std::string x) {
                 return Replace(x,
                                "<drone-dji:DewarpData>",
                                "<drone-dji:RtkFlag>16</drone-dji:RtkFlag><drone-dji:DewarpData>");
               }),
       "XMP property drone-dji:RtkFlag"},
      {WithXmp(good,
               [](std::string x) {
                 return Replace(x, "GpsLatitude=\"-8.2942500\"", "GpsLatitude=\"south\"");
               }),
       "drone-dji:GpsLatitude is not a number (got 'south')"},
      {WithXmp(good,
               [](std::string x) {
                 return Replace(x, "GpsLatitude=\"-8.2942500\"", "GpsLatitude=\"-98.1\"");
               }),
       "latitude -98.1 is beyond 90 deg"},
      {WithXmp(
           good,
           [](std::string x) { return Replace(x, "RtkStdLat=\"0.01456\"", "RtkStdLat=\"0\""); }),
       "RTK standard deviation 0 m must be in (0, 1e6]"},
      {WithXmp(good, [](std::string x) { return Replace(x, "xmlns:drone-dji", "xmlns:other"); }),
       "namespace prefix 'drone-dji'"},
  };
  for (const auto& [bytes, message] : cases) {
    SCOPED_TRACE(message);
    testing::TempDir tmp("aerocal_import_images_bad");
    fs::create_directories(tmp.File("flight"));
    WriteFileAtomically(tmp.File("flight/DJI_0001.JPG"), bytes);
    const auto r = RunAerocal("import images " + tmp.File("flight") +
                              " --pixel-size-mm 0.00241 --out " + tmp.File("out"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(tmp.File("out")));
  }
}

TEST(ImportImages, NoUsableImageIsExitTwoNamingEachFile) {
  testing::TempDir tmp("aerocal_import_images_none");
  fs::create_directories(tmp.File("flight"));
  const std::string good = ReadTextFile(kImages + "/dji_constructed.jpg");
  WriteFileAtomically(tmp.File("flight/zero.jpg"), WithXmp(good, [](std::string x) {
                        x = Replace(x, "GpsLatitude=\"-8.2942500\"", "GpsLatitude=\"0\"");
                        return Replace(x, "GpsLongtitude=\"115.4618306\"", "GpsLongtitude=\"0\"");
                      }));
  const auto r = RunAerocal("import images " + tmp.File("flight") + " --out " + tmp.File("out"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("zero.jpg: GPS position 0, 0 (the receiver had no fix)"),
            std::string::npos)
      << r.output;
}

TEST(ImportImages, EveryOptionRefusesBadValuesByName) {
  Flight f;
  for (const auto& [option, name] : std::vector<std::pair<std::string, std::string>>{
           {"--gnss-sigma-m 0,1", "--gnss-sigma-m"},
           {"--gnss-sigma-m nan,1", "--gnss-sigma-m"},
           {"--gnss-sigma-m 1", "--gnss-sigma-m"},
           {"--attitude-sigma-deg -1", "--attitude-sigma-deg"},
           {"--attitude-sigma-deg inf", "--attitude-sigma-deg"},
           {"--pixel-size-mm 0", "--pixel-size-mm"},
           {"--pixel-size-mm 1e308", "--pixel-size-mm"},
           {"--heights geoid", "--heights"},
           {"--crs EPSG:999999", "EPSG:999999"}}) {
    SCOPED_TRACE(option);
    const auto r =
        RunAerocal("import images " + f.dir + " " + option + " --out " + f.tmp.File("out"));
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(f.tmp.File("out")));
  }
  const auto r =
      RunAerocal("import images " + f.tmp.File("missing") + " --out " + f.tmp.File("out"));
  EXPECT_EQ(r.exit_code, 2) << r.output;
  EXPECT_NE(r.output.find("missing: not a folder"), std::string::npos) << r.output;
}

TEST(ImportImages, RealCanonJpegWithoutGpsIsNamedNotUsed) {
  const std::string data = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (data.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  Flight f;
  fs::copy_file(data + "/images/img_4880.jpg", f.dir + "/img_4880.jpg");
  const auto r =
      RunAerocal("import images " + f.dir + " --pixel-size-mm 0.00241 --out " + f.tmp.File("out"));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(
      ReadTextFile(f.tmp.File("out/images_not_used.csv")).find("img_4880.jpg,no GPS position"),
      std::string::npos);
}

}  // namespace
}  // namespace aerocal
