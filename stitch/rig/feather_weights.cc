#include "stitch/rig/feather_weights.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>

namespace aerocal::stitch {

namespace {

// OpenCV's 3 x 3 L2 chamfer steps in its 16-bit fixed point (distransform.cpp:
// CV_FLT_TO_FIX(0.955f, 16), CV_FLT_TO_FIX(1.3693f, 16)); its distance is t / 2^16 exactly.
const int kShift = 16;
const int kStraight = cvRound(0.955f * (1 << kShift));
const int kDiagonal = cvRound(1.3693f * (1 << kShift));
constexpr int kTile = 16;

// Tiles (kTile x kTile) that hold an uncovered pixel within Chebyshev distance `reach` of any of
// their pixels: the only ones whose distance can be below the cap.
std::vector<char> TilesNearTheBorder(
    const std::uint8_t* covered, int width, int height, int tiles_x, int tiles_y, int reach) {
  std::vector<char> open(static_cast<size_t>(tiles_x) * tiles_y, 0);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* row = covered + static_cast<size_t>(y) * width;
    char* flags = &open[static_cast<size_t>(y / kTile) * tiles_x];
    for (int tx = 0; tx < tiles_x; ++tx) {
      if (flags[tx]) continue;
      const int x0 = tx * kTile, x1 = std::min(width, x0 + kTile);
      flags[tx] = std::memchr(row + x0, 0, x1 - x0) != nullptr;
    }
  }
  const int r = (reach + kTile - 1) / kTile;  // tiles: a pixel beyond r tiles is > reach away
  std::vector<char> near(open.size(), 0);
  for (int ty = 0; ty < tiles_y; ++ty)
    for (int tx = 0; tx < tiles_x; ++tx) {
      if (!open[static_cast<size_t>(ty) * tiles_x + tx]) continue;
      for (int y = std::max(0, ty - r); y <= std::min(tiles_y - 1, ty + r); ++y)
        std::fill(&near[static_cast<size_t>(y) * tiles_x + std::max(0, tx - r)],
                  &near[static_cast<size_t>(y) * tiles_x + std::min(tiles_x - 1, tx + r)] + 1,
                  char{1});
    }
  return near;
}

// Column spans [first, last) of the near tiles in tile row ty.
std::vector<std::pair<int, int>> SpansOfTileRow(const std::vector<char>& near,
                                                int ty,
                                                int tiles_x,
                                                int width) {
  std::vector<std::pair<int, int>> spans;
  const char* flags = &near[static_cast<size_t>(ty) * tiles_x];
  for (int tx = 0; tx < tiles_x; ++tx) {
    if (!flags[tx]) continue;
    const int first = tx * kTile;
    while (tx + 1 < tiles_x && flags[tx + 1]) ++tx;
    spans.emplace_back(first, std::min(width, (tx + 1) * kTile));
  }
  return spans;
}

}  // namespace

