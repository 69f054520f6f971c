// The metadata of a JPEG or TIFF image file: the image size from the image data, the EXIF tags
// (tiff_tags.h) and the XMP packet (xmp_packet.h), read without decoding the image.
//
// JPEG (ITU-T T.81 annex B; EXIF 2.32 section 4.5.4; XMP part 3 section 1.1.3): the markers are
// walked from SOI to SOS, every segment length checked against the file; APP1 "Exif\0\0" holds
// the TIFF structure, APP1 "http://ns.adobe.com/xap/1.0/\0" the XMP packet; the size comes from
// the SOF marker. Two EXIF segments or two standard XMP packets are an error naming the file (which
// one a tool reads is not defined); extended XMP (APP1 "http://ns.adobe.com/xmp/extension/") is
// not read (said in `notes`). A file whose markers run past its end, that has no SOF before SOS,
// or whose entropy-coded data has no EOI marker is truncated: an error.
// TIFF (TIFF 6.0): IFD0 gives the size (ImageWidth, ImageLength) and the XMP packet (tag 700).
#pragma once

#include "calib/metadata/tiff_tags.h"
#include "calib/metadata/xmp_packet.h"

#include <optional>
#include <string>
#include <vector>

namespace aerocal::calib {

struct ImageMetadata {
  std::string format;               // "jpeg" or "tiff"
  int width_px = 0, height_px = 0;  // from SOF / IFD0 (0 when a TIFF gives none)
  TiffTags exif;                    // empty when the file has no EXIF
  std::optional<XmpPacket> xmp;
  std::vector<std::string> notes;  // what was present and not read
};

/// True when `bytes` start like a JPEG (FF D8 FF) or a TIFF (II*\0, MM\0*).
bool IsJpegOrTiff(const std::string& bytes);

/// The metadata of the file's bytes; `path` names it in messages. InputError when the bytes are
/// neither JPEG nor TIFF, or break one of the rules above.
ImageMetadata ImageMetadataOfBytes(const std::string& bytes, const std::string& path);

/// ReadTextFile(path) (a regular file) + ImageMetadataOfBytes.
ImageMetadata ReadImageMetadata(const std::string& path);

/// The XMP packet of a camera file given to a camera reader (DJI, Pix4D XMP): a JPEG's or TIFF's
/// packet, or the file itself when it is an XMP sidecar (text holding x:xmpmeta or rdf:RDF, parsed
/// whole so line numbers are the file's); nullopt when the file is neither. Sets the image size
/// of a JPEG / TIFF (else leaves it).
std::optional<XmpPacket> XmpOfCameraFile(const std::string& bytes,
                                         const std::string& path,
                                         int* width_px,
                                         int* height_px);

}  // namespace aerocal::calib
