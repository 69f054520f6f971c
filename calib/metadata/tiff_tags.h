// A small, bounded reader of TIFF image file directories (TIFF 6.0 section 2; EXIF 2.32
// section 4.6): the tags of IFD0 and of the EXIF and GPS sub-IFDs it points to, as a JPEG's APP1
// "Exif" segment or a TIFF file holds them. No dependency: OpenCV decodes EXIF only for the
// orientation and exposes no GPS tags.
//
// Bounds (every one an InputError naming `where`): the header must be "II*\0" or "MM\0*"; an IFD
// must lie inside the data with at most kMaxIfdEntries entries; every value must lie inside the
// data (sizes computed in 64 bits, so a count of 4e9 cannot wrap); a sub-IFD pointer to an IFD
// already read is a loop; a tag twice in one IFD is an error, never resolved by taking the first.
// Only IFD0 and its EXIF / GPS sub-IFDs are read (the thumbnail's IFD1 and maker notes are not).
// Entries of an unknown type are skipped (TIFF 6.0: readers ignore them). Numeric values are kept
// up to kMaxNumbers per tag; text up to the first NUL.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::calib {

enum class TiffIfd { kImage, kExif, kGps };

struct TiffEntry {
  int type = 0;  // TIFF field type (2 ASCII, 3 SHORT, 5 RATIONAL, ...)
  uint32_t count = 0;
  std::vector<double> numbers;  // numeric types; RATIONAL as numerator / denominator
  std::string text;             // ASCII up to the first NUL; BYTE / UNDEFINED as raw bytes
};

using TiffTags = std::map<std::pair<TiffIfd, uint16_t>, TiffEntry>;

inline constexpr int kMaxIfdEntries = 1000;
inline constexpr int kMaxNumbers = 64;

/// The tags of `tiff` (a TIFF structure starting with its byte-order header). `where` names the
/// source in messages ("a.jpg: EXIF").
TiffTags ReadTiffTags(const std::string& tiff, const std::string& where);

/// "TIFF tag 0x8825" / the name of the tags aerocal reads ("GPSLatitude").
std::string TiffTagName(TiffIfd ifd, uint16_t tag);

}  // namespace aerocal::calib
