// A light scan of an OpenCV FileStorage text (YAML, XML or JSON) before cv::FileStorage reads it
// (issue 37 class 9). cv::FileStorage reports no line for what it reads, quotes its own internals
// in its messages, and allocates whatever a matrix header asks for (`rows: nan` became a 51 GB
// allocation). The scan reads the text line by line, without building a tree, and:
//  - checks every matrix header it finds (rows, cols, dt; an n-d matrix's sizes): whole numbers
//    >= 1, a known element type of 1..4 channels, and rows x cols x channels at most the number
//    of characters in the text (every element needs at least one), so nothing cv::FileStorage
//    then allocates is larger than a small multiple of the file;
//  - refuses a NUL byte (cv::FileStorage reads memory as a C string; a NUL in an XML declaration
//    crashed OpenCV 4.6) and a top-level key that occurs twice (cv::FileStorage would take one
//    silently);
//  - bounds nesting (64 levels of collections or elements, YAML indentation within 256 columns):
//    cv::FileStorage parses recursively without a limit (200000 '[' overflowed its stack);
//  - keeps the line of every top-level key, for the reader's FILE:LINE messages.
// Errors are InputError "FILE:LINE: what".
#pragma once

#include <map>
#include <string>

namespace aerocal::tools {

struct OpenCvStorageScan {
  std::map<std::string, int> key_lines;  // top-level key -> its line (1-based)
  /// The line of top-level `key`, else 1 (the file).
  int Line(const std::string& key) const;
};

/// Scans `text` (the content of `path`). InputError("PATH:LINE: ...") for a matrix header out of
/// bounds or a duplicated top-level key.
OpenCvStorageScan ScanOpenCvStorage(const std::string& text, const std::string& path);

/// The line and message of a cv::FileStorage parse error (the text of cv::Exception's err and
/// func, one of which reads "<source>(LINE): message"); line 1 and the first line of `err` when
/// it holds no line.
std::pair<int, std::string> OpenCvParseErrorLine(const std::string& err);

}  // namespace aerocal::tools
