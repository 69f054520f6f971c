#include "tools/opencv_storage_scan.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <sstream>

#include "calib/core/csv.h"
#include "calib/core/error.h"

namespace aerocal::tools {
namespace {

enum class Syntax { kYaml, kXml, kJson };

Syntax SyntaxOf(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && text[first] == '<') return Syntax::kXml;
  if (first != std::string::npos && text[first] == '{') return Syntax::kJson;
  return Syntax::kYaml;
}

// The header of the matrix being read: its fields as they come (rows, cols, dt; data ends it).
struct Header {
  double rows = -1, cols = -1, channels = 1;
};

class Scanner {
 public:
  Scanner(const std::string& text, const std::string& path)
      : path_(path), limit_(static_cast<double>(text.size())) {}

  // One header field `name` = `value` on `line`.
  void Field(const std::string& name, const std::string& value, int line) {
    if (name == "data") {
      header_ = Header();
      return;
    }
    if (name == "rows" || name == "cols") {
      const double v = WholeNumber(value, name, line);
      (name == "rows" ? header_.rows : header_.cols) = v;
    } else if (name == "dt") {
      header_.channels = Channels(value, line);
    } else if (name == "sizes") {
      Sizes(value, line);
      return;
    }
    // Every element of the matrix needs at least one character of the file.
    if (header_.rows >= 0 && header_.cols >= 0 && header_.rows * header_.cols * header_.channels > limit_)
      Throw(line, "a matrix of " + FormatNumber(header_.rows) + " x " + FormatNumber(header_.cols) +
                      (header_.channels > 1 ? " x " + FormatNumber(header_.channels) : "") +
                      " elements cannot be held by a file of " + FormatNumber(limit_) + " characters");
  }

  void Key(const std::string& key, int line, OpenCvStorageScan* scan) const {
    const auto [it, inserted] = scan->key_lines.emplace(key, line);
    if (!inserted)
      Throw(line, "'" + key + "' occurs twice (first on line " + std::to_string(it->second) +
                      "): cv::FileStorage would read one of them silently");
  }

 private:
  [[noreturn]] void Throw(int line, const std::string& what) const { ThrowInputError({path_, line}, what); }

  double WholeNumber(const std::string& value, const std::string& name, int line) const {
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v) || v != std::floor(v) || v < 0 || v > limit_)
      Throw(line, name + " must be a whole number within 0 .. " + FormatNumber(limit_) +
                      " (the file's size) (got '" + value + "')");
    return v;
  }

  // dt: an element type of OpenCV (u c w s i f d h), a matrix's with 1..4 channels in front; a
  // raw sequence's compound type ("2if") is checked for its letters only.
  double Channels(const std::string& value, int line) const {
    static const std::regex kSingle(R"(([1-4]?)([ucwsifdh]))"), kCompound(R"(([0-9]{0,3}[ucwsifdhr])+)");
    std::smatch m;
    if (std::regex_match(value, m, kSingle)) return m[1].length() ? std::stod(m[1]) : 1.0;
    if (value.size() <= 32 && std::regex_match(value, kCompound)) return 1.0;
    Throw(line, "dt must be an OpenCV element type (u c w s i f d h, 1..4 channels in front, as 'd' "
                "or '3f') (got '" + value + "')");
  }

  // An n-d matrix's sizes: whole numbers whose product the file can hold.
  void Sizes(const std::string& list, int line) const {
    std::string cleaned;
    for (char c : list) cleaned += (c == '[' || c == ']' || c == ',') ? ' ' : c;
    std::istringstream in(cleaned);
    double product = 1;
    for (std::string item; in >> item;) product *= WholeNumber(item, "sizes", line);
    if (product > limit_)
      Throw(line, "sizes of " + FormatNumber(product) + " elements cannot be held by a file of " +
                      FormatNumber(limit_) + " characters");
  }

  std::string path_;
  double limit_;
  Header header_;
};

// A value as written: quotes stripped.
std::string Unquoted(std::string value) {
  if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') && value.back() == value.front())
    value = value.substr(1, value.size() - 2);
  return value;
}

// YAML and JSON: `rows: 3`, `"rows": 3`, in block or flow style (several fields on a line).
void ScanFieldsYamlJson(const std::string& line, int number, Scanner* scanner) {
  static const std::regex kField(R"re((?:^|[\s{,])"?(rows|cols|dt|sizes|data)"?\s*:\s*(\[[^\]]*\]?|"[^"]*"|[^,}\s]*))re");
  for (auto it = std::sregex_iterator(line.begin(), line.end(), kField); it != std::sregex_iterator(); ++it)
    scanner->Field((*it)[1], Unquoted((*it)[2]), number);
}

void ScanFieldsXml(const std::string& line, int number, Scanner* scanner) {
  static const std::regex kField(R"(<(rows|cols|dt|sizes|data)>\s*([^<]*?)\s*(</|$))");
  for (auto it = std::sregex_iterator(line.begin(), line.end(), kField); it != std::sregex_iterator(); ++it)
    scanner->Field((*it)[1], Unquoted((*it)[2]), number);  // XML quotes dt too: <dt>"2f"</dt>
}

