#include "tools/camera_formats.h"

#include "calib/camera/camera_io.h"
#include "calib/core/atomic_file.h"
#include "calib/core/csv.h"
#include "tools/opencv_storage_scan.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

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
      {"opencv",
       "OpenCV FileStorage YAML/XML/JSON (camera_matrix, distortion_coefficients)",
       ReadOpenCvCamera,
       WriteOpenCvCamera,
       // k1 k2 p1 p2 [k3 [k4 k5 k6]]: a camera of another model is fitted choosing 4, 5 or 8.
       {{calib::CameraModelId::kOpenCv, {}, calib::CovarianceForm::kNone, true}},
       LooksLikeOpenCv,
       ".yml"});
  return true;
}();

}  // namespace

std::string DescribeConversion(const calib::ConversionResult& r) {
  char buffer[256];
  std::snprintf(buffer,
                sizeof(buffer),
                "residual over the format: rms %.3g px, max %.3g px at pixel (%.0f, %.0f), max "
                "within 80 %% of the half-diagonal %.3g px",
                r.residual.rms_px,
                r.residual.max_px,
                r.residual.max_at_px.x(),
                r.residual.max_at_px.y(),
                r.residual.max_inner80_px);
  return buffer;
}

calib::ConversionResult WriteCameraInFormat(const std::string& path,
                                            const calib::Camera& camera,
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
  const calib::FormatTarget target = format.target(source.camera);
  if (source.covariance &&
      calib::CovarianceHeld(format, target.model) == calib::CovarianceForm::kNone) {
    source.covariance.reset();
    std::printf("note: interior sigmas not written: %s holds no covariance\n", format.name.c_str());
  }
  std::vector<std::string> tried;
  const calib::FileConversion conversion =
      calib::ConvertCameraFileSimplest(source, target, {}, kDefaultMaxCoefficients, &tried);
  for (const std::string& line : tried) std::printf("  %s\n", line.c_str());
  calib::WriteCameraFileVerified(format, path, conversion.file);
  const calib::ConversionResult& r = conversion.result;
  std::printf("camera as %s (%s): %s; %s\n",
              format.name.c_str(),
              std::string(calib::CameraModelName(r.camera.model)).c_str(),
              r.exact ? "exact (closed form)" : "least-squares fit over the format",
              DescribeConversion(r).c_str());
  return r;
}

