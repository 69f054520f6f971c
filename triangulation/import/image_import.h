// `aerocal import images DIR`: the exposures of a drone flight from its images' own metadata
// (EXIF and XMP, calib/metadata/), so that matching and adjustment can follow (issue 34 item 3).
//
// Per image (a .jpg/.jpeg/.tif/.tiff file directly in DIR, in name order):
// - centre: drone-dji:GpsLatitude / GpsLongitude (DJI's early GpsLongtitude too) and
//   AbsoluteAltitude where the XMP has them (more digits), else EXIF GPSLatitude / GPSLongitude
//   with their N/S, E/W refs and GPSAltitude with GPSAltitudeRef; longitude, latitude (deg) and
//   altitude (m). The altitude's datum is not recorded in the files: EXIF defines it as above sea
//   level, so it is read as an EGM96 height (`heights: egm96`, CRS EPSG:4326+5773, the geoid PROJ
//   ships) unless `heights: ellipsoidal` (EPSG:4979) is asked for (RTK drones writing
//   ellipsoidal heights). drone-dji:RelativeAltitude is listed, not used.
// - sigmas: drone-dji:RtkStdLon / RtkStdLat / RtkStdHgt (m; east, north, up) where present, else
//   `gnss_sigma_m` (horizontal, vertical), else none (the centre is not a weighted observation);
//   drone-dji:RtkFlag is listed with the values.
// - attitude: drone-dji:GimbalYawDegree / GimbalPitchDegree / GimbalRollDegree converted to
//   omega, phi, kappa relative to east / north / up at the exposure (gimbal_attitude.h), the
//   convention of a crs: frame's exposures; without them omega = phi = kappa = 0 (said). The
//   aircraft's FlightYaw/Pitch/RollDegree are listed, not used (the camera is on the gimbal).
//   An approximation: sigma `attitude_sigma_deg` when given, else none.
// - camera, one per serial (EXIF BodySerialNumber, else drone-dji:CameraSerialNumber, else make
//   and model): the format from the image data; drone-dji:DewarpData(K6) when present (the DJI
//   reader's conversion, an `opencv` camera), else `brown_fraser_10` with c = EXIF FocalLength; the
//   pixel size from `pixel_size_mm`, else EXIF FocalPlaneXResolution (+ unit), else from the 35 mm
//   equivalent focal length (43.27 mm diagonal; approximate, said). Images of one camera with
//   another format are an error; another DewarpData is said.
// Every file not used is named with the reason (no GPS position, a 0/0 position, not an image).
// Broken metadata (truncated JPEG, IFD loop, two XMP packets, a duplicated XMP property, a value
// that is no number) is an InputError naming the file: nothing is written.
// With `crs`, the centres, sigmas and attitudes are converted by PROJ into that CRS (through the
// tangent plane at the flight's centre: object_frame.h FromAdjustmentFrame).
#pragma once

#include "triangulation/block/block.h"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace aerocal::triangulation {

struct ImageImportOptions {
  std::string folder;                           // the images
  std::string crs;                              // output CRS; "" = the images' own
  std::string heights = "egm96";                // egm96 | ellipsoidal: the altitudes' datum
  std::optional<Eigen::Vector2d> gnss_sigma_m;  // (horizontal, vertical) m, > 0, without RTK std
  std::optional<double> attitude_sigma_deg;     // > 0
  double pixel_size_mm = 0;                     // > 0 overrides the images'; 0 = from the images
};

/// One value an image gave: quantity ("latitude_deg"), the tag ("XMP drone-dji:GpsLatitude",
/// "EXIF GPSLatitude") and the value as read.
struct UsedTag {
  std::string image, quantity, tag, value;
};

struct ImageImportReport {
  Project project;  // cameras, exposures, frame
  std::vector<UsedTag> used_tags;
  std::vector<std::pair<std::string, std::string>> not_used;  // file, reason
  std::vector<std::string> notes;
};

/// The CRS of the images' own coordinates for `heights` (EPSG:4326+5773 or EPSG:4979).
std::string ImageCrs(const std::string& heights);

ImageImportReport ImportImages(const ImageImportOptions& options);

/// The project folder (project.yaml, camera_<id>.yaml, exposures.csv, empty observations.csv and
/// points.csv for the matching to fill), tags.csv (image,quantity,tag,value) and
/// images_not_used.csv (file,reason); each file written atomically.
void WriteImageImport(const ImageImportReport& report, const std::string& folder);

}  // namespace aerocal::triangulation
