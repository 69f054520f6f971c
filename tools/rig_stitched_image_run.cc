#include "tools/rig_stitched_image_run.h"

#include "calib/core/error.h"
#include "calib/core/finding.h"
#include "stitch/image_io/image_io.h"
#include "stitch/resample/tiff_raster.h"
#include "stitch/rig/rig_conversion.h"

#include <algorithm>
#include <filesystem>

namespace aerocal::tools {

namespace fs = std::filesystem;

RigExposureImages OpenRigExposureImages(const calib::Rig& rig,
                                        const std::string& folder,
                                        const std::string& image) {
  RigExposureImages images;
  for (const auto& head : rig.heads) {
    const std::string path = HeadImagePath(folder, image, head.id);
    const std::string ext = fs::path(path).extension().string();
    if (ext == ".tif" || ext == ".tiff")
      images.owned.push_back(stitch::OpenTiff(path));
    else
      images.owned.push_back(
          std::make_unique<stitch::MemoryRaster>(stitch::ReadImageFile(path, true)));
    images.sources.push_back(images.owned.back().get());
  }
  return images;
}

const stitch::RigStitchExposureResult* RefinedExposure(const RigStitchRun& run,
                                                       const std::string& image) {
  const auto& refined = run.result.exposures;
  const auto it =
      std::find_if(refined.begin(), refined.end(), [&](const auto& r) { return r.image == image; });
  return it == refined.end() ? nullptr : &*it;
}

const stitch::RigStitchExposureResult& RequireRefinedExposure(const RigStitchRun& run,
                                                              const std::string& image) {
  const stitch::RigStitchExposureResult* refined = RefinedExposure(run, image);
  if (refined == nullptr)
    throw InputError("image " + image + ": not an exposure of the rig stitch result");
  return *refined;
}

stitch::StitchedImageReport StitchRigExposure(const RigStitchRun& run,
                                              const std::string& image,
                                              RigExposureImages& heads,
                                              const stitch::StitchedImageOptions& options,
                                              stitch::RasterSink* image_sink,
                                              stitch::RasterSink* mask_sink) {
  const auto exposure = std::find_if(
      run.exposures.begin(), run.exposures.end(), [&](const auto& e) { return e.image == image; });
  const stitch::RigStitchExposureResult& refined = RequireRefinedExposure(run, image);
  AEROCAL_CHECK(exposure != run.exposures.end());  // the result's exposures are the run's
  const calib::Rig& rig = run.rig;
  stitch::RigExposure pose = exposure->pose;
  pose.increment_rad.assign(rig.heads.size(), Eigen::Vector3d::Zero());
  pose.dt_s.assign(rig.heads.size(), 0.0);
  for (const auto& h : refined.heads) {
    const int k = rig.HeadIndex(h.head);
    pose.increment_rad[k] = h.increment_rad;
    pose.dt_s[k] = h.dt_fitted_s;  // also where not determinable on its own: the fitted geometry
  }
  const stitch::RigConverter converter(
      rig,
      pose,
      stitch::MakeRectificationPlane(
          rig, pose, exposure->pose.rig_center_m.z() - exposure->z_ref_m));
  return stitch::MakeStitchedImage(converter, heads.sources, options, image_sink, mask_sink);
}

nlohmann::json StitchedImageReportJson(const stitch::StitchedImageReport& r) {
  nlohmann::json heads = nlohmann::json::array(), zones = nlohmann::json::array();
  for (const auto& h : r.heads)
    heads.push_back({{"head", h.head},
                     {"gain", h.gain},
                     {"offset_dn", h.offset_dn},
                     {"samples", h.samples},
                     {"reference", h.reference}});
  const auto zone_json = [](const stitch::OverlapDisagreement& z) {
    return nlohmann::json{
        {"zone", z.zone}, {"pixels", z.pixels}, {"rms_dn", z.rms_dn}, {"mean_dn", z.mean_dn}};
  };
  for (const auto& z : r.zones) zones.push_back(zone_json(z));
  return {{"width_px", r.width_px},
          {"height_px", r.height_px},
          {"bits", r.bits},
          {"valid_pixels", r.valid_pixels},
          {"radiometry", heads},
          {"overlap_disagreement_dn", {{"all", zone_json(r.overall)}, {"zones", zones}}},
          {"warnings", FindingsToJson(r.warnings)}};
}

}  // namespace aerocal::tools