namespace {

// Opens `text` from memory; on failure `*error` (optional) receives cv::FileStorage's message.
bool OpenStorage(const std::string& text, cv::FileStorage* fs, std::string* error = nullptr) {
  try {
    return fs->open(text, cv::FileStorage::READ | cv::FileStorage::MEMORY) && fs->isOpened();
  } catch (const cv::Exception& e) {
    // OpenCV 4's parse errors carry "(LINE): message" in `func` and the function's name in `err`
    // (the two arguments are swapped in FileStorage::Impl::parseError): both are kept.
    if (error) *error = e.err + "\n" + e.func;
    return false;
  } catch (const std::exception&) {
    // The parser failing outside cv::Exception (std::length_error, std::bad_alloc) on input the
    // scan let through: a parse failure too, said without the library's words.
    if (error) *error = "the parser failed";
    return false;
  }
}

// A YAML file cut short (the first lines of a calibration output): the longest prefix that ends
// before a top-level key at or above the line cv::FileStorage stopped at (`error_line`) and
// parses; 0 when there is none. At most a few prefixes are parsed, so a long file with an error
// is not parsed once per line (readers stay linear, issue 37 class 7).
size_t ReadablePrefixLines(const std::vector<std::string>& lines,
                           size_t error_line,
                           cv::FileStorage* fs) {
  int attempts = 0;
  for (size_t cut = std::min(error_line, lines.size()); cut-- > 1 && attempts < 4;) {
    const std::string& line = lines[cut];
    if (line.empty() || line[0] == ' ' || line[0] == '-' || line[0] == '#' ||
        line.find(':') == std::string::npos)
      continue;
    ++attempts;
    std::string text;
    for (size_t i = 0; i < cut; ++i) text += lines[i] + "\n";
    if (OpenStorage(text, fs)) return cut;
  }
  return 0;
}

// A matrix of the file, read by cv::FileStorage after the scan bounded its header; what cv
// refuses is said with the key's line, not in cv's words.
cv::Mat ReadMatrix(const cv::FileStorage& fs, const std::string& key, const SourceRef& where) {
  cv::Mat m;
  try {
    fs[key] >> m;
  } catch (const cv::Exception&) {
    ThrowInputError(where,
                    key +
                        ": not a matrix cv::FileStorage reads (an opencv-matrix whose data "
                        "holds rows x cols values of its dt)");
  }
  if (!m.empty() && m.channels() != 1)
    ThrowInputError(where, key + " must have one channel (dt d or f)");
  if (!m.empty()) m.convertTo(m, CV_64F);
  return m;
}

// image_width / image_height: absent (0), else a whole number of pixels.
int ImageSize(const cv::FileStorage& fs, const std::string& key, const SourceRef& where) {
  const cv::FileNode node = fs[key];
  if (node.empty()) return 0;
  const double v = node.isInt() || node.isReal() ? node.real() : -1.0;
  if (!(v >= 1 && v <= 1e6 && v == std::floor(v)))
    ThrowInputError(where, key + " must be a whole number of pixels within 1 .. 1000000");
  return static_cast<int>(v);
}

// cv::FileStorage's parse error, said at its line (FILE:LINE) in the reader's words.
[[noreturn]] void ThrowUnparsable(const std::string& path, const std::string& error) {
  const auto [line, what] = OpenCvParseErrorLine(error);
  ThrowInputError({path, line}, "cv::FileStorage cannot parse the file here (" + what + ")");
}

// Opens the text in `fs`. A YAML file cut short is read up to its last complete entry (a note
// says which lines); `error` keeps cv's parse error then, so a later miss can name the cut.
// The top level must be a map: cv::FileStorage asserts (cv::Exception) on keys of another.
void OpenCameraStorage(const std::string& path,
                       const std::string& text,
                       cv::FileStorage* fs,
                       std::string* error,
                       std::vector<std::string>* notes) {
  if (!OpenStorage(text, fs, error)) {
    const std::vector<std::string> lines = SplitLines(text);
    const size_t error_line = static_cast<size_t>(OpenCvParseErrorLine(*error).first);
    const size_t kept =
        text.rfind("%YAML", 0) == 0 ? ReadablePrefixLines(lines, error_line, fs) : 0;
    if (kept == 0) ThrowUnparsable(path, *error);
    notes->push_back("the file is cut short: lines 1-" + std::to_string(kept) +
                     " read (the entry from line " + std::to_string(kept + 1) +
                     " on is incomplete)");
  }
  if (!fs->root().isMap()) {
    if (!error->empty()) ThrowUnparsable(path, *error);
    ThrowInputError(
        {path, 1},
        "the top level is not a map of keys (camera_matrix, distortion_coefficients, ...)");
  }
}

// The keys of the camera read: camera_matrix / distortion_coefficients, or a stereo file's
// M1/D1 or M2/D2 (--camera names which; required when both are there).
struct OpenCvCameraKeys {
  std::string matrix = "camera_matrix";
  std::string dist = "distortion_coefficients";
  bool stereo = false;
};

OpenCvCameraKeys FindCameraKeys(const cv::FileStorage& fs,
                                const std::string& path,
                                const OpenCvStorageScan& scan,
                                const std::string& error,
                                const calib::CameraReadOptions& options) {
  OpenCvCameraKeys keys;
  if (!fs["camera_matrix"].empty()) return keys;
  const std::string id = options.camera_id.empty() ? "1" : options.camera_id;
  if (fs["M" + id].empty() && !error.empty())
    ThrowUnparsable(path, error);  // a prefix read without the camera
  if (fs["M" + id].empty())
    ThrowInputError({path, 1},
                    options.camera_id.empty() ? "no camera_matrix (nor a stereo M1/D1)"
                                              : "no camera M" + id + "/D" + id);
  if (options.camera_id.empty() && !fs["M2"].empty())
    ThrowInputError({path, scan.Line("M2")},
                    "a stereo file: name the camera with --camera (1 or 2)");
  keys.matrix = "M" + id;
  keys.dist = "D" + id;
  keys.stereo = true;
  return keys;
}

// The forms the opencv model holds: K = [fx 0 cx; 0 fy cy; 0 0 1] and 4, 5, 8, 12 or 14
// distortion values whose thin-prism and tilt terms (from the 9th) are 0.
void CheckOpenCvMatrices(const cv::Mat& k,
                         const cv::Mat& d,
                         const OpenCvCameraKeys& keys,
                         const SourceRef& matrix_at,
                         const SourceRef& dist_at) {
  if (k.rows != 3 || k.cols != 3)
    ThrowInputError(matrix_at, keys.matrix + " must be a 3 x 3 matrix");
  const size_t n = d.total();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    ThrowInputError(
        dist_at, keys.dist + " must hold 4, 5, 8, 12 or 14 values (got " + std::to_string(n) + ")");
  for (size_t i = 8; i < n; ++i)
    if (d.at<double>(static_cast<int>(i)) != 0.0)
      ThrowInputError(dist_at,
                      keys.dist +
                          ": the thin-prism s1-s4 and tilt terms are not "
                          "modelled (must be 0)");
  if (k.at<double>(0, 1) != 0.0 || k.at<double>(1, 0) != 0.0 || k.at<double>(2, 0) != 0.0 ||
      k.at<double>(2, 1) != 0.0 || k.at<double>(2, 2) != 1.0)
    ThrowInputError(matrix_at,
                    keys.matrix +
                        " must be [fx 0 cx; 0 fy cy; 0 0 1] (skew is not "
                        "modelled)");
}

// The opencv model's parameters from K and the first (up to 8) distortion values, in OpenCV's
// order k1 k2 p1 p2 k3 k4 k5 k6; every value read must be finite and fx, fy > 0.
std::vector<double> OpenCvParams(const cv::Mat& k,
                                 const cv::Mat& d,
                                 const OpenCvCameraKeys& keys,
                                 const SourceRef& matrix_at,
                                 const SourceRef& dist_at) {
  const size_t n = d.total();
  std::vector<double> p(OpenCvModel::kNumParams, 0.0);
  p[OpenCvModel::kFx] = k.at<double>(0, 0);
  p[OpenCvModel::kFy] = k.at<double>(1, 1);
  p[OpenCvModel::kCx] = k.at<double>(0, 2);
  p[OpenCvModel::kCy] = k.at<double>(1, 2);
  static const int kOrder[8] = {OpenCvModel::kK1,
                                OpenCvModel::kK2,
                                OpenCvModel::kP1,
                                OpenCvModel::kP2,
                                OpenCvModel::kK3,
                                OpenCvModel::kK4,
                                OpenCvModel::kK5,
                                OpenCvModel::kK6};
  for (size_t i = 0; i < n && i < 8; ++i) p[kOrder[i]] = d.at<double>(static_cast<int>(i));
  for (int i : {OpenCvModel::kFx, OpenCvModel::kFy, OpenCvModel::kCx, OpenCvModel::kCy})
    if (!std::isfinite(p[i])) ThrowInputError(matrix_at, keys.matrix + ": a value is not finite");
  for (size_t i = 0; i < n && i < 8; ++i)
    if (!std::isfinite(p[kOrder[i]]))
      ThrowInputError(dist_at, keys.dist + ": a value is not finite");
  if (!(p[OpenCvModel::kFx] > 0 && p[OpenCvModel::kFy] > 0))
    ThrowInputError(matrix_at, "fx, fy must be > 0 px");
  return p;
}

}  // namespace

