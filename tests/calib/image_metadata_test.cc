// calib/metadata: the XMP packet by namespace URI, the bounded TIFF-IFD reader and the JPEG walk,
// on the metadata-only DJI fixtures (tests/data/images), a real Canon JPEG (../shared/data) and
// bytes built here to break one rule each (truncation, IFD loops, huge counts, duplicates).
#include "calib/metadata/image_metadata.h"

#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/error.h"
#include "tests/support/test_support.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace aerocal::calib {
namespace {

const std::string kImages = std::string(AEROCAL_TEST_DATA_DIR) + "/images";

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string Packet(const std::string& description) {
  return "<x:xmpmeta xmlns:x=\"adobe:ns:meta/\">\n<rdf:RDF "
         "xmlns:rdf=\"http://www.w3.org/1999/02/22-rdf-syntax-ns#\">\n" +
         description + "\n</rdf:RDF>\n</x:xmpmeta>\n";
}

TEST(XmpPacket, PropertiesAreFoundByNamespaceUriWhateverThePrefix) {
  for (const char* prefix : {"drone-dji", "dji", "x1"}) {
    const std::string p = prefix;
    const XmpPacket packet = XmpPacket::Parse(
        Packet("<rdf:Description xmlns:" + p + "=\"http://www.dji.com/drone-dji/1.0/\" " + p +
               ":GpsLatitude=\" +46.5 \">\n<" + p + ":DewarpData>1,2</" + p +
               ":DewarpData>\n</rdf:Description>"),
        {"a.xmp", 1});
    ASSERT_NE(packet.Find(xmp_ns::kDji, "GpsLatitude"), nullptr) << prefix;
    EXPECT_EQ(packet.Text(xmp_ns::kDji, "GpsLatitude"), "+46.5");
    EXPECT_EQ(packet.Find(xmp_ns::kDji, "GpsLatitude")->qualified, p + ":GpsLatitude");
    EXPECT_EQ(packet.Find(xmp_ns::kDji, "DewarpData")->where.line, 4);
  }
  // The prefix "drone-dji" bound to another URI is not DJI's namespace.
  const XmpPacket other =
      XmpPacket::Parse(Packet("<rdf:Description xmlns:drone-dji=\"http://example.com/other/\" "
                              "drone-dji:GpsLatitude=\"1\"/>"),
                       {"b.xmp", 1});
  EXPECT_EQ(other.Find(xmp_ns::kDji, "GpsLatitude"), nullptr);
  EXPECT_NE(other.Find("http://example.com/other", "GpsLatitude"),
            nullptr);  // trailing '/' ignored
}

TEST(XmpPacket, BrokenPacketsAreErrorsWithTheirLine) {
  const std::string dji = "xmlns:d=\"http://www.dji.com/drone-dji/1.0/\"";
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(
                  Packet("<rdf:Description " + dji +
                         " d:RtkFlag=\"50\">\n<d:RtkFlag>16</d:RtkFlag>\n</rdf:Description>"),
                  {"dup.xmp", 1});
            }).find("dup.xmp:4: XMP property d:RtkFlag"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(
                  Packet("<rdf:Description " + dji + " d:RtkFlag=\"50\"/>\n<rdf:Description " +
                         dji + " d:RtkFlag=\"50\"/>"),
                  {"two.xmp", 1});
            }).find("given twice (first at two.xmp:3)"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(Packet("<rdf:Description q:A=\"1\"/>"), {"ns.xmp", 1});
            }).find("ns.xmp:3: namespace prefix 'q'"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(
                  Packet("<rdf:Description " + dji + ">\n<d:A>1</d:B>\n</rdf:Description>"),
                  {"bad.xmp", 1});
            }).find("bad.xmp:4: XMP packet is not well-formed XML"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(Packet("") + Packet(""), {"twice.xmp", 1});
            }).find("twice.xmp"),
            std::string::npos);
  // In a binary file the line is counted in the packet.
  EXPECT_NE(ErrorOf([&] {
              XmpPacket::Parse(Packet("<rdf:Description q:A=\"1\"/>"), {"a.jpg", 0});
            }).find("a.jpg: XMP line 3:"),
            std::string::npos);
}

