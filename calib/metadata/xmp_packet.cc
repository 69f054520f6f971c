#include "calib/metadata/xmp_packet.h"

#include <tinyxml2.h>
#include <vector>

namespace aerocal::calib {
namespace {

constexpr const char* kRdfUri = "http://www.w3.org/1999/02/22-rdf-syntax-ns#";
constexpr const char* kXmlUri = "http://www.w3.org/XML/1998/namespace";

using Scope = std::map<std::string, std::string>;  // prefix ("" = default) -> URI

std::string Trimmed(const char* text) {
  const std::string s = text ? text : "";
  const size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string WithoutTrailingSlash(std::string uri) {
  if (!uri.empty() && uri.back() == '/') uri.pop_back();
  return uri;
}

}  // namespace

// Builds the property table of one packet; every message names the packet's source and line.
struct XmpPacketBuilder {
  SourceRef where;
  XmpPacket packet;

  SourceRef At(const tinyxml2::XMLElement* e) const {
    const int line = e ? e->GetLineNum() : 1;
    if (where.line > 0) return {where.file, where.line - 1 + line};
    return {where.file + ": XMP line " + std::to_string(line), 0};
  }

  // The scope of `e`: its parent's plus its own xmlns declarations.
  static Scope ScopeOf(const tinyxml2::XMLElement* e, Scope scope) {
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
      const std::string name = a->Name();
      if (name == "xmlns")
        scope[""] = a->Value();
      else if (name.rfind("xmlns:", 0) == 0)
        scope[name.substr(6)] = a->Value();
    }
    scope["xml"] = kXmlUri;
    return scope;
  }

  // (URI, local name) of a qualified name; unprefixed attributes have no namespace ("").
  std::pair<std::string, std::string> Resolve(const std::string& qualified,
                                              const Scope& scope,
                                              const tinyxml2::XMLElement* at,
                                              bool attribute) const {
    const size_t colon = qualified.find(':');
    const std::string prefix = colon == std::string::npos ? "" : qualified.substr(0, colon);
    const std::string local = colon == std::string::npos ? qualified : qualified.substr(colon + 1);
    if (prefix.empty() && attribute) return {"", local};
    const auto it = scope.find(prefix);
    if (it == scope.end())
      ThrowInputError(At(at),
                      prefix.empty() ? "element <" + qualified + "> has no namespace"
                                     : "namespace prefix '" + prefix + "' of " + qualified +
                                           " is not declared");
    return {it->second, local};
  }

  void Add(const std::string& uri, const std::string& local, XmpProperty property) {
    const auto key = std::make_pair(WithoutTrailingSlash(uri), local);
    const auto [it, inserted] = packet.properties_.emplace(key, property);
    if (!inserted)
      ThrowInputError(property.where,
                      "XMP property " + property.qualified + " (" + uri +
                          ") is given twice (first at " + it->second.where.ToString() + ")");
  }

  void ReadDescription(const tinyxml2::XMLElement* d, const Scope& outer) {
    const Scope scope = ScopeOf(d, outer);
    for (const tinyxml2::XMLAttribute* a = d->FirstAttribute(); a; a = a->Next()) {
      const std::string name = a->Name();
      if (name == "xmlns" || name.rfind("xmlns:", 0) == 0) continue;
      const auto [uri, local] = Resolve(name, scope, d, true);
      if (uri.empty() || uri == kRdfUri || uri == kXmlUri) continue;  // rdf:about, xml:lang
      Add(uri, local, {name, Trimmed(a->Value()), false, At(d)});
    }
    for (const tinyxml2::XMLElement* c = d->FirstChildElement(); c; c = c->NextSiblingElement()) {
      const auto [uri, local] = Resolve(c->Name(), ScopeOf(c, scope), c, false);
      const bool structured = c->FirstChildElement() != nullptr;
      Add(uri, local, {c->Name(), structured ? "" : Trimmed(c->GetText()), structured, At(c)});
    }
  }

  // rdf:RDF elements below `e` (the packet's root is x:xmpmeta, or rdf:RDF itself).
  void FindRdf(const tinyxml2::XMLElement* e,
               const Scope& outer,
               std::vector<std::pair<const tinyxml2::XMLElement*, Scope>>* found) const {
    const Scope scope = ScopeOf(e, outer);
    if (Resolve(e->Name(), scope, e, false) ==
        std::make_pair(std::string(kRdfUri), std::string("RDF"))) {
      found->emplace_back(e, scope);
      return;
    }
    for (const tinyxml2::XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement())
      FindRdf(c, scope, found);
  }
};

XmpPacket XmpPacket::Parse(const std::string& text, const SourceRef& where) {
  XmpPacketBuilder b{where, {}};
  // The packet wrapper's trailer <?xpacket end="w"?> follows the root element; tinyxml2 accepts a
  // processing instruction only before it, so the trailer is cut (lines before it are unchanged).
  const size_t trailer = text.rfind("<?xpacket end");
  const std::string xml = trailer == std::string::npos ? text : text.substr(0, trailer);
  tinyxml2::XMLDocument doc;
  if (doc.Parse(xml.data(), xml.size()) != tinyxml2::XML_SUCCESS) {
    SourceRef at = b.At(nullptr);
    if (where.line > 0)
      at.line = where.line - 1 + doc.ErrorLineNum();
    else
      at.file = where.file + ": XMP line " + std::to_string(doc.ErrorLineNum());
    ThrowInputError(at, std::string("XMP packet is not well-formed XML: ") + doc.ErrorName());
  }
  if (!doc.RootElement()) ThrowInputError(b.At(nullptr), "empty XMP packet");
  // tinyxml2 accepts several top-level elements; an XMP packet has one (two are two packets).
  if (const tinyxml2::XMLElement* second = doc.RootElement()->NextSiblingElement())
    ThrowInputError(
        b.At(second),
        "two XMP packets (a second top-level element <" + std::string(second->Name()) + ">)");
  std::vector<std::pair<const tinyxml2::XMLElement*, Scope>> rdf;
  b.FindRdf(doc.RootElement(), {}, &rdf);
  if (rdf.empty()) ThrowInputError(b.At(doc.RootElement()), "XMP packet without rdf:RDF");
  if (rdf.size() > 1) ThrowInputError(b.At(rdf[1].first), "XMP packet with two rdf:RDF elements");
  const Scope rdf_scope = rdf[0].second;
  for (const tinyxml2::XMLElement* d = rdf[0].first->FirstChildElement(); d;
       d = d->NextSiblingElement()) {
    const Scope scope = XmpPacketBuilder::ScopeOf(d, rdf_scope);
    if (b.Resolve(d->Name(), scope, d, false) !=
        std::make_pair(std::string(kRdfUri), std::string("Description")))
      ThrowInputError(b.At(d),
                      std::string("<") + d->Name() + "> inside rdf:RDF: expected rdf:Description");
    b.ReadDescription(d, rdf_scope);
  }
  return b.packet;
}

const XmpProperty* XmpPacket::Find(const std::string& uri, const std::string& name) const {
  const auto it = properties_.find({WithoutTrailingSlash(uri), name});
  return it == properties_.end() ? nullptr : &it->second;
}

std::string XmpPacket::Text(const std::string& uri, const std::string& name) const {
  const XmpProperty* p = Find(uri, name);
  return p && !p->structured ? p->value : "";
}

}  // namespace aerocal::calib
