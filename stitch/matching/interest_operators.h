// Interest operators for tie-point detection in low-contrast aerial overlaps.
//
// Wallis filter (Wallis 1976, in the form of Baltsavias 1991): a locally adaptive contrast
// enhancement that forces every window to a target mean m_f and standard deviation s_f,
//   g' = (g - m) c s_f / (c s + (1 - c) s_f) + b m_f + (1 - b) m,
// with m, s the local mean and standard deviation over a square window, c the contrast expansion
// (0..1) and b the brightness forcing (0..1).
//
// Foerstner interest operator (Foerstner & Guelch 1987): with the structure tensor N summed over a
// small window of grey-value gradients, the point precision (interest) w = det N / trace N and the
// roundness of the error ellipse q = 4 det N / trace^2 N. Points are local maxima of w with
// q > q_min and w > w_factor * mean(w) (Foerstner's rule of thumb: 0.5 .. 1.5 times the mean).
#pragma once

#include "stitch/image_io/gray_image.h"

#include <Eigen/Core>

#include <vector>

namespace aerocal::stitch {

struct WallisOptions {
  int window_px = 31;          // odd window side for local mean and standard deviation, >= 3
  double target_mean = 127.0;  // m_f, DN
  double target_std = 50.0;    // s_f, DN, > 0
  double contrast = 0.8;       // c, 0 .. 1
  double brightness = 0.9;     // b, 0 .. 1
  void Validate() const;       // throws ConfigError naming the field
};

GrayImage WallisFilter(const GrayImage& image, const WallisOptions& options);

struct FoerstnerOptions {
  int window_px = 5;           // odd side of the structure tensor window, >= 3
  double min_roundness = 0.5;  // q_min, 0 .. 1
  double weight_factor = 1.0;  // w > weight_factor * mean(w), > 0
  int suppression_px = 9;      // odd side of the non-maximum suppression window, >= 3
  int max_points = 4000;       // strongest kept, > 0
  void Validate() const;
};

struct InterestPoint {
  Eigen::Vector2d position;  // pixel (col, row) of the window centre
  double weight = 0;         // w = det N / trace N
  double roundness = 0;      // q
};

/// Foerstner points, strongest first (ties broken by row, then column: deterministic).
std::vector<InterestPoint> DetectFoerstner(const GrayImage& image, const FoerstnerOptions& options);

}  // namespace aerocal::stitch
