// OpenCV's image file codecs (cv::imread, cv::imwrite), loaded on the first image read or written.
//
// Why not link opencv_imgcodecs: Debian builds it with GDAL, and linking it makes the dynamic
// loader map about 140 more shared libraries (gdal, hdf5, gdcm, poppler, ...) at every start: 0.12
// of the 0.15 s an `aerocal` command took to start (2026-11-28), paid by every command, batch unit
// and test process, most of which never touch an image. The two calls therefore live in a small
// module, libaerocal_image_codecs.so (codecs_module/), which links imgcodecs and is dlopen'ed once,
// on first use; the results are those of the direct calls.
//
// Where the module is looked for, in order: the file named by the environment variable
// AEROCAL_IMAGE_CODECS; beside the shared object holding this code (the Python extension, whose
// package folder holds a copy); beside the running program (the `aerocal` executable's folder);
// the build tree that compiled this code. A module that cannot be loaded is an Error naming every
// place tried and the loader's message.
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>  // the cv::IMREAD_* flags (declarations only; nothing is linked)

#include <string>

namespace aerocal::stitch {

/// cv::imread(path, flags): an empty matrix when OpenCV cannot decode the file; OpenCV's own
/// exceptions pass through.
cv::Mat DecodeImageFile(const std::string& path, int flags);

/// cv::imwrite(path, image): false when OpenCV cannot write that format; OpenCV's own exceptions
/// pass through.
bool EncodeImageFile(const std::string& path, const cv::Mat& image);

}  // namespace aerocal::stitch
