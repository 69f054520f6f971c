#include "calib/metadata/image_metadata.h"

#include "calib/core/atomic_file.h"
#include "calib/core/error.h"

#include <cstdio>

namespace aerocal::calib {
namespace {

const std::string kExifHeader("Exif\0\0", 6);
const std::string kXmpHeader("http://ns.adobe.com/xap/1.0/\0", 29);
const std::string kExtendedXmpHeader("http://ns.adobe.com/xmp/extension/\0", 35);

std::string Hex(unsigned v) {
  char s[8];
  std::snprintf(s, sizeof(s), "0x%02X", v);
  return s;
}

bool IsSof(unsigned marker) {
  return marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
}

ImageMetadata ReadJpeg(const std::string& b, const std::string& path) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(b[i]); };
  const auto fail = [&](const std::string& what) -> void { throw InputError(path + ": " + what); };
  ImageMetadata m;
  m.format = "jpeg";
  std::string exif, xmp;
  int extended = 0;
  bool sof = false;
  size_t i = 2;
  for (;;) {
    if (i >= b.size()) fail("truncated JPEG: the file ends before the image data (no SOS marker)");
    if (byte(i) != 0xFF) fail("not a JPEG marker at byte " + std::to_string(i));
    while (i < b.size() && byte(i) == 0xFF) ++i;  // fill bytes
    if (i >= b.size()) fail("truncated JPEG: the file ends in a marker");
    const unsigned marker = byte(i++);
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
    if (marker == 0xD9) fail("JPEG without image data (EOI before SOS)");
    if (i + 2 > b.size())
      fail("truncated JPEG: segment " + Hex(marker) + " at byte " + std::to_string(i - 2));
    const size_t length = (byte(i) << 8) | byte(i + 1);
    if (length < 2 || i + length > b.size())
      fail("truncated JPEG: segment " + Hex(marker) + " at byte " + std::to_string(i - 2) +
           " of length " + std::to_string(length) + " runs past the end (" +
           std::to_string(b.size()) + " bytes)");
    const std::string payload = b.substr(i + 2, length - 2);
    if (marker == 0xE1 && payload.compare(0, kExifHeader.size(), kExifHeader) == 0) {
      if (!exif.empty()) fail("two EXIF (APP1) segments");
      exif = payload.substr(kExifHeader.size());
      if (exif.empty()) fail("empty EXIF segment");
    } else if (marker == 0xE1 && payload.compare(0, kXmpHeader.size(), kXmpHeader) == 0) {
      if (!xmp.empty())
        fail("two XMP packets (APP1 segments): which one holds the image's values is not defined");
      xmp = payload.substr(kXmpHeader.size());
      if (xmp.empty()) fail("empty XMP segment");
    } else if (marker == 0xE1 &&
               payload.compare(0, kExtendedXmpHeader.size(), kExtendedXmpHeader) == 0) {
      ++extended;
    } else if (IsSof(marker)) {
      if (sof) fail("two SOF markers");
      if (payload.size() < 5) fail("SOF segment too short");
      m.height_px = (byte(i + 3) << 8) | byte(i + 4);
      m.width_px = (byte(i + 5) << 8) | byte(i + 6);
      if (m.width_px == 0 || m.height_px == 0) fail("SOF gives an image size of zero");
      sof = true;
    } else if (marker == 0xDA) {
      if (!sof) fail("no SOF marker before the image data");
      if (b.rfind("\xFF\xD9") == std::string::npos || b.rfind("\xFF\xD9") < i + length)
        fail("truncated JPEG: no EOI marker after the image data");
      break;
    }
    i += length;
  }
  if (!exif.empty()) m.exif = ReadTiffTags(exif, path + ": EXIF");
  if (!xmp.empty()) m.xmp = XmpPacket::Parse(xmp, {path, 0});
  if (extended > 0)
    m.notes.push_back(std::to_string(extended) + " extended XMP segment(s) not read");
  return m;
}

ImageMetadata ReadTiff(const std::string& b, const std::string& path) {
  ImageMetadata m;
  m.format = "tiff";
  m.exif = ReadTiffTags(b, path);
  const auto size = [&](uint16_t tag) {
    const auto it = m.exif.find({TiffIfd::kImage, tag});
    if (it == m.exif.end() || it->second.numbers.size() != 1 ||
        !(it->second.numbers[0] >= 1 && it->second.numbers[0] <= 1e6))
      throw InputError(path + ": TIFF without a valid " + TiffTagName(TiffIfd::kImage, tag));
    return static_cast<int>(it->second.numbers[0]);
  };
  m.width_px = size(0x0100);
  m.height_px = size(0x0101);
  const auto xmp = m.exif.find({TiffIfd::kImage, 0x02BC});
  if (xmp != m.exif.end()) m.xmp = XmpPacket::Parse(xmp->second.text, {path, 0});
  return m;
}

}  // namespace

bool IsJpegOrTiff(const std::string& bytes) {
  return (bytes.size() >= 3 && bytes.compare(0, 3, "\xFF\xD8\xFF") == 0) ||
         (bytes.size() >= 4 &&
          (bytes.compare(0, 4, "II*\0", 4) == 0 || bytes.compare(0, 4, "MM\0*", 4) == 0));
}

ImageMetadata ImageMetadataOfBytes(const std::string& bytes, const std::string& path) {
  if (bytes.size() >= 3 && bytes.compare(0, 3, "\xFF\xD8\xFF") == 0) return ReadJpeg(bytes, path);
  if (IsJpegOrTiff(bytes)) return ReadTiff(bytes, path);
  throw InputError(path + ": neither a JPEG nor a TIFF file");
}

ImageMetadata ReadImageMetadata(const std::string& path) {
  return ImageMetadataOfBytes(ReadTextFile(path), path);
}

std::optional<XmpPacket> XmpOfCameraFile(const std::string& bytes,
                                         const std::string& path,
                                         int* width_px,
                                         int* height_px) {
  if (IsJpegOrTiff(bytes)) {
    const ImageMetadata m = ImageMetadataOfBytes(bytes, path);
    *width_px = m.width_px;
    *height_px = m.height_px;
    if (!m.xmp) throw InputError(path + ": the image holds no XMP packet");
    return m.xmp;
  }
  const size_t first = bytes.find("<x:xmpmeta");
  if (first != std::string::npos && bytes.find("<x:xmpmeta", first + 1) != std::string::npos)
    throw InputError(path + ": two XMP packets (x:xmpmeta) in one file");
  if (first == std::string::npos && bytes.find("<rdf:RDF") == std::string::npos)
    return std::nullopt;
  return XmpPacket::Parse(bytes, {path, 1});
}

}  // namespace aerocal::calib
