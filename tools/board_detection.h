// Planar calibration boards detected with OpenCV for `aerocal calibrate --images GLOB --board
// SPEC`: chessboards (inner corners, cv::findChessboardCorners refined by cv::cornerSubPix with an
// 11 x 11 window to 1e-4 px, as OpenCV's calibration sample) and circle grids (cv::findCirclesGrid,
// symmetric or asymmetric; blob centres). The marks become block observations (pixel frame of
// CONVENTIONS.md = OpenCV's: the centre of the top-left pixel is (0, 0)) and the board points
// control points on the plane Z = 0 (metres), row-major: point "r{row}c{col}" at
// X = col * s, Y = row * s (asymmetric circles: X = (2 col + row % 2) * s).
// Also `cv::calibrateCamera` on the same marks, the peer of aerocal's calibration.
#pragma once

#include "triangulation/block/block.h"

#include <string>
#include <vector>

namespace aerocal::tools {

struct BoardSpec {
  std::string kind;           // chessboard | circles | acircles
  int columns = 0, rows = 0;  // inner corners / circles per row and per column
  double square_mm = 0;       // corner or circle spacing, mm
};

/// "chessboard:9x6:25", "circles:4x11:20", "acircles:4x11:20"; ConfigError naming `option`.
BoardSpec ParseBoard(const std::string& text, const std::string& option);

struct DetectedBoards {
  std::vector<triangulation::ImageObservation> observations;
  std::vector<triangulation::GroundPoint> points;
  std::vector<std::string> images, image_paths;  // detected (id = file stem), in glob order
  std::vector<std::string> not_detected;         // paths where the board was not found
  int width_px = 0, height_px = 0;
};

/// Detects the board in every file matching `glob` (sorted); InputError when none matches, an
/// image cannot be read, the images differ in size, or the board is found in fewer than 3.
DetectedBoards DetectBoards(const std::string& glob,
                            const BoardSpec& board,
                            double sigma_px,
                            double point_sigma_mm);

/// Board marks measured elsewhere (Python arrays): per image id, columns x rows marks in the
/// detector's order (row-major, pixel frame of CONVENTIONS.md), made into the same observations
/// and points as DetectBoards; the format is the camera's (width_px, height_px). InputError naming
/// the image when its count differs from the board's, a mark is not finite or lies off the format,
/// an image id is empty or given twice, or fewer than 3 images are given.
DetectedBoards BoardsFromMarks(
    const std::vector<std::pair<std::string, std::vector<Eigen::Vector2d>>>& marks,
    const BoardSpec& board,
    int width_px,
    int height_px,
    double sigma_px,
    double point_sigma_mm);

/// cv::calibrateCamera (k1, k2, p1, p2, k3; fx, fy, cx, cy free) on the detected marks.
struct OpenCvCalibration {
  double rms_px = 0, seconds = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::vector<double> distortion;  // k1, k2, p1, p2, k3
  int iterations_limit = 0;
};
OpenCvCalibration CalibrateWithOpenCv(const DetectedBoards& boards);

}  // namespace aerocal::tools