CameraFile ReadOpenCvCamera(const std::string& path, const calib::CameraReadOptions& options) {
  CheckInputFile(path);
  // The text is read by our reader (regular-file checks, BOM), scanned for its lines and matrix
  // sizes (tools/opencv_storage_scan.h: nothing huge reaches cv::FileStorage) and parsed from
  // memory.
  const std::string text = ReadTextFile(path);
  const OpenCvStorageScan scan = ScanOpenCvStorage(text, path);
  const auto at = [&](const std::string& key) { return SourceRef{path, scan.Line(key)}; };
  cv::FileStorage fs;
  std::string error;
  std::vector<std::string> notes;
  OpenCameraStorage(path, text, &fs, &error, &notes);
  const OpenCvCameraKeys keys = FindCameraKeys(fs, path, scan, error, options);
  const cv::Mat k = ReadMatrix(fs, keys.matrix, at(keys.matrix));
  const cv::Mat d = ReadMatrix(fs, keys.dist, at(keys.dist));
  CheckOpenCvMatrices(k, d, keys, at(keys.matrix), at(keys.dist));
  CameraFile file;
  file.notes = notes;
  file.name = std::filesystem::path(path).stem().string();
  file.chosen_by_camera_id = keys.stereo && !options.camera_id.empty();
  file.camera.model = CameraModelId::kOpenCv;
  file.camera.params = OpenCvParams(k, d, keys, at(keys.matrix), at(keys.dist));
  const int width = ImageSize(fs, "image_width", at("image_width"));
  const int height = ImageSize(fs, "image_height", at("image_height"));
  calib::internal::ResolveFormat(&file, options, at(keys.matrix), width, height, 0.0);
  return file;
}

void WriteOpenCvCamera(const std::string& path, const CameraFile& file) {
  AEROCAL_CHECK(file.camera.model == CameraModelId::kOpenCv) << "not opencv";
  const std::vector<double>& p = file.camera.params;
  // The simplest form that holds the camera: k1 k2 p1 p2 [k3 [k4 k5 k6]].
  const bool rational =
      p[OpenCvModel::kK4] != 0 || p[OpenCvModel::kK5] != 0 || p[OpenCvModel::kK6] != 0;
  std::vector<double> coefficients = {
      p[OpenCvModel::kK1], p[OpenCvModel::kK2], p[OpenCvModel::kP1], p[OpenCvModel::kP2]};
  if (rational || p[OpenCvModel::kK3] != 0) coefficients.push_back(p[OpenCvModel::kK3]);
  if (rational)
    coefficients.insert(coefficients.end(),
                        {p[OpenCvModel::kK4], p[OpenCvModel::kK5], p[OpenCvModel::kK6]});
  const std::vector<double> k = {p[OpenCvModel::kFx],
                                 0,
                                 p[OpenCvModel::kCx],
                                 0,
                                 p[OpenCvModel::kFy],
                                 p[OpenCvModel::kCy],
                                 0,
                                 0,
                                 1};
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
  WriteFileAtomically(path,
                      "%YAML:1.0\n---\nimage_width: " + std::to_string(file.camera.frame.width_px) +
                          "\nimage_height: " + std::to_string(file.camera.frame.height_px) +
                          "\ncamera_matrix:" + matrix(k, 3, 3) + "distortion_coefficients:" +
                          matrix(coefficients, static_cast<int>(coefficients.size()), 1));
}

}  // namespace aerocal::tools
