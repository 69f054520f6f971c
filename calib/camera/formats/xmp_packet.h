// Reading camera properties from an XMP packet (Adobe XMP: RDF/XML inside a JPEG's APP1 segment or
// in a sidecar file), as DJI and Pix4D write them. A property is an attribute of rdf:Description
// (PREFIX:NAME="v") or an element (<PREFIX:NAME>v</PREFIX:NAME>); the packet is searched as text
// because a JPEG is not XML and sidecars in the field are often not well-formed.
#pragma once

#include <cstddef>
#include <string>

namespace aerocal::calib::internal {

/// The value of the XMP property `qualified` ("drone-dji:DewarpData"); its offset in `text`, or
/// std::string::npos when absent.
size_t FindXmpValue(const std::string& text, const std::string& qualified, std::string* value);

/// The prefix bound to namespace `uri` (xmlns:PREFIX="uri", with or without a trailing slash);
/// `fallback` when the packet does not declare it.
std::string XmpPrefix(const std::string& text, const std::string& uri, const std::string& fallback);

/// Width and height from a JPEG's SOF marker; false when the bytes are not a JPEG.
bool JpegSize(const std::string& bytes, int* width, int* height);

/// 1-based line of `offset` in `text`.
int LineAt(const std::string& text, size_t offset);

/// `s` without leading and trailing blanks (space, tab, CR, LF).
std::string TrimBlanks(const std::string& s);

}  // namespace aerocal::calib::internal
