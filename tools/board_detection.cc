#include "tools/board_detection.h"

#include "calib/core/error.h"
#include "calib/core/progress.h"
#include "calib/core/stopwatch.h"
#include "calib/core/string_printf.h"
#include "stitch/image_io/image_codecs.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <glob.h>
#include <map>
#include <sstream>

namespace aerocal::tools {
namespace {

// cv::cornerSubPix as in OpenCV's calibration sample: 11 x 11 window, 30 iterations or 1e-4 px.
constexpr int kSubPixWindow = 5;  // half size: 11 x 11
// cv::calibrateCamera run to convergence (OpenCV's default stops after 30 iterations).
constexpr int kOpenCvIterations = 200;

std::vector<std::string> Glob(const std::string& pattern) {
  glob_t g{};
  std::vector<std::string> out;
  if (::glob(pattern.c_str(), 0, nullptr, &g) == 0)
    for (size_t i = 0; i < g.gl_pathc; ++i) out.push_back(g.gl_pathv[i]);
  globfree(&g);
  std::sort(out.begin(), out.end());
  return out;
}

// One image's marks as observations of the board points r{row}c{col}.
void AddBoardImage(const std::string& image,
                   const std::vector<Eigen::Vector2d>& marks,
                   const BoardSpec& board,
                   double sigma_px,
                   DetectedBoards* out) {
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.columns; ++c) {
      triangulation::ImageObservation o;
      o.image = image;
      o.point = StringPrintf("r%dc%d", r, c);
      o.pixel = marks[r * board.columns + c];
      o.sigma_px = sigma_px;
      out->observations.push_back(o);
    }
}

// The board's points on the plane Z = 0 (m), control with the board's design sigma.
void AddBoardPoints(const BoardSpec& board, double point_sigma_mm, DetectedBoards* out) {
  for (int r = 0; r < board.rows; ++r)
    for (int c = 0; c < board.columns; ++c) {
      triangulation::GroundPoint p;
      p.id = StringPrintf("r%dc%d", r, c);
      p.xyz_m =
          Eigen::Vector3d((board.kind == "acircles" ? 2 * c + r % 2 : c) * board.square_mm * 1e-3,
                          r * board.square_mm * 1e-3,
                          0.0);
      p.sigma_m = Eigen::Vector3d::Constant(point_sigma_mm * 1e-3);
      p.role = triangulation::PointRole::kControl;
      out->points.push_back(p);
    }
}

std::string TooFewBoards(const BoardSpec& board, size_t found, size_t given, const char* where) {
  return StringPrintf("%s: the board %s:%dx%d was found in %zu of %zu images (needs 3)",
                      where,
                      board.kind.c_str(),
                      board.columns,
                      board.rows,
                      found,
                      given);
}

}  // namespace

BoardSpec ParseBoard(const std::string& text, const std::string& option) {
  BoardSpec b;
  std::stringstream ss(text);
  std::string kind, size, square;
  std::getline(ss, kind, ':');
  std::getline(ss, size, ':');
  std::getline(ss, square, ':');
  char x = 0;
  std::stringstream sz(size);
  const bool ok = (kind == "chessboard" || kind == "circles" || kind == "acircles") &&
                  (sz >> b.columns >> x >> b.rows) && x == 'x' && b.columns >= 2 && b.rows >= 2;
  char* end = nullptr;
  b.square_mm = std::strtod(square.c_str(), &end);
  if (!ok || square.empty() || *end != '\0' || !(b.square_mm > 0))
    throw ConfigError(option +
                      ": expected chessboard|circles|acircles:COLSxROWS:SPACING_MM "
                      "(e.g. chessboard:9x6:25), got '" +
                      text + "'");
  b.kind = kind;
  return b;
}

