#include "tools/opencv_storage_scan.h"

#include "calib/core/csv.h"
#include "calib/core/error.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <regex>
#include <sstream>

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

constexpr int kMaxNesting = 64;       // collections inside collections
constexpr int kMaxIndentation = 256;  // YAML block nesting: columns of indentation

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
    if (header_.rows >= 0 && header_.cols >= 0 &&
        header_.rows * header_.cols * header_.channels > limit_)
      Throw(line,
            "a matrix of " + FormatNumber(header_.rows) + " x " + FormatNumber(header_.cols) +
                (header_.channels > 1 ? " x " + FormatNumber(header_.channels) : "") +
                " elements cannot be held by a file of " + FormatNumber(limit_) + " characters");
  }

  // cv::FileStorage parses nested collections recursively, without a limit: 200000 '[' overflowed
  // its stack. Nesting is bounded before it reads anything.
  void Nesting(int depth, int line, const char* what) const {
    if (depth > kMaxNesting)
      Throw(line,
            std::string(what) + " nested deeper than " + std::to_string(kMaxNesting) + " levels");
  }
  void EmptyKey(int line) const { Throw(line, "a key is empty (nothing before ':')"); }
  void Indentation(size_t columns, int line) const {
    if (columns > static_cast<size_t>(kMaxIndentation))
      Throw(line,
            "indented " + std::to_string(columns) + " columns: YAML nested deeper than " +
                std::to_string(kMaxIndentation) + " columns");
  }

  void Key(const std::string& key, int line, OpenCvStorageScan* scan) const {
    const auto [it, inserted] = scan->key_lines.emplace(key, line);
    if (!inserted)
      Throw(line,
            "'" + key + "' occurs twice (first on line " + std::to_string(it->second) +
                "): cv::FileStorage would read one of them silently");
  }

 private:
  [[noreturn]] void Throw(int line, const std::string& what) const {
    ThrowInputError({path_, line}, what);
  }

  double WholeNumber(const std::string& value, const std::string& name, int line) const {
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (value.empty() || *end != '\0' || !std::isfinite(v) || v != std::floor(v) || v < 0 ||
        v > limit_)
      Throw(line,
            name + " must be a whole number within 0 .. " + FormatNumber(limit_) +
                " (the file's size) (got '" + value + "')");
    return v;
  }

  // dt: an element type of OpenCV (u c w s i f d h), a matrix's with 1..4 channels in front; a
  // raw sequence's compound type ("2if") is checked for its letters only.
  double Channels(const std::string& value, int line) const {
    static const std::regex kSingle(R"(([1-4]?)([ucwsifdh]))"),
        kCompound(R"(([0-9]{0,3}[ucwsifdhr])+)");
    std::smatch m;
    if (std::regex_match(value, m, kSingle)) return m[1].length() ? std::stod(m[1]) : 1.0;
    if (value.size() <= 32 && std::regex_match(value, kCompound)) return 1.0;
    Throw(line,
          "dt must be an OpenCV element type (u c w s i f d h, 1..4 channels in front, as 'd' "
          "or '3f') (got '" +
              value + "')");
  }

  // An n-d matrix's sizes: whole numbers whose product the file can hold.
  void Sizes(const std::string& list, int line) const {
    std::string cleaned;
    for (char c : list) cleaned += (c == '[' || c == ']' || c == ',') ? ' ' : c;
    std::istringstream in(cleaned);
    double product = 1;
    for (std::string item; in >> item;) product *= WholeNumber(item, "sizes", line);
    if (product > limit_)
      Throw(line,
            "sizes of " + FormatNumber(product) + " elements cannot be held by a file of " +
                FormatNumber(limit_) + " characters");
  }

  std::string path_;
  double limit_;
  Header header_;
};

// A value as written: quotes stripped.
std::string Unquoted(std::string value) {
  if (value.size() >= 2 && (value.front() == '"' || value.front() == '\'') &&
      value.back() == value.front())
    value = value.substr(1, value.size() - 2);
  return value;
}

// The scan is hand-written, not std::regex: libstdc++'s regex recurses once per character and
// overflows the stack on a long line, and every step here is linear in the line.
bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
bool IsNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' ||
         c == ':';
}

size_t SkipSpaces(const std::string& line, size_t i) {
  while (i < line.size() && IsSpace(line[i])) ++i;
  return i;
}