// ---- TIFF IFDs ----

void Put16(std::string* s, size_t at, uint16_t v) { (*s)[at] = v & 0xFF, (*s)[at + 1] = v >> 8; }
void Put32(std::string* s, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) (*s)[at + i] = (v >> (8 * i)) & 0xFF;
}

// Little-endian TIFF with IFD0 at 8 holding `entries` (tag, type, count, value) and nothing else.
std::string Tiff(const std::vector<std::array<uint32_t, 4>>& entries, size_t extra = 64) {
  std::string t(8 + 2 + 12 * entries.size() + 4 + extra, '\0');
  t.replace(0, 4, std::string("II*\0", 4));
  Put32(&t, 4, 8);
  Put16(&t, 8, static_cast<uint16_t>(entries.size()));
  for (size_t k = 0; k < entries.size(); ++k) {
    const size_t e = 10 + 12 * k;
    Put16(&t, e, entries[k][0]);
    Put16(&t, e + 2, entries[k][1]);
    Put32(&t, e + 4, entries[k][2]);
    Put32(&t, e + 8, entries[k][3]);
  }
  return t;
}

TEST(TiffTags, BoundedAgainstLoopsHugeCountsAndDuplicates) {
  // Make "Ab" (ASCII, 3 bytes in the entry), ImageWidth 640.
  const TiffTags ok = ReadTiffTags(Tiff({{0x010F, 2, 3, 0x6241}, {0x0100, 3, 1, 640}}), "ok");
  EXPECT_EQ(ok.at({TiffIfd::kImage, 0x010F}).text, "Ab");
  EXPECT_EQ(ok.at({TiffIfd::kImage, 0x0100}).numbers, std::vector<double>{640});
  // The Exif IFD pointer points back at IFD0: a loop.
  EXPECT_NE(ErrorOf([] {
              ReadTiffTags(Tiff({{0x8769, 4, 1, 8}}), "loop");
            }).find("loop: IFD loop"),
            std::string::npos);
  // 0x40000000 rationals: 8 GB claimed in a 100-byte structure.
  EXPECT_NE(ErrorOf([] {
              ReadTiffTags(Tiff({{0x010F, 5, 0x40000000, 20}}), "huge");
            }).find("run past the end"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ReadTiffTags(Tiff({{0x010F, 5, 0xFFFFFFFF, 0xFFFFFFF0}}), "wrap");
            }).find("run past the end"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ReadTiffTags(Tiff({{0x0100, 3, 1, 1}, {0x0100, 3, 1, 2}}), "dup");
            }).find("EXIF ImageWidth is given twice"),
            std::string::npos);
  std::string many = Tiff({});
  Put16(&many, 8, 60000);
  EXPECT_NE(ErrorOf([&] { ReadTiffTags(many, "many"); }).find("claims 60000 entries"),
            std::string::npos);
  EXPECT_NE(ErrorOf([] {
              ReadTiffTags(std::string("II*\0\xFF\xFF\xFF\x00", 8), "far");
            }).find("outside the data"),
            std::string::npos);
  // Every prefix of a valid structure is refused or read, never read out of bounds (ASan job).
  const std::string full = Tiff({{0x010F, 2, 3, 0x6241}, {0x8825, 4, 1, 8}});
  for (size_t n = 0; n < full.size(); ++n) {
    try {
      ReadTiffTags(full.substr(0, n), "prefix");
    } catch (const InputError&) {
    }
  }
}

// ---- JPEG ----

std::string Fixture(const std::string& name) { return ReadTextFile(kImages + "/" + name); }

