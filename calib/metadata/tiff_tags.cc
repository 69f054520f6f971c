#include "calib/metadata/tiff_tags.h"

#include "calib/core/error.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>

namespace aerocal::calib {
namespace {

constexpr uint16_t kExifIfdPointer = 0x8769;
constexpr uint16_t kGpsIfdPointer = 0x8825;

// Bytes per value of each TIFF field type; 0 for unknown types.
int TypeSize(int type) {
  switch (type) {
    case 1:
    case 2:
    case 6:
    case 7:
      return 1;  // BYTE, ASCII, SBYTE, UNDEFINED
    case 3:
    case 8:
      return 2;  // SHORT, SSHORT
    case 4:
    case 9:
    case 11:
    case 13:
      return 4;  // LONG, SLONG, FLOAT, IFD
    case 5:
    case 10:
    case 12:
      return 8;  // RATIONAL, SRATIONAL, DOUBLE
    default:
      return 0;
  }
}

class TiffReader {
 public:
  TiffReader(const std::string& data, const std::string& where) : d_(data), where_(where) {
    if (d_.size() < 8 || !(d_.compare(0, 4, "II*\0", 4) == 0 || d_.compare(0, 4, "MM\0*", 4) == 0))
      Fail("not a TIFF structure (no II*/MM* header)");
    little_ = d_[0] == 'I';
  }

  TiffTags Read() {
    ReadIfd(U32(4), TiffIfd::kImage);
    return tags_;
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + ": " + what); }

  uint64_t U(uint64_t at, int bytes) const {
    if (at + bytes > d_.size()) Fail("value at byte " + std::to_string(at) + " past the end");
    uint64_t v = 0;
    for (int i = 0; i < bytes; ++i) {
      const uint64_t b = static_cast<unsigned char>(d_[at + i]);
      v |= little_ ? b << (8 * i) : b << (8 * (bytes - 1 - i));
    }
    return v;
  }
  uint32_t U32(uint64_t at) const { return static_cast<uint32_t>(U(at, 4)); }
  uint16_t U16(uint64_t at) const { return static_cast<uint16_t>(U(at, 2)); }

  double Number(int type, uint64_t at) const {
    switch (type) {
      case 1:
      case 7:
        return static_cast<double>(U(at, 1));
      case 6:
        return static_cast<int8_t>(U(at, 1));
      case 3:
        return U16(at);
      case 8:
        return static_cast<int16_t>(U16(at));
      case 4:
      case 13:
        return U32(at);
      case 9:
        return static_cast<int32_t>(U32(at));
      case 5: {
        const double den = U32(at + 4);
        return den == 0 ? NAN : U32(at) / den;
      }
      case 10: {
        const double den = static_cast<int32_t>(U32(at + 4));
        return den == 0 ? NAN : static_cast<int32_t>(U32(at)) / den;
      }
      case 11: {
        const uint32_t bits = U32(at);
        float f;
        std::memcpy(&f, &bits, 4);
        return f;
      }
      case 12: {
        const uint64_t bits = U(at, 8);
        double v;
        std::memcpy(&v, &bits, 8);
        return v;
      }
      default:
        return NAN;
    }
  }

  void ReadIfd(uint64_t offset, TiffIfd ifd) {
    if (!visited_.insert(offset).second)
      Fail("IFD loop: the IFD at byte " + std::to_string(offset) + " is pointed to twice");
    if (offset < 8 || offset + 2 > d_.size())
      Fail("IFD offset " + std::to_string(offset) + " outside the data");
    const int n = U16(offset);
    if (n > kMaxIfdEntries)
      Fail("IFD at byte " + std::to_string(offset) + " claims " + std::to_string(n) +
           " entries (at most " + std::to_string(kMaxIfdEntries) + ")");
    if (offset + 2 + 12ull * n > d_.size())
      Fail("IFD at byte " + std::to_string(offset) + " runs past the end");
    std::set<uint16_t> seen;
    for (int k = 0; k < n; ++k) {
      const uint64_t e = offset + 2 + 12ull * k;
      const uint16_t tag = U16(e);
      const int type = U16(e + 2);
      const uint32_t count = U32(e + 4);
      if (!seen.insert(tag).second) Fail(TiffTagName(ifd, tag) + " is given twice in one IFD");
      const int size = TypeSize(type);
      if (size == 0) continue;  // unknown type: ignored (TIFF 6.0)
      const uint64_t bytes = static_cast<uint64_t>(count) * size;
      const uint64_t at = bytes <= 4 ? e + 8 : U32(e + 8);
      if (at + bytes > d_.size())
        Fail(TiffTagName(ifd, tag) + ": " + std::to_string(count) + " values at byte " +
             std::to_string(at) + " run past the end");
      if (ifd == TiffIfd::kImage && (tag == kExifIfdPointer || tag == kGpsIfdPointer)) {
        if (count != 1 || (type != 4 && type != 13))
          Fail(TiffTagName(ifd, tag) + " is not one offset");
        pointers_.emplace_back(U32(at), tag == kExifIfdPointer ? TiffIfd::kExif : TiffIfd::kGps);
        continue;
      }
      TiffEntry entry;
      entry.type = type;
      entry.count = count;
      if (type == 2 || type == 1 || type == 7) {
        entry.text = d_.substr(at, bytes);
        if (type == 2) entry.text = entry.text.substr(0, entry.text.find('\0'));
      }
      if (type != 2)
        for (uint32_t i = 0; i < count && i < static_cast<uint32_t>(kMaxNumbers); ++i)
          entry.numbers.push_back(Number(type, at + static_cast<uint64_t>(i) * size));
      tags_[{ifd, tag}] = std::move(entry);
    }
    if (ifd == TiffIfd::kImage) {
      const auto pointers = pointers_;
      for (const auto& [sub, kind] : pointers) ReadIfd(sub, kind);
    }
  }

