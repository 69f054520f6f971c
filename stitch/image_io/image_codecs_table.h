// The table of functions the image codecs module (codecs_module/) hands to image_codecs.cc: the
// only interface between the program and the dlopen'ed module. Both sides are compiled from this
// tree with the same compiler and OpenCV, so C++ types may cross it; `abi` guards a stale module
// left in a build or install folder by an older aerocal.
#pragma once

#include <opencv2/core.hpp>

#include <string>

namespace aerocal::stitch {

constexpr int kImageCodecsAbi = 1;
/// The module's one exported symbol: `const ImageCodecsTable* aerocal_image_codecs()`.
constexpr const char* kImageCodecsSymbol = "aerocal_image_codecs";
/// The module's file name (CMake's MODULE library `aerocal_image_codecs`).
constexpr const char* kImageCodecsFile = "libaerocal_image_codecs.so";

struct ImageCodecsTable {
  int abi;                                                 // kImageCodecsAbi of the module
  cv::Mat (*read)(const std::string& path, int flags);     // cv::imread
  bool (*write)(const std::string& path, const cv::Mat&);  // cv::imwrite
};

}  // namespace aerocal::stitch