TEST(ImageMetadata, MetadataOnlyDjiJpegGivesItsTagsAndSize) {
  const ImageMetadata m =
      ImageMetadataOfBytes(Fixture("dji_constructed.jpg"), "dji_constructed.jpg");
  EXPECT_EQ(m.format, "jpeg");
  EXPECT_EQ(m.width_px, 64);
  EXPECT_EQ(m.height_px, 48);
  EXPECT_EQ(m.exif.at({TiffIfd::kImage, 0x010F}).text, "DJI");
  EXPECT_EQ(m.exif.at({TiffIfd::kGps, 0x0002}).numbers, (std::vector<double>{8, 17, 39.30}));
  EXPECT_EQ(m.exif.at({TiffIfd::kGps, 0x0001}).text, "S");
  ASSERT_TRUE(m.xmp);
  EXPECT_EQ(m.xmp->Text(xmp_ns::kDji, "GpsLongtitude"), "115.4618306");
}

TEST(ImageMetadata, TruncatedOrDoubledJpegsAreErrorsNamingTheFile) {
  const std::string jpeg = Fixture("dji_constructed.jpg");
  // Every truncation: an InputError naming the file (a cut in the entropy-coded data lacks EOI).
  for (size_t n = 0; n + 1 < jpeg.size(); ++n) {
    const std::string e = ErrorOf([&] { ImageMetadataOfBytes(jpeg.substr(0, n), "cut.jpg"); });
    ASSERT_EQ(e.rfind("cut.jpg", 0), 0u) << n << ": " << e;
  }
  // A second copy of the XMP APP1 segment.
  const size_t xmp = jpeg.find("http://ns.adobe.com/xap/1.0/");
  const size_t start = xmp - 4;
  const size_t length = (static_cast<unsigned char>(jpeg[start + 2]) << 8) |
                        static_cast<unsigned char>(jpeg[start + 3]);
  const std::string doubled = jpeg.substr(0, start + 2 + length) + jpeg.substr(start, 2 + length) +
                              jpeg.substr(start + 2 + length);
  EXPECT_NE(
      ErrorOf([&] { ImageMetadataOfBytes(doubled, "two.jpg"); }).find("two.jpg: two XMP packets"),
      std::string::npos);
  EXPECT_NE(
      ErrorOf([&] { ImageMetadataOfBytes("GIF89a", "x.gif"); }).find("neither a JPEG nor a TIFF"),
      std::string::npos);
}

TEST(ImageMetadata, RealCanonJpegGivesMakeModelAndSize) {
  const std::string dir = testing::SharedDataDir("odm_boruszyn_kap_frames");
  if (dir.empty()) GTEST_SKIP() << "../shared/data/odm_boruszyn_kap_frames is absent";
  const ImageMetadata m = ReadImageMetadata(dir + "/images/img_4880.jpg");
  // PROVENANCE.md: Canon PowerShot A3300 IS, 4608 x 3456 px, f = 5.0 mm; no GPS.
  EXPECT_EQ(m.width_px, 4608);
  EXPECT_EQ(m.height_px, 3456);
  EXPECT_EQ(m.exif.at({TiffIfd::kImage, 0x010F}).text, "Canon");
  EXPECT_EQ(m.exif.at({TiffIfd::kImage, 0x0110}).text, "Canon PowerShot A3300 IS");
  EXPECT_NEAR(m.exif.at({TiffIfd::kExif, 0x920A}).numbers.at(0), 5.0, 1e-9);
  EXPECT_EQ(m.exif.count({TiffIfd::kGps, 0x0002}), 0u);
}

TEST(ImageMetadata, TiffFileGivesItsSizeFromIfd0) {
  const std::string tiff =
      ReadTextFile(std::string(AEROCAL_TEST_DATA_DIR) + "/../fuzz/seeds/image_metadata/tiny.tif");
  const ImageMetadata m = ImageMetadataOfBytes(tiff, "tiny.tif");
  EXPECT_EQ(m.format, "tiff");
  EXPECT_EQ(m.width_px, 4);
  EXPECT_EQ(m.height_px, 4);
}

// ---- the camera readers (issue 37 class 9): prefixes by namespace URI ----