DetectedBoards DetectBoards(const std::string& glob,
                            const BoardSpec& board,
                            double sigma_px,
                            double point_sigma_mm) {
  DetectedBoards out;
  const std::vector<std::string> files = Glob(glob);
  if (files.empty()) throw InputError("--images: no file matches '" + glob + "'");
  const cv::Size pattern(board.columns, board.rows);
  Progress progress("board detection", static_cast<long>(files.size()));
  struct Tick {  // one unit per image, also for the images skipped with `continue`
    Progress& progress;
    ~Tick() { progress.Advance(); }
  };
  for (const auto& path : files) {
    const Tick tick{progress};
    const cv::Mat gray = stitch::DecodeImageFile(path, cv::IMREAD_GRAYSCALE);
    if (gray.empty()) throw InputError(path + ": not an image OpenCV can read");
    if (out.width_px == 0) {
      out.width_px = gray.cols;
      out.height_px = gray.rows;
    } else if (gray.cols != out.width_px || gray.rows != out.height_px) {
      throw InputError(StringPrintf("%s: %d x %d px, the first image is %d x %d px",
                                    path.c_str(),
                                    gray.cols,
                                    gray.rows,
                                    out.width_px,
                                    out.height_px));
    }
    std::vector<cv::Point2f> marks;
    bool found = false;
    if (board.kind == "chessboard") {
      found = cv::findChessboardCorners(
          gray, pattern, marks, cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE);
      if (found)
        cv::cornerSubPix(
            gray,
            marks,
            cv::Size(kSubPixWindow, kSubPixWindow),
            cv::Size(-1, -1),
            cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 30, 1e-4));
    } else {
      found = cv::findCirclesGrid(
          gray,
          pattern,
          marks,
          board.kind == "acircles" ? cv::CALIB_CB_ASYMMETRIC_GRID : cv::CALIB_CB_SYMMETRIC_GRID);
    }
    if (!found || static_cast<int>(marks.size()) != board.columns * board.rows) {
      out.not_detected.push_back(path);
      continue;
    }
    const std::string image = std::filesystem::path(path).stem().string();
    out.images.push_back(image);
    out.image_paths.push_back(path);
    std::vector<Eigen::Vector2d> pixels;
    for (const cv::Point2f& m : marks) pixels.emplace_back(m.x, m.y);
    AddBoardImage(image, pixels, board, sigma_px, &out);
  }
  if (out.images.size() < 3)
    throw InputError(TooFewBoards(board, out.images.size(), files.size(), "--images"));
  AddBoardPoints(board, point_sigma_mm, &out);
  return out;
}

DetectedBoards BoardsFromMarks(
    const std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>>& marks,
    const BoardSpec& board,
    int width_px,
    int height_px,
    double sigma_px,
    double point_sigma_mm) {
  DetectedBoards out;
  out.width_px = width_px;
  out.height_px = height_px;
  const size_t count = static_cast<size_t>(board.columns) * board.rows;
  for (const auto& [image, pixels] : marks) {
    const std::string where = "corners['" + image + "']";
    if (image.empty()) throw InputError("corners: an empty image id");
    if (std::find(out.images.begin(), out.images.end(), image) != out.images.end())
      throw InputError(where + ": the image is given twice");
    if (pixels.size() != count)
      throw InputError(StringPrintf(
          "%s: %zu marks, the board has %zu (%d x %d, row-major as the detector gives them)",
          where.c_str(),
          pixels.size(),
          count,
          board.columns,
          board.rows));
    for (size_t k = 0; k < pixels.size(); ++k) {
      const Eigen::Vector2d& p = pixels[k];
      if (!(p.allFinite() && p.x() > -0.5 && p.y() > -0.5 && p.x() < width_px - 0.5 &&
            p.y() < height_px - 0.5))
        throw InputError(StringPrintf("%s[%zu]: (%g, %g) is not a pixel of the %d x %d format",
                                      where.c_str(),
                                      k,
                                      p.x(),
                                      p.y(),
                                      width_px,
                                      height_px));
    }
    out.images.push_back(image);
    out.image_paths.push_back(where);
    AddBoardImage(image, pixels, board, sigma_px, &out);
  }
  if (out.images.size() < 3)
    throw InputError(TooFewBoards(board, out.images.size(), marks.size(), "corners"));
  AddBoardPoints(board, point_sigma_mm, &out);
  return out;
}

OpenCvCalibration CalibrateWithOpenCv(const DetectedBoards& boards) {
  std::map<std::string, cv::Point3f> board;
  for (const auto& p : boards.points)
    board[p.id] =
        cv::Point3f(static_cast<float>(p.xyz_m->x()), static_cast<float>(p.xyz_m->y()), 0.0f);
  std::vector<std::vector<cv::Point3f>> object(boards.images.size());
  std::vector<std::vector<cv::Point2f>> image(boards.images.size());
  std::map<std::string, size_t> index;
  for (size_t i = 0; i < boards.images.size(); ++i) index[boards.images[i]] = i;
  for (const auto& o : boards.observations) {
    const size_t i = index.at(o.image);
    object[i].push_back(board.at(o.point));
    image[i].emplace_back(static_cast<float>(o.pixel.x()), static_cast<float>(o.pixel.y()));
  }
  cv::Mat k, d;
  std::vector<cv::Mat> rvecs, tvecs;
  OpenCvCalibration out;
  out.iterations_limit = kOpenCvIterations;
  const Stopwatch calibration_time;
  out.rms_px = cv::calibrateCamera(
      object,
      image,
      cv::Size(boards.width_px, boards.height_px),
      k,
      d,
      rvecs,
      tvecs,
      0,
      cv::TermCriteria(
          cv::TermCriteria::COUNT + cv::TermCriteria::EPS, kOpenCvIterations, DBL_EPSILON));
  out.seconds = calibration_time.Seconds();
  out.fx = k.at<double>(0, 0);
  out.fy = k.at<double>(1, 1);
  out.cx = k.at<double>(0, 2);
  out.cy = k.at<double>(1, 2);
  for (int i = 0; i < 5; ++i) out.distortion.push_back(d.at<double>(i));
  return out;
}

}  // namespace aerocal::tools
