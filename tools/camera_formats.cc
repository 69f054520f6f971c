#include "tools/camera_formats.h"

#include <cstdio>
#include <filesystem>

#include <opencv2/core.hpp>

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"

namespace aerocal::tools {
namespace {

using calib::CameraFile;
using calib::CameraModelId;
using calib::FormatTarget;
using calib::ModelCamera;
using calib::OpenCvModel;

bool LooksLikeOpenCv(const std::string& head, const std::string&) {
  // cv::FileStorage tags every matrix (YAML !!opencv-matrix, XML and JSON type_id).
  return head.find("opencv-matrix") != std::string::npos ||
         head.find("<opencv_storage>") != std::string::npos;
}

// The opencv row of calib's registry (OpenCV stays out of calib).
const bool kOpenCvRegistered = [] {
  calib::RegisterCameraFormat(
      {"opencv", "OpenCV FileStorage YAML/XML/JSON (camera_matrix, distortion_coefficients)",
       ReadOpenCvCamera, WriteOpenCvCamera,
       calib::OpenCvTarget, LooksLikeOpenCv, ".yml"});
  return true;
}();

}  // namespace

std::string DescribeConversion(const calib::ConversionResult& r) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer),
                "residual over the format: rms %.3g px, max %.3g px at pixel (%.0f, %.0f), max "
                "within 80 %% of the half-diagonal %.3g px",
                r.residual.rms_px, r.residual.max_px, r.residual.max_at_px.x(),
                r.residual.max_at_px.y(), r.residual.max_inner80_px);
  return buffer;
}

calib::ConversionResult WriteCameraInFormat(const std::string& path, const calib::Camera& camera,
                                            const std::string& format_name,
                                            const calib::InteriorParams* posterior_sigma) {
  const CameraFormat& format = FindCameraFormat(format_name, "--camera-format");
  if (format.name == "aerocal") {
    calib::WriteCamera(path, camera);
    calib::ConversionResult same;
    same.exact = same.acceptable = true;
    return same;
  }
  CameraFile source = calib::CameraFileFromCamera(camera);
  if (posterior_sigma) {
    const Eigen::Map<const Eigen::VectorXd> sigma(posterior_sigma->data(), posterior_sigma->size());
    source.covariance = Eigen::MatrixXd(sigma.cwiseAbs2().asDiagonal());
  }
  if (source.covariance && !format.holds_covariance) {
    source.covariance.reset();
    std::printf("note: interior sigmas not written: %s holds no covariance\n", format.name.c_str());
  }
  std::vector<std::string> tried;
  const calib::FileConversion conversion = calib::ConvertCameraFileSimplest(
      source, format.target(source.camera), {}, kDefaultMaxCoefficients, &tried);
  for (const std::string& line : tried) std::printf("  %s\n", line.c_str());
  calib::WriteCameraFileVerified(format, path, conversion.file);
  const calib::ConversionResult& r = conversion.result;
  std::printf("camera as %s (%s): %s; %s\n", format.name.c_str(),
              std::string(calib::CameraModelName(r.camera.model)).c_str(),
              r.exact ? "exact (closed form)" : "least-squares fit over the format",
              DescribeConversion(r).c_str());
  return r;
}

namespace {

bool OpenStorage(const std::string& text, cv::FileStorage* fs) {
  try {
    return fs->open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY) && fs->isOpened();
  } catch (const cv::Exception&) {
    return false;
  }
}

// A YAML file cut short (the first lines of a calibration output): the longest prefix that ends
// before a top-level key and parses; 0 when there is none.
size_t ReadablePrefixLines(const std::vector<std::string>& lines, cv::FileStorage* fs) {
  for (size_t cut = lines.size(); cut-- > 1;) {
    const std::string& line = lines[cut];
    if (line.empty() || line[0] == ' ' || line[0] == '-' || line[0] == '#' ||
        line.find(':') == std::string::npos)
      continue;
    std::string text;
    for (size_t i = 0; i < cut; ++i) text += lines[i] + "\n";
    if (OpenStorage(text, fs)) return cut;
  }
  return 0;
}

}  // namespace

