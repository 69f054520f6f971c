// The camera-file formats of `aerocal camera` and `--camera-format`: calib's registry
// (calib/camera/formats/camera_formats.h CameraFormats(), the formats and their conventions) plus
// the opencv row registered here, because cv::FileStorage and OpenCV stay out of calib.
#pragma once

#include "calib/camera/formats/camera_formats.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace aerocal::tools {

// The registry lives in calib (camera_formats.h); this layer adds the OpenCV FileStorage row.
using calib::CameraFormat;
using calib::CameraFormatNames;
using calib::CameraFormats;
using calib::FindCameraFormat;

/// Distortion coefficients written by default into OpenCV-form files (k1 k2 p1 p2 k3).
inline constexpr int kDefaultMaxCoefficients = 5;

/// One line on how exactly a conversion holds: residual RMS, max and where, max within 80 %.
std::string DescribeConversion(const calib::ConversionResult& result);

/// `--camera-format` of adjust, calibrate and flight: writes our adjusted camera to `path` in the
/// format named `format_name` (CameraFormats()). `aerocal` writes our YAML exactly as before
/// (sub-images and reference points included); any other format converts our camera into the
/// format's model first (exact where equivalent, else a least-squares fit over the format, said
/// with its residual on stdout), carrying sigmas where the format holds a covariance (metashape,
/// australis) and saying so where it drops them: `posterior_sigma` (the adjustment's standard
/// deviations, table order and units, 0 = fixed) when given, else the camera's interior_sigma.
/// Returns the conversion (exact, with a zero residual, for `aerocal`).
calib::ConversionResult WriteCameraInFormat(const std::string& path,
                                            const calib::Camera& camera,
                                            const std::string& format_name,
                                            const calib::InteriorParams* posterior_sigma = nullptr);

/// OpenCV's calibration file as cv::FileStorage reads and writes it (YAML, XML or JSON by the
/// extension): camera_matrix 3x3, distortion_coefficients (k1 k2 p1 p2 [k3 [k4 k5 k6]]),
/// image_width, image_height; or a stereo file's M1/D1, M2/D2 (--camera 1 / 2).
calib::CameraFile ReadOpenCvCamera(const std::string& path,
                                   const calib::CameraReadOptions& options);
void WriteOpenCvCamera(const std::string& path, const calib::CameraFile& camera);

}  // namespace aerocal::tools
