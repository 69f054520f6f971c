#include "stitch/image_io/subimage_cutter.h"

#include "calib/core/error.h"
#include "stitch/image_io/cv_view.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <random>

namespace aerocal::stitch {

std::vector<GrayImage> CutSubimages(const GrayImage& frame,
                                    const calib::Camera& camera,
                                    const CutOptions& options) {
  const std::size_t n = camera.subimages.size();
  AEROCAL_CHECK(options.gains.empty() || options.gains.size() == n) << "one gain per sub-image";
  AEROCAL_CHECK(options.offsets.empty() || options.offsets.size() == n)
      << "one offset per sub-image";
  AEROCAL_CHECK(options.noise_dn >= 0.0) << "noise_dn must be >= 0";
  const cv::Mat source = CvView(frame);
  std::mt19937_64 rng(options.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<GrayImage> out;
  for (std::size_t k = 0; k < n; ++k) {
    const calib::SubimageMapping& sub = camera.subimages[k];
    // H maps sub-image pixels to frame pixels: exactly the inverse map the warp functions want.
    const Eigen::Matrix3d h = calib::HomographyFromParams(sub.model, sub.params.data());
    GrayImage image(sub.height_px, sub.width_px);
    cv::Mat target(sub.height_px, sub.width_px, CV_32F, image.data());
    const int flags = cv::INTER_CUBIC | cv::WARP_INVERSE_MAP;
    if (sub.model == calib::MappingModel::kProjective) {
      const cv::Matx33d m(
          h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2), h(2, 0), h(2, 1), h(2, 2));
      cv::warpPerspective(source, target, m, target.size(), flags, cv::BORDER_REFLECT);
    } else {
      const cv::Matx23d m(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2));
      cv::warpAffine(source, target, m, target.size(), flags, cv::BORDER_REFLECT);
    }
    const double gain = options.gains.empty() ? 1.0 : options.gains[k];
    const double offset = options.offsets.empty() ? 0.0 : options.offsets[k];
    for (Eigen::Index i = 0; i < image.size(); ++i) {
      double value = gain * image.data()[i] + offset;
      if (options.noise_dn > 0.0) value += options.noise_dn * noise(rng);
      image.data()[i] = static_cast<float>(value);
    }
    out.push_back(std::move(image));
  }
  return out;
}

}  // namespace aerocal::stitch