// A field's value cut to a length no valid value exceeds (the check then refuses it).
std::string Bounded(const std::string& value) {
  return value.size() > 64 ? value.substr(0, 65) : value;
}

constexpr const char* kFieldNames[] = {"rows", "cols", "dt", "sizes", "data"};

// YAML and JSON: `rows: 3`, `"rows": 3`, in block or flow style (several fields on a line).
void ScanFieldsYamlJson(const std::string& line, int number, Scanner* scanner) {
  for (const char* name : kFieldNames) {
    const std::string key(name);
    for (size_t at = line.find(key); at != std::string::npos; at = line.find(key, at + 1)) {
      size_t begin = at;
      if (begin > 0 && line[begin - 1] == '"') --begin;
      if (begin > 0 &&
          !(IsSpace(line[begin - 1]) || line[begin - 1] == '{' || line[begin - 1] == ','))
        continue;
      size_t i = at + key.size();
      if (i < line.size() && line[i] == '"') ++i;
      i = SkipSpaces(line, i);
      if (i >= line.size() || line[i] != ':') continue;
      i = SkipSpaces(line, i + 1);
      size_t end = i;
      if (i < line.size() && line[i] == '[') {
        end = line.find(']', i);
        end = end == std::string::npos ? line.size() : end + 1;
      } else if (i < line.size() && line[i] == '"') {
        end = line.find('"', i + 1);
        end = end == std::string::npos ? line.size() : end + 1;
      } else {
        while (end < line.size() && line[end] != ',' && line[end] != '}' && !IsSpace(line[end]))
          ++end;
      }
      scanner->Field(key, Bounded(Unquoted(line.substr(i, end - i))), number);
    }
  }
}

// XML: <rows>3</rows>; the value is the text up to the next tag (XML quotes dt too: <dt>"2f"</dt>).
void ScanFieldsXml(const std::string& line, int number, Scanner* scanner) {
  for (const char* name : kFieldNames) {
    const std::string tag = "<" + std::string(name) + ">";
    for (size_t at = line.find(tag); at != std::string::npos; at = line.find(tag, at + 1)) {
      const size_t i = SkipSpaces(line, at + tag.size());
      size_t end = line.find('<', i);
      if (end == std::string::npos) end = line.size();
      while (end > i && IsSpace(line[end - 1])) --end;
      scanner->Field(name, Bounded(Unquoted(line.substr(i, end - i))), number);
    }
  }
}

// YAML: a key at column 0 (a name, or a quoted one, then ':' and a space or the line's end) is a
// top-level key.
void ScanKeyYaml(const std::string& line,
                 int number,
                 const Scanner& scanner,
                 OpenCvStorageScan* scan) {
  if (line.empty()) return;
  size_t end = 0;
  if (line[0] == '"') {
    end = line.find('"', 1);
    if (end == std::string::npos) return;
    ++end;
  } else if (std::isalpha(static_cast<unsigned char>(line[0])) || line[0] == '_') {
    while (end < line.size() && IsNameChar(line[end]) && line[end] != ':') ++end;
  } else {
    return;
  }
  const size_t colon = SkipSpaces(line, end);
  if (colon >= line.size() || line[colon] != ':') return;
  if (colon + 1 < line.size() && !IsSpace(line[colon + 1])) return;
  scanner.Key(Unquoted(line.substr(0, end)), number, scan);
}