// YAML: a key at column 0 is a top-level key.
void ScanKeyYaml(const std::string& line, int number, const Scanner& scanner, OpenCvStorageScan* scan) {
  static const std::regex kKey(R"re(^([A-Za-z_][A-Za-z0-9_.-]*|"[^"]*")\s*:(\s.*)?$)re");
  std::smatch m;
  if (std::regex_match(line, m, kKey)) scanner.Key(Unquoted(m[1]), number, scan);
}

// XML: the elements directly inside the root (<opencv_storage>); comments and declarations skipped.
class XmlKeys {
 public:
  void Line(const std::string& line, int number, const Scanner& scanner, OpenCvStorageScan* scan) {
    static const std::regex kTag(R"(<(/?)([A-Za-z_][A-Za-z0-9_.:-]*)[^>]*?(/?)>)");
    std::string rest = line;
    std::string visible;  // the line without comments
    while (!rest.empty()) {
      if (in_comment_) {
        const size_t end = rest.find("-->");
        if (end == std::string::npos) return;
        rest = rest.substr(end + 3);
        in_comment_ = false;
      }
      const size_t start = rest.find("<!--");
      visible += rest.substr(0, start);
      if (start == std::string::npos) break;
      rest = rest.substr(start + 4);
      in_comment_ = true;
    }
    for (auto it = std::sregex_iterator(visible.begin(), visible.end(), kTag); it != std::sregex_iterator(); ++it) {
      const auto& m = *it;
      if (m[1].length()) {
        --depth_;
      } else {
        if (depth_ == 1) scanner.Key(m[2], number, scan);
        if (!m[3].length()) ++depth_;
      }
    }
  }

 private:
  int depth_ = 0;
  bool in_comment_ = false;
};

// JSON: the keys of the top-level object (strings followed by ':' at depth 1).
class JsonKeys {
 public:
  void Line(const std::string& line, int number, const Scanner& scanner, OpenCvStorageScan* scan) {
    for (size_t i = 0; i < line.size(); ++i) {
      const char c = line[i];
      if (c == '"') {
        const size_t end = StringEnd(line, i);
        if (depth_ == 1) {
          const size_t colon = line.find_first_not_of(" \t", end + 1);
          if (colon != std::string::npos && line[colon] == ':')
            scanner.Key(line.substr(i + 1, end - i - 1), number, scan);
        }
        i = end;
      } else if (c == '{' || c == '[') {
        ++depth_;
      } else if (c == '}' || c == ']') {
        --depth_;
      }
    }
  }

 private:
  static size_t StringEnd(const std::string& line, size_t open) {
    for (size_t i = open + 1; i < line.size(); ++i) {
      if (line[i] == '\\') ++i;
      else if (line[i] == '"') return i;
    }
    return line.size();
  }
  int depth_ = 0;
};

}  // namespace

int OpenCvStorageScan::Line(const std::string& key) const {
  const auto it = key_lines.find(key);
  return it == key_lines.end() ? 1 : it->second;
}

OpenCvStorageScan ScanOpenCvStorage(const std::string& text, const std::string& path) {
  // cv::FileStorage reads a memory buffer as a C string: a NUL byte cuts it short, and in an XML
  // declaration that made OpenCV 4.6 dereference a null pointer (found by fuzz/camera_formats).
  const size_t nul = text.find('\0');
  if (nul != std::string::npos)
    ThrowInputError({path, 1 + static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n'))},
                    "a NUL byte: not a text file (an OpenCV FileStorage file is YAML, XML or JSON text)");
  OpenCvStorageScan scan;
  Scanner scanner(text, path);
  const Syntax syntax = SyntaxOf(text);
  XmlKeys xml;
  JsonKeys json;
  std::istringstream in(text);
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    switch (syntax) {
      case Syntax::kXml:
        xml.Line(line, number, scanner, &scan);
        ScanFieldsXml(line, number, &scanner);
        break;
      case Syntax::kJson:
        json.Line(line, number, scanner, &scan);
        ScanFieldsYamlJson(line, number, &scanner);
        break;
      case Syntax::kYaml:
        if (line.rfind('#', 0) == 0) break;
        ScanKeyYaml(line, number, scanner, &scan);
        ScanFieldsYamlJson(line, number, &scanner);
        break;
    }
  }
  return scan;
}

std::pair<int, std::string> OpenCvParseErrorLine(const std::string& err) {
  static const std::regex kLine(R"(\((\d{1,9})\): *([^\n]*))");
  std::smatch m;
  if (std::regex_search(err, m, kLine)) return {std::max(1, std::stoi(m[1])), m[2]};
  return {1, err.substr(0, err.find('\n'))};
}

}  // namespace aerocal::tools
