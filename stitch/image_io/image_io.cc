#include "stitch/image_io/image_io.h"

#include "calib/core/error.h"
#include "stitch/image_io/cv_view.h"
#include "stitch/image_io/image_codecs.h"

#include <opencv2/core.hpp>

#include <sys/stat.h>

namespace aerocal::stitch {

GrayImage ReadGrayImage(const std::string& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) ThrowInputError({path, 0}, "image file not found");
  if (!S_ISREG(info.st_mode)) ThrowInputError({path, 0}, "not a regular file");
  cv::Mat raw;
  try {
    raw = DecodeImageFile(
        path, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH | cv::IMREAD_IGNORE_ORIENTATION);
  } catch (const cv::Exception& e) {
    ThrowInputError({path, 0}, std::string("cannot decode image: ") + e.what());
  }
  if (raw.empty())
    ThrowInputError({path, 0}, "cannot decode image (unknown format or corrupt file)");
  GrayImage image(raw.rows, raw.cols);
  cv::Mat view(raw.rows, raw.cols, CV_32F, image.data());
  raw.convertTo(view, CV_32F);
  return image;
}

GrayImage ReadSubimage(const std::string& path, const calib::SubimageMapping& subimage) {
  GrayImage image = ReadGrayImage(path);
  if (image.cols() != subimage.width_px || image.rows() != subimage.height_px) {
    ThrowInputError({path, 0},
                    "image is " + std::to_string(image.cols()) + " x " +
                        std::to_string(image.rows()) + " px, but sub-image " + subimage.id +
                        " of the camera file is " + std::to_string(subimage.width_px) + " x " +
                        std::to_string(subimage.height_px) + " px");
  }
  return image;
}

void WriteGrayImage(const std::string& path, const GrayImage& image, int bits) {
  AEROCAL_CHECK(bits == 8 || bits == 16) << "bits must be 8 or 16, got " << bits;
  const cv::Mat view = CvView(image);
  cv::Mat out;
  view.convertTo(out, bits == 8 ? CV_8U : CV_16U);  // rounds and saturates
  bool ok = false;
  try {
    ok = EncodeImageFile(path, out);
  } catch (const cv::Exception& e) {
    throw Error(path + ": cannot write image: " + e.what());
  }
  if (!ok) throw Error(path + ": cannot write image");
}

}  // namespace aerocal::stitch
