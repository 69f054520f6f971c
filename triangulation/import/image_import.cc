#include "triangulation/import/image_import.h"

#include "calib/camera/camera.h"
#include "calib/camera/formats/camera_formats.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "triangulation/georef/object_frame.h"
#include "triangulation/import/gimbal_attitude.h"
#include "triangulation/import/image_record.h"
#include "triangulation/import/write_project.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

namespace aerocal::triangulation {
namespace {

namespace fs = std::filesystem;
using internal::ImageRecord;

constexpr double kDeg = M_PI / 180.0;
constexpr double kFullFrameDiagonalMm = 43.2666;  // 36 x 24 mm

bool IsImageName(const std::string& name) {
  std::string ext = fs::path(name).extension().string();
  std::transform(
      ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".jpg" || ext == ".jpeg" || ext == ".tif" || ext == ".tiff";
}

// A CSV field (formats.md: no quoting): a comma becomes ';', a control character a space.
std::string Field(std::string text) {
  for (char& c : text) {
    if (c == ',')
      c = ';';
    else if (static_cast<unsigned char>(c) < 32)
      c = ' ';
  }
  return text;
}

// A camera id usable as a file name (camera_<id>.yaml) and a CSV field.
std::string CameraId(const std::string& key) {
  std::string id;
  for (unsigned char c : key)
    id += std::isalnum(c) || c == '-' || c == '_' || c == '.' ? static_cast<char>(c) : '_';
  return id.empty() ? "camera" : id;
}

// The pixel size of a camera from its first image; the rule used is said in `notes`.
double PixelSizeMm(const ImageRecord& r,
                   const ImageImportOptions& o,
                   std::vector<std::string>* notes) {
  if (o.pixel_size_mm > 0) return o.pixel_size_mm;
  if (r.focal_plane_pixel_mm && *r.focal_plane_pixel_mm >= 1e-5 && *r.focal_plane_pixel_mm <= 1)
    return *r.focal_plane_pixel_mm;
  if (r.focal_mm && r.focal_35mm && *r.focal_mm > 0 && *r.focal_35mm > 0) {
    const double p =
        kFullFrameDiagonalMm * *r.focal_mm / *r.focal_35mm / std::hypot(r.width_px, r.height_px);
    notes->push_back(
        "camera " + CameraId(r.camera_key) + ": pixel size " + FormatNumber(p * 1000, 4) +
        " um from the 35 mm equivalent focal length (approximate; --pixel-size-mm to set it)");
    return p;
  }
  throw InputError(r.image +
                   ": no pixel size (EXIF FocalPlaneXResolution, or FocalLength with "
                   "FocalLengthIn35mmFilm): pass --pixel-size-mm");
}

calib::Camera MakeCamera(const ImageRecord& r,
                         const ImageImportOptions& o,
                         std::vector<std::string>* notes) {
  const double pixel_mm = PixelSizeMm(r, o, notes);
  calib::ModelCamera model;
  if (!r.dewarp_data.empty()) {
    model = calib::DjiDewarpDataCamera(r.dewarp_data, r.dewarp_where, r.width_px, r.height_px);
  } else {
    if (!r.focal_mm || !(*r.focal_mm > 0 && *r.focal_mm <= 1e4))
      throw InputError(r.image +
                       ": no EXIF FocalLength in (0, 1e4] mm and no DewarpData: no camera");
    model.model = calib::CameraModelId::kBrownFraser10;
    model.params.assign(calib::BrownFraser10Model::kNumParams, 0.0);
    model.params[calib::BrownFraser10Model::kC] = *r.focal_mm;
  }
  model.frame = {pixel_mm, r.width_px, r.height_px};
  calib::Camera camera = calib::Camera::OfModel(model.model).WithModelCamera(model);
  camera.name = r.make_model + (r.camera_key != r.make_model ? " " + r.camera_key : "");
  return camera;
}

Exposure MakeExposure(const ImageRecord& r,
                      const std::string& camera,
                      const ImageImportOptions& o) {
  Exposure e;
  e.image = r.image;
  e.camera = camera;
  e.center_m = *r.lon_lat_alt;
  if (r.gimbal_ypr_deg) {
    e.opk_rad = OpkOfGimbal(r.gimbal_ypr_deg->x(), r.gimbal_ypr_deg->y(), r.gimbal_ypr_deg->z());
    if (o.attitude_sigma_deg)
      e.opk_sigma_rad = Eigen::Vector3d::Constant(*o.attitude_sigma_deg * kDeg);
  }
  if (r.sigma_enu_m)
    e.center_sigma_m = r.sigma_enu_m;
  else if (o.gnss_sigma_m)
    e.center_sigma_m =
        Eigen::Vector3d(o.gnss_sigma_m->x(), o.gnss_sigma_m->x(), o.gnss_sigma_m->y());
  return e;
}

// The exposures in `crs` (centres, sigmas and attitudes through the tangent plane at the flight's
// centre; the same main CRS on both sides, so the same datum pivot and origin).
Project InCrs(const Project& images, const std::string& crs) {
  Project in = images;
  in.frame.crs = crs;
  in.frame.exposures_crs = images.frame.crs;
  in.frame.source = "--crs";
  const ObjectFrame from(in.frame);
  from.FixOrigin(in);
  FrameSpec out_spec;
  out_spec.kind = FrameSpec::Kind::kCrs;
  out_spec.crs = crs;
  out_spec.source = "--crs";
  const Eigen::Vector3d origin = from.Origin();
  out_spec.has_origin = true;
  out_spec.lon_deg = origin.x(), out_spec.lat_deg = origin.y(), out_spec.h_m = origin.z();
  Project out = FromAdjustmentFrame(ToAdjustmentFrame(in, from), ObjectFrame(out_spec));
  for (const Exposure& e : out.exposures)
    if (!e.center_m.allFinite())
      throw InputError("--crs: image " + e.image + " cannot be converted to " + crs);
  out.frame.has_origin =
      false;  // the block centre (with its control points) is chosen at adjustment
  return out;
}

}  // namespace

std::string ImageCrs(const std::string& heights) {
  if (heights == "egm96") return "EPSG:4326+5773";
  if (heights == "ellipsoidal") return "EPSG:4979";
  throw ConfigError("--heights must be egm96 or ellipsoidal (got '" + heights + "')");
}

ImageImportReport ImportImages(const ImageImportOptions& o) {
  ImageImportReport report;
  Project& p = report.project;
  p.path = o.folder;
  p.frame.kind = FrameSpec::Kind::kCrs;
  p.frame.crs = ImageCrs(o.heights);
  std::error_code ec;
  if (!fs::is_directory(o.folder, ec)) throw InputError(o.folder + ": not a folder");
  std::vector<std::string> names;
  for (const fs::directory_entry& entry : fs::directory_iterator(o.folder))
    names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  std::map<std::string, const ImageRecord*> first_of_camera;
  std::vector<ImageRecord> records;
  records.reserve(names.size());
  for (const std::string& name : names) {
    const std::string path = (fs::path(o.folder) / name).string();
    if (fs::is_directory(path, ec)) {
      report.not_used.emplace_back(name, "a folder (not searched)");
      continue;
    }
    if (!IsImageName(name)) {
      report.not_used.emplace_back(name, "not a .jpg/.jpeg/.tif/.tiff file");
      continue;
    }
    if (Field(name) != name) {
      report.not_used.emplace_back(name, "a comma or control character in the name (not a CSV id)");
      continue;
    }
    records.push_back(internal::ReadImageRecord(calib::ReadImageMetadata(path), path, name));
  }
  for (const ImageRecord& r : records) {
    if (!r.lon_lat_alt) {
      report.not_used.emplace_back(r.image, r.no_position);
      continue;
    }
    const std::string id = CameraId(r.camera_key);
    const auto [it, first] = first_of_camera.emplace(id, &r);
    if (first) {
      p.cameras[id] = MakeCamera(r, o, &report.notes);
    } else if (r.width_px != it->second->width_px || r.height_px != it->second->height_px) {
      throw InputError(r.image + ": " + std::to_string(r.width_px) + " x " +
                       std::to_string(r.height_px) + " px, but camera " + id + " is " +
                       std::to_string(it->second->width_px) + " x " +
                       std::to_string(it->second->height_px) + " px (" + it->second->image + ")");
    } else if (r.dewarp_data != it->second->dewarp_data) {
      report.notes.push_back(r.image + ": another DewarpData than " + it->second->image +
                             " of camera " + id + " (the camera is that of " + it->second->image +
                             ")");
    }
    if (!r.gimbal_ypr_deg)
      report.notes.push_back(
          r.image + ": no gimbal angles: omega = phi = kappa = 0 (nadir, heading unknown)");
    p.exposures.push_back(MakeExposure(r, id, o));
    report.used_tags.insert(report.used_tags.end(), r.tags.begin(), r.tags.end());
  }
  if (p.exposures.empty()) {
    std::string why;
    for (size_t i = 0; i < report.not_used.size() && i < 5; ++i)
      why += (i ? "; " : "") + report.not_used[i].first + ": " + report.not_used[i].second;
    throw InputError(o.folder + ": no image with a GPS position (" +
                     std::to_string(report.not_used.size()) + " files not used" +
                     (why.empty() ? "" : ": " + why) + (report.not_used.size() > 5 ? "; ..." : "") +
                     ")");
  }
  if (!o.crs.empty()) p = InCrs(p, o.crs);
  return report;
}

void WriteImageImport(const ImageImportReport& report, const std::string& folder) {
  WriteProjectFolder(report.project, folder);
  WriteFileAtomically(folder + "/tags.csv", [&](std::ostream& out) {
    out << "image,quantity,tag,value\n";
    for (const UsedTag& t : report.used_tags)
      out << Field(t.image) << "," << Field(t.quantity) << "," << Field(t.tag) << ","
          << Field(t.value) << "\n";
  });
  WriteFileAtomically(folder + "/images_not_used.csv", [&](std::ostream& out) {
    out << "file,reason\n";
    for (const auto& [file, reason] : report.not_used)
      out << Field(file) << "," << Field(reason) << "\n";
  });
}

}  // namespace aerocal::triangulation