  const std::string& d_;
  const std::string where_;
  bool little_ = true;
  std::set<uint64_t> visited_;
  std::vector<std::pair<uint64_t, TiffIfd>> pointers_;
  TiffTags tags_;
};

}  // namespace

TiffTags ReadTiffTags(const std::string& tiff, const std::string& where) {
  return TiffReader(tiff, where).Read();
}

std::string TiffTagName(TiffIfd ifd, uint16_t tag) {
  static const std::map<std::pair<TiffIfd, uint16_t>, const char*> kNames = {
      {{TiffIfd::kImage, 0x0100}, "ImageWidth"},
      {{TiffIfd::kImage, 0x0101}, "ImageLength"},
      {{TiffIfd::kImage, 0x010F}, "Make"},
      {{TiffIfd::kImage, 0x0110}, "Model"},
      {{TiffIfd::kImage, 0x0132}, "DateTime"},
      {{TiffIfd::kImage, 0x02BC}, "XMLPacket"},
      {{TiffIfd::kImage, 0x8769}, "ExifIFDPointer"},
      {{TiffIfd::kImage, 0x8825}, "GPSInfoIFDPointer"},
      {{TiffIfd::kExif, 0x9003}, "DateTimeOriginal"},
      {{TiffIfd::kExif, 0x9011}, "OffsetTimeOriginal"},
      {{TiffIfd::kExif, 0x9291}, "SubSecTimeOriginal"},
      {{TiffIfd::kExif, 0x920A}, "FocalLength"},
      {{TiffIfd::kExif, 0xA002}, "PixelXDimension"},
      {{TiffIfd::kExif, 0xA003}, "PixelYDimension"},
      {{TiffIfd::kExif, 0xA20E}, "FocalPlaneXResolution"},
      {{TiffIfd::kExif, 0xA20F}, "FocalPlaneYResolution"},
      {{TiffIfd::kExif, 0xA210}, "FocalPlaneResolutionUnit"},
      {{TiffIfd::kExif, 0xA405}, "FocalLengthIn35mmFilm"},
      {{TiffIfd::kExif, 0xA431}, "BodySerialNumber"},
      {{TiffIfd::kGps, 0x0001}, "GPSLatitudeRef"},
      {{TiffIfd::kGps, 0x0002}, "GPSLatitude"},
      {{TiffIfd::kGps, 0x0003}, "GPSLongitudeRef"},
      {{TiffIfd::kGps, 0x0004}, "GPSLongitude"},
      {{TiffIfd::kGps, 0x0005}, "GPSAltitudeRef"},
      {{TiffIfd::kGps, 0x0006}, "GPSAltitude"},
      {{TiffIfd::kGps, 0x0012}, "GPSMapDatum"},
  };
  const auto it = kNames.find({ifd, tag});
  if (it != kNames.end()) return std::string("EXIF ") + it->second;
  char hex[8];
  std::snprintf(hex, sizeof(hex), "0x%04X", tag);
  const char* group = ifd == TiffIfd::kImage  ? "IFD0"
                      : ifd == TiffIfd::kExif ? "Exif IFD"
                                              : "GPS IFD";
  return std::string("EXIF ") + group + " tag " + hex;
}

}  // namespace aerocal::calib