// XML: the elements directly inside the root (<opencv_storage>); comments and declarations skipped.
class XmlKeys {
 public:
  void Line(const std::string& line, int number, const Scanner& scanner, OpenCvStorageScan* scan) {
    size_t i = 0;
    while (i < line.size()) {
      if (in_comment_) {
        const size_t end = line.find("-->", i);
        if (end == std::string::npos) return;
        i = end + 3;
        in_comment_ = false;
        continue;
      }
      const size_t open = line.find('<', i);
      if (open == std::string::npos) return;
      if (line.compare(open, 4, "<!--") == 0) {
        in_comment_ = true;
        i = open + 4;
        continue;
      }
      size_t j = open + 1;
      const bool closing = j < line.size() && line[j] == '/';
      if (closing) ++j;
      const size_t name_begin = j;
      while (j < line.size() && IsNameChar(line[j])) ++j;
      const size_t close = line.find('>', j);
      if (j == name_begin || !(std::isalpha(static_cast<unsigned char>(line[name_begin])) ||
                               line[name_begin] == '_')) {
        i = open + 1;  // a declaration (<?xml ...?>), text, or a tag cut by the line's end
        continue;
      }
      if (closing) {
        --depth_;
      } else {
        if (depth_ == 1) scanner.Key(line.substr(name_begin, j - name_begin), number, scan);
        const bool self_closing = close != std::string::npos && close > j && line[close - 1] == '/';
        if (!self_closing) scanner.Nesting(++depth_, number, "elements");
      }
      if (close == std::string::npos) return;
      i = close + 1;
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
        scanner.Nesting(++depth_, number, "objects and arrays");
      } else if (c == '}' || c == ']') {
        --depth_;
      }
    }
  }

 private:
  static size_t StringEnd(const std::string& line, size_t open) {
    for (size_t i = open + 1; i < line.size(); ++i) {
      if (line[i] == '\\')
        ++i;
      else if (line[i] == '"')
        return i;
    }
    return line.size();
  }
  int depth_ = 0;
};

// XML: every attribute's '=' is followed by a quoted value. OpenCV 4.6's XML parser dereferences
// null when the text ends after an '=' (found by fuzz/camera_formats: `<?xml version=` and CRs).
void CheckXmlAttributes(const std::string& text, const std::string& path) {
  int line = 1;
  bool in_tag = false;
  char quote = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') ++line;
    if (quote) {
      if (c == quote) quote = 0;
    } else if (!in_tag) {
      if (c == '<' && text.compare(i, 4, "<!--") == 0) {
        const size_t end = text.find("-->", i + 4);
        const size_t stop = end == std::string::npos ? text.size() : end + 3;
        line += static_cast<int>(std::count(text.begin() + i, text.begin() + stop, '\n'));
        i = stop - 1;
      } else if (c == '<') {
        in_tag = true;
      }
    } else if (c == '>') {
      in_tag = false;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '=') {
      size_t j = i + 1;
      while (j < text.size() && std::isspace(static_cast<unsigned char>(text[j]))) ++j;
      if (j >= text.size() || (text[j] != '"' && text[j] != '\''))
        ThrowInputError({path, line}, "an XML attribute without a quoted value after '='");
    }
  }
}

// YAML: block nesting by indentation (leading spaces and "- " items), flow nesting by [ and {
// outside quoted strings, carried from line to line.
class YamlNesting {
 public:
  void Line(const std::string& line, int number, const Scanner& scanner) {
    size_t indent = 0;
    while (indent < line.size() &&
           (line[indent] == ' ' ||
            (line[indent] == '-' && indent + 1 < line.size() && line[indent + 1] == ' ')))
      ++indent;
    scanner.Indentation(indent, number);
    // An empty key (`   : 460.4`): OpenCV 4.6's YAML parser then asks std::string for a negative
    // length (std::length_error, found by fuzz/camera_formats).
    if (indent < line.size() && line[indent] == ':' &&
        (indent + 1 == line.size() || IsSpace(line[indent + 1])))
      scanner.EmptyKey(number);
    char quote = 0;
    for (size_t i = indent; i < line.size(); ++i) {
      const char c = line[i];
      if (quote) {
        if (c == quote) quote = 0;
      } else if (c == '"' || c == '\'') {
        quote = c;
      } else if (c == '#' && (i == 0 || IsSpace(line[i - 1]))) {
        return;  // a comment
      } else if (c == '[' || c == '{') {
        scanner.Nesting(++flow_depth_, number, "flow collections");
      } else if ((c == ']' || c == '}') && flow_depth_ > 0) {
        --flow_depth_;
      }
    }
  }

 private:
  int flow_depth_ = 0;
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
    ThrowInputError(
        {path, 1 + static_cast<int>(std::count(text.begin(), text.begin() + nul, '\n'))},
        "a NUL byte: not a text file (an OpenCV FileStorage file is YAML, XML or JSON text)");
  OpenCvStorageScan scan;
  Scanner scanner(text, path);
  const Syntax syntax = SyntaxOf(text);
  if (syntax == Syntax::kXml) CheckXmlAttributes(text, path);
  XmlKeys xml;
  JsonKeys json;
  YamlNesting yaml;
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
        yaml.Line(line, number, scanner);
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
