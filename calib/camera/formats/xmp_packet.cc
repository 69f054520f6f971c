#include "calib/camera/formats/xmp_packet.h"

namespace aerocal::calib::internal {

int LineAt(const std::string& text, size_t offset) {
  int line = 1;
  for (size_t i = 0; i < offset && i < text.size(); ++i) line += text[i] == '\n';
  return line;
}

// The value of an XMP property written as an attribute (drone-dji:NAME="v") or an element
// (<drone-dji:NAME>v</drone-dji:NAME>); npos when absent.
size_t FindXmpValue(const std::string& text, const std::string& qualified, std::string* value) {
  const std::string attribute = qualified + "=\"";
  size_t at = text.find(attribute);
  if (at != std::string::npos) {
    const size_t begin = at + attribute.size(), end = text.find('"', begin);
    if (end == std::string::npos) return std::string::npos;
    *value = text.substr(begin, end - begin);
    return begin;
  }
  const std::string open = "<" + qualified + ">", close = "</" + qualified + ">";
  at = text.find(open);
  if (at == std::string::npos) return std::string::npos;
  const size_t begin = at + open.size(), end = text.find(close, begin);
  if (end == std::string::npos) return std::string::npos;
  *value = text.substr(begin, end - begin);
  return begin;
}

// Width and height from a JPEG's SOF marker; false when the bytes are not a JPEG.
bool JpegSize(const std::string& bytes, int* width, int* height) {
  const auto byte = [&](size_t i) { return static_cast<unsigned char>(bytes[i]); };
  if (bytes.size() < 4 || byte(0) != 0xFF || byte(1) != 0xD8) return false;
  size_t i = 2;
  while (i + 9 < bytes.size()) {
    if (byte(i) != 0xFF) return false;
    const unsigned marker = byte(i + 1);
    const size_t length = (byte(i + 2) << 8) | byte(i + 3);
    if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      *height = (byte(i + 5) << 8) | byte(i + 6);
      *width = (byte(i + 7) << 8) | byte(i + 8);
      return true;
    }
    if (marker == 0xDA || length < 2) return false;
    i += 2 + length;
  }
  return false;
}

std::string TrimBlanks(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n"), e = s.find_last_not_of(" \t\r\n");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string XmpPrefix(const std::string& text, const std::string& uri, const std::string& fallback) {
  for (const std::string& value : {uri, uri + "/"}) {
    const size_t at = text.find("=\"" + value + "\"");
    if (at == std::string::npos) continue;
    const size_t colon = text.rfind("xmlns:", at);
    if (colon == std::string::npos) continue;
    const std::string prefix = text.substr(colon + 6, at - colon - 6);
    if (!prefix.empty() && prefix.find_first_of(" \t\r\n<>\"") == std::string::npos) return prefix;
  }
  return fallback;
}

}  // namespace aerocal::calib::internal