CameraFile ReadOpenCvCamera(const std::string& path, const calib::CameraReadOptions& options) {
  CheckInputFile(path);
  cv::FileStorage fs;
  std::vector<std::string> notes;
  // The text is read by our reader (regular-file checks, BOM) and parsed from memory.
  const std::string text = ReadTextFile(path);
  if (!OpenStorage(text, &fs)) {
    const std::vector<std::string> lines = SplitLines(text);
    const size_t kept = text.rfind("%YAML", 0) == 0 ? ReadablePrefixLines(lines, &fs) : 0;
    if (kept == 0) ThrowInputError({path, 1}, "cv::FileStorage cannot parse it");
    notes.push_back("the file is cut short: lines 1-" + std::to_string(kept) +
                    " read (the entry from line " + std::to_string(kept + 1) +
                    " on is incomplete)");
  }
  std::string matrix_key = "camera_matrix", dist_key = "distortion_coefficients";
  if (fs["camera_matrix"].empty()) {
    const std::string id = options.camera_id.empty() ? "1" : options.camera_id;
    if (fs["M" + id].empty())
      ThrowInputError({path, 1}, options.camera_id.empty()
                                     ? "no camera_matrix (nor a stereo M1/D1)"
                                     : "no camera M" + id + "/D" + id);
    if (options.camera_id.empty() && !fs["M2"].empty())
      ThrowInputError({path, 1}, "a stereo file: name the camera with --camera (1 or 2)");
    matrix_key = "M" + id;
    dist_key = "D" + id;
  }
  cv::Mat k, d;
  try {
    fs[matrix_key] >> k;
    fs[dist_key] >> d;
  } catch (const cv::Exception& e) {
    ThrowInputError({path, 0}, matrix_key + " / " + dist_key + ": " + e.err);
  }
  if (k.rows != 3 || k.cols != 3) ThrowInputError({path, 0}, matrix_key + " must be a 3 x 3 matrix");
  k.convertTo(k, CV_64F);
  if (!d.empty()) d.convertTo(d, CV_64F);
  const size_t n = d.total();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    ThrowInputError({path, 0}, dist_key + " must hold 4, 5, 8, 12 or 14 values (got " +
                                   std::to_string(n) + ")");
  for (size_t i = 8; i < n; ++i)
    if (d.at<double>(static_cast<int>(i)) != 0.0)
      ThrowInputError({path, 0}, dist_key + ": the thin-prism s1-s4 and tilt terms are not "
                                            "modelled (must be 0)");
  if (k.at<double>(0, 1) != 0.0 || k.at<double>(1, 0) != 0.0 || k.at<double>(2, 0) != 0.0 ||
      k.at<double>(2, 1) != 0.0 || k.at<double>(2, 2) != 1.0)
    ThrowInputError({path, 0}, matrix_key + " must be [fx 0 cx; 0 fy cy; 0 0 1] (skew is not "
                                            "modelled)");
  CameraFile file;
  file.notes = notes;
  file.name = std::filesystem::path(path).stem().string();
  file.camera.model = CameraModelId::kOpenCv;
  file.camera.params.assign(OpenCvModel::kNumParams, 0.0);
  std::vector<double>& p = file.camera.params;
  p[OpenCvModel::kFx] = k.at<double>(0, 0);
  p[OpenCvModel::kFy] = k.at<double>(1, 1);
  p[OpenCvModel::kCx] = k.at<double>(0, 2);
  p[OpenCvModel::kCy] = k.at<double>(1, 2);
  if (!(p[0] > 0 && p[1] > 0)) ThrowInputError({path, 0}, "fx, fy must be > 0 px");
  static const int kOrder[8] = {OpenCvModel::kK1, OpenCvModel::kK2, OpenCvModel::kP1,
                                OpenCvModel::kP2, OpenCvModel::kK3, OpenCvModel::kK4,
                                OpenCvModel::kK5, OpenCvModel::kK6};
  for (size_t i = 0; i < n && i < 8; ++i) p[kOrder[i]] = d.at<double>(static_cast<int>(i));
  for (double v : p)
    if (!std::isfinite(v)) ThrowInputError({path, 0}, "a parameter is not finite");
  int width = 0, height = 0;
  if (!fs["image_width"].empty()) width = static_cast<int>(fs["image_width"]);
  if (!fs["image_height"].empty()) height = static_cast<int>(fs["image_height"]);
  calib::internal::ResolveFormat(&file, options, {path, 0}, width, height, 0.0);
  return file;
}

void WriteOpenCvCamera(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == CameraModelId::kOpenCv) << "not opencv";
  const std::vector<double>& p = file.camera.params;
  // The simplest form that holds the camera: k1 k2 p1 p2 [k3 [k4 k5 k6]].
  const bool rational = p[OpenCvModel::kK4] != 0 || p[OpenCvModel::kK5] != 0 || p[OpenCvModel::kK6] != 0;
  std::vector<double> coefficients = {p[OpenCvModel::kK1], p[OpenCvModel::kK2],
                                      p[OpenCvModel::kP1], p[OpenCvModel::kP2]};
  if (rational || p[OpenCvModel::kK3] != 0) coefficients.push_back(p[OpenCvModel::kK3]);
  if (rational)
    coefficients.insert(coefficients.end(),
                        {p[OpenCvModel::kK4], p[OpenCvModel::kK5], p[OpenCvModel::kK6]});
  const std::vector<double> k = {p[OpenCvModel::kFx], 0, p[OpenCvModel::kCx], 0,
                                 p[OpenCvModel::kFy], p[OpenCvModel::kCy], 0, 0, 1};
  const std::string extension = std::filesystem::path(path).extension().string();
  if (extension == ".xml" || extension == ".json") {
    cv::FileStorage fs(extension, cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    fs << "image_width" << file.camera.frame.width_px;
    fs << "image_height" << file.camera.frame.height_px;
    fs << "camera_matrix" << cv::Mat(k, true).reshape(1, 3);
    fs << "distortion_coefficients" << cv::Mat(coefficients, true);
    WriteFileAtomically(path, fs.releaseAndGetString());
    return;
  }
  // YAML in cv::FileStorage's own layout, the numbers in the shortest form that reads back to
  // the same double (cv::FileStorage prints %.16e: 0.009 as 8.9999999999999997e-03).
  const auto matrix = [](const std::vector<double>& values, int rows, int cols) {
    std::string text = " !!opencv-matrix\n   rows: " + std::to_string(rows) +
                       "\n   cols: " + std::to_string(cols) + "\n   dt: d\n   data: [ ";
    for (size_t i = 0; i < values.size(); ++i)
      text += (i ? ", " : "") + calib::internal::ShortestNumber(values[i]);
    return text + " ]\n";
  };
  WriteFileAtomically(path, "%YAML:1.0\n---\nimage_width: " +
                                std::to_string(file.camera.frame.width_px) + "\nimage_height: " +
                                std::to_string(file.camera.frame.height_px) + "\ncamera_matrix:" +
                                matrix(k, 3, 3) + "distortion_coefficients:" +
                                matrix(coefficients, static_cast<int>(coefficients.size()), 1));
}

}  // namespace aerocal::tools
