// The image codecs module: OpenCV's imread/imwrite behind one exported table (image_codecs.h
// says why they live in a module loaded on first use). Nothing but the two calls belongs here.
#include "stitch/image_io/image_codecs_table.h"

#include <opencv2/imgcodecs.hpp>

namespace {

cv::Mat Read(const std::string& path, int flags) { return cv::imread(path, flags); }

bool Write(const std::string& path, const cv::Mat& image) { return cv::imwrite(path, image); }

const aerocal::stitch::ImageCodecsTable kTable{aerocal::stitch::kImageCodecsAbi, &Read, &Write};

}  // namespace

extern "C" __attribute__((visibility("default"))) const aerocal::stitch::ImageCodecsTable*
aerocal_image_codecs() {
  return &kTable;
}