TEST(CameraXmp, DjiDewarpDataIsReadByNamespaceUriNotPrefix) {
  CameraReadOptions options;
  const CameraFile a = ReadDjiDewarpData(kImages + "/dji_constructed.jpg", options);
  const CameraFile b = ReadDjiDewarpData(kImages + "/dji_prefix.jpg", options);  // prefix "dji:"
  EXPECT_EQ(a.camera.params, b.camera.params);
  EXPECT_EQ(a.camera.params[OpenCvModel::kFx], 3684.48);
  EXPECT_EQ(a.camera.params[OpenCvModel::kCx], 32 + 2.24);  // W / 2 + cx of the 64 x 48 image
  EXPECT_EQ(a.name, "2018-09-06");
  // A sidecar whose drone-dji prefix names another namespace holds no DJI DewarpData.
  testing::TempDir dir("aerocal_xmp_ns");
  WriteFileAtomically(dir.File("other.xmp"),
                      Packet("<rdf:Description xmlns:drone-dji=\"http://example.com/not-dji/\" "
                             "drone-dji:DewarpData=\"1,1,0,0,0,0,0,0,0\"/>"));
  options.width_px = 100, options.height_px = 100;
  EXPECT_NE(ErrorOf([&] {
              ReadDjiDewarpData(dir.File("other.xmp"), options);
            }).find("no DewarpData of namespace"),
            std::string::npos);
  // Two packets in one sidecar, a duplicated DewarpData: errors naming the file.
  WriteFileAtomically(dir.File("two.xmp"), Packet("") + Packet(""));
  EXPECT_NE(ErrorOf([&] {
              ReadDjiDewarpData(dir.File("two.xmp"), options);
            }).find("two.xmp: two XMP packets"),
            std::string::npos);
  WriteFileAtomically(dir.File("dup.xmp"),
                      Packet("<rdf:Description xmlns:d=\"http://www.dji.com/drone-dji/1.0/\" "
                             "d:DewarpData=\"1,1,0,0,0,0,0,0,0\">\n"
                             "<d:DewarpData>2,2,0,0,0,0,0,0,0</d:DewarpData></rdf:Description>"));
  EXPECT_NE(ErrorOf([&] {
              ReadDjiDewarpData(dir.File("dup.xmp"), options);
            }).find("dup.xmp:4: XMP property d:DewarpData"),
            std::string::npos);
}

TEST(CameraXmp, Pix4dTagsUnderAnotherNamespaceAreNotPix4ds) {
  testing::TempDir dir("aerocal_pix4d_ns");
  // "Camera" is bound to another URI; P4 is Pix4D's: only the P4 values count.
  WriteFileAtomically(dir.File("p.xmp"),
                      Packet("<rdf:Description xmlns:Camera=\"http://example.com/camera/\" "
                             "xmlns:P4=\"http://pix4d.com/camera/1.0\">\n"
                             "<Camera:PerspectiveFocalLength>99</Camera:PerspectiveFocalLength>\n"
                             "<P4:PerspectiveFocalLength>4.5</P4:PerspectiveFocalLength>\n"
                             "<P4:PrincipalPoint>2.4,1.8</P4:PrincipalPoint>\n</rdf:Description>"));
  CameraReadOptions options;
  options.width_px = 4000, options.height_px = 3000, options.pixel_size_mm = 0.0012;
  EXPECT_EQ(ReadPix4dXmp(dir.File("p.xmp"), options).camera.params[Pix4dPerspectiveModel::kF], 4.5);
  WriteFileAtomically(
      dir.File("q.xmp"),
      Packet("<rdf:Description xmlns:Camera=\"http://example.com/camera/\">\n"
             "<Camera:PerspectiveFocalLength>99</Camera:PerspectiveFocalLength>\n"
             "<Camera:PrincipalPoint>2.4,1.8</Camera:PrincipalPoint>\n</rdf:Description>"));
  EXPECT_NE(
      ErrorOf([&] { ReadPix4dXmp(dir.File("q.xmp"), options); }).find("no PerspectiveFocalLength"),
      std::string::npos);
}

}  // namespace
}  // namespace aerocal::calib