// OpenCV's two raster passes (forward: left, upper-left, up, upper-right; backward: right,
// lower-right, down, lower-left), in the same integers, run over the near tiles only; every other
// pixel reads as the cap (its distance is above it), and every value is capped. The cap
// feather_px * 2^16 is where the weight saturates: round(t / 2^16) >= feather_px. The distance
// buffer is written only where it is read (the near spans of a row and of the rows above and
// below, one pixel wider), so the pages of the interior are never touched.
std::vector<std::uint8_t> FeatherWeights(const std::uint8_t* covered,
                                         int width,
                                         int height,
                                         int feather_px) {
  std::vector<std::uint8_t> weight(static_cast<size_t>(width) * height);
  if (weight.empty()) return weight;
  const int cap = feather_px << kShift;
  const int reach = cap / kStraight + 2;
  const int tiles_x = (width + kTile - 1) / kTile, tiles_y = (height + kTile - 1) / kTile;
  const std::vector<char> near =
      TilesNearTheBorder(covered, width, height, tiles_x, tiles_y, reach);
  std::vector<std::vector<std::pair<int, int>>> spans(tiles_y);
  for (int ty = 0; ty < tiles_y; ++ty) spans[ty] = SpansOfTileRow(near, ty, tiles_x, width);
  // Distances on rows -1..height and columns -1..width (outside the raster is no border).
  const size_t stride = width + 2;
  const std::unique_ptr<int[]> t(new int[stride * (height + 2)]);  // uninitialised on purpose
  const auto row = [&](int y) { return t.get() + static_cast<size_t>(y + 1) * stride + 1; };
  std::fill(row(-1) - 1, row(-1) - 1 + stride, cap);
  std::fill(row(height) - 1, row(height) - 1 + stride, cap);
  for (int y = 0; y < height; ++y)
    for (const int ty :
         {std::max(0, y - 1) / kTile, y / kTile, std::min(height - 1, y + 1) / kTile})
      for (const auto& [first, last] : spans[ty])
        std::fill(row(y) + first - 1, row(y) + last + 1, cap);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* in = covered + static_cast<size_t>(y) * width;
    int* d = row(y);
    const int* up = row(y - 1);
    for (const auto& [first, last] : spans[y / kTile])
      for (int x = first; x < last; ++x) {
        if (in[x] == 0) {
          d[x] = 0;
          continue;
        }
        int v = std::min(up[x - 1] + kDiagonal, up[x] + kStraight);
        v = std::min(v, up[x + 1] + kDiagonal);
        d[x] = std::min({v, d[x - 1] + kStraight, cap});
      }
  }
  for (int y = height - 1; y >= 0; --y) {
    int* d = row(y);
    const int* down = row(y + 1);
    for (const auto& [first, last] : spans[y / kTile])
      for (int x = last - 1; x >= first; --x) {
        if (d[x] <= kStraight) continue;  // no neighbour can lower it (OpenCV's shortcut too)
        int v = std::min(down[x + 1] + kDiagonal, down[x] + kStraight);
        v = std::min(v, down[x - 1] + kDiagonal);
        d[x] = std::min({d[x], v, d[x + 1] + kStraight});
      }
  }
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* in = covered + static_cast<size_t>(y) * width;
    const int* d = row(y);
    std::uint8_t* w = weight.data() + static_cast<size_t>(y) * width;
    std::memset(w, feather_px, width);  // the tiles off the band: covered, far from any border
    // lround(t / 2^16) for t >= 0 is (t + 2^15) >> 16.
    for (const auto& [first, last] : spans[y / kTile])
      for (int x = first; x < last; ++x)
        w[x] = in[x] == 0 ? 0
                          : static_cast<std::uint8_t>(
                                std::clamp((d[x] + (1 << (kShift - 1))) >> kShift, 1, feather_px));
  }
  return weight;
}

std::vector<std::uint8_t> FeatherWeightsWhole(const std::uint8_t* covered,
                                              int width,
                                              int height,
                                              int feather_px) {
  std::vector<std::uint8_t> weight(static_cast<size_t>(width) * height);
  if (weight.empty()) return weight;
  const cv::Mat inside(height, width, CV_8UC1, const_cast<std::uint8_t*>(covered));
  cv::Mat distance;
  cv::distanceTransform(inside, distance, cv::DIST_L2, 3);
  for (int r = 0; r < height; ++r) {
    const float* d = distance.ptr<float>(r);
    const std::uint8_t* in = inside.ptr<std::uint8_t>(r);
    std::uint8_t* w = weight.data() + static_cast<size_t>(r) * width;
    for (int c = 0; c < width; ++c)
      w[c] = in[c] == 0 ? 0
                        : static_cast<std::uint8_t>(
                              std::clamp(std::lround(d[c]), 1L, static_cast<long>(feather_px)));
  }
  return weight;
}

}  // namespace aerocal::stitch
