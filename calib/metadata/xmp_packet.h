// An XMP packet (Adobe XMP, ISO 16684-1: RDF/XML in a JPEG's APP1 segment, a TIFF's tag 700 or a
// sidecar file) parsed with tinyxml2 into its simple properties, each addressed by NAMESPACE URI
// and local name, never by the prefix a writer happened to choose (`drone-dji:`, `Camera:`,
// `P4:` ... are only names bound by xmlns declarations in scope).
//
// A property is an attribute of an rdf:Description (PREFIX:NAME="v") or a child element of one
// (<PREFIX:NAME>v</PREFIX:NAME>). An element with child elements (rdf:Seq, rdf:Bag, rdf:Alt, a
// struct) is kept as a structured property without a value. Rules, each an InputError naming the
// file and line: the packet must be well-formed XML; a prefix must be declared; the same property
// (URI and name) given twice (in one or in several rdf:Description, as attribute or element) is
// an error naming both lines, never resolved by taking the first. Namespace URIs are compared
// exactly, except that one trailing '/' is ignored (Pix4D documents its URI without it, writers
// add it).
#pragma once

#include "calib/core/error.h"

#include <map>
#include <string>
#include <utility>

namespace aerocal::calib {

struct XmpProperty {
  std::string qualified;  // as written in the file ("drone-dji:GpsLatitude"), for messages
  std::string value;      // text, blanks trimmed; empty for a structured property
  bool structured = false;
  SourceRef where;  // file and line of the attribute's element or of the element
};

class XmpPacket {
 public:
  XmpPacket() = default;
  /// Parses `xml`, one packet; `where` names it (file, and the line of its first character in
  /// that file, 1 for a sidecar; 0 inside a binary file: lines are then counted in the packet and
  /// the messages say "XMP line N").
  static XmpPacket Parse(const std::string& xml, const SourceRef& where);

  /// The property `name` of namespace `uri`; nullptr when absent.
  const XmpProperty* Find(const std::string& uri, const std::string& name) const;
  /// Its text (blanks trimmed), or "" when absent or structured.
  std::string Text(const std::string& uri, const std::string& name) const;
  int size() const { return static_cast<int>(properties_.size()); }
  bool empty() const { return properties_.empty(); }

 private:
  // (namespace URI without a trailing '/', local name) -> property
  std::map<std::pair<std::string, std::string>, XmpProperty> properties_;
  friend struct XmpPacketBuilder;
};

/// Namespace URIs of the properties aerocal reads.
namespace xmp_ns {
inline constexpr const char* kDji = "http://www.dji.com/drone-dji/1.0/";
inline constexpr const char* kPix4dCamera = "http://pix4d.com/camera/1.0";
inline constexpr const char* kTiff = "http://ns.adobe.com/tiff/1.0/";
inline constexpr const char* kExif = "http://ns.adobe.com/exif/1.0/";
inline constexpr const char* kExifAux = "http://ns.adobe.com/exif/1.0/aux/";
}  // namespace xmp_ns

}  // namespace aerocal::calib
