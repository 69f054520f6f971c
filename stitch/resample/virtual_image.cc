#include "stitch/resample/virtual_image.h"

#include "calib/core/error.h"
#include "calib/core/stopwatch.h"
#include "stitch/resample/fast_strip.h"
#include "stitch/resample/resample_window.h"

#include <Eigen/LU>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>

namespace aerocal::stitch {
namespace {

using internal::ColumnSpan;
using internal::CoveredColumns;
using internal::Window;

// Keys (1981) cubic convolution weights, a = -0.5, for fractional offset t in [0, 1].
inline void CubicWeights(float t, float* w) {
  const float t2 = t * t, t3 = t2 * t;
  w[0] = -0.5f * t3 + t2 - 0.5f * t;
  w[1] = 1.5f * t3 - 2.5f * t2 + 1.0f;
  w[2] = -1.5f * t3 + 2.0f * t2 + 0.5f * t;
  w[3] = 0.5f * t3 - 0.5f * t2;
}

// Adds the sample of the window at (u, v) (window pixels, inside) to out[0 .. kBands).
template <typename T, int kBands, Interpolation kInterpolation>
inline void AddSample(const Window& win, float u, float v, float* out) {
  const T* data = reinterpret_cast<const T*>(win.bytes.data());
  const int stride = win.w * kBands;
  if constexpr (kInterpolation == Interpolation::kBilinear) {
    const int iu = std::min(static_cast<int>(u), std::max(win.w - 2, 0));
    const int iv = std::min(static_cast<int>(v), std::max(win.h - 2, 0));
    const float fu = u - iu, fv = v - iv;
    const int du = win.w > 1 ? kBands : 0, dv = win.h > 1 ? stride : 0;
    const T* p = data + iv * stride + iu * kBands;
    for (int b = 0; b < kBands; ++b) {
      const float top = p[b] + fu * (static_cast<float>(p[b + du]) - p[b]);
      const float bottom = p[b + dv] + fu * (static_cast<float>(p[b + dv + du]) - p[b + dv]);
      out[b] += top + fv * (bottom - top);
    }
  } else {
    const int iu = static_cast<int>(u), iv = static_cast<int>(v);
    float wu[4], wv[4];
    CubicWeights(u - iu, wu);
    CubicWeights(v - iv, wv);
    int cols[4], rows[4];
    for (int k = 0; k < 4; ++k) {
      cols[k] = std::clamp(iu - 1 + k, 0, win.w - 1) * kBands;
      rows[k] = std::clamp(iv - 1 + k, 0, win.h - 1) * stride;
    }
    for (int b = 0; b < kBands; ++b) {
      float acc = 0.0f;
      for (int r = 0; r < 4; ++r) {
        const T* row = data + rows[r] + b;
        acc += wv[r] * (wu[0] * row[cols[0]] + wu[1] * row[cols[1]] + wu[2] * row[cols[2]] +
                        wu[3] * row[cols[3]]);
      }
      out[b] += acc;
    }
  }
}

// One virtual row V of one window: its covered run [first, last] (positions are stepped from
// `first`), the columns made, and the row's sums and counts (indexed by virtual column).
struct RowTask {
  double V;
  int first, last;
  ColumnSpan columns;
  float* sum;
  std::uint8_t* count;
};

// kAffine: the projective row of the map is (0, 0, 1), so w = 1 and no division is needed.
// Positions are stepped from column `first` (the covered run's start) whatever `columns` the
// strip makes, so a region's pixels get the whole row's bits.
template <typename T, int kBands, Interpolation kInterpolation, bool kAffine>
void AccumulateRow(const Window& win, const RowTask& row) {
  const auto [V, first, last, columns, sum, count] = row;
  const Eigen::Matrix3d& m = win.sub_from_virtual;
  double x =
      m(0, 0) * first + m(0, 1) * V + m(0, 2) - win.x0 * (m(2, 0) * first + m(2, 1) * V + m(2, 2));
  double y =
      m(1, 0) * first + m(1, 1) * V + m(1, 2) - win.y0 * (m(2, 0) * first + m(2, 1) * V + m(2, 2));
  double w = m(2, 0) * first + m(2, 1) * V + m(2, 2);
  const double dx = m(0, 0) - win.x0 * m(2, 0), dy = m(1, 0) - win.y0 * m(2, 0), dw = m(2, 0);
  const float max_u = static_cast<float>(win.w - 1), max_v = static_cast<float>(win.h - 1);
  const int from = std::max(first, columns.first), to = std::min(last, columns.last);
  for (int c = first; c < from; ++c) x += dx, y += dy, w += dw;
  for (int c = from; c <= to; ++c, x += dx, y += dy, w += dw) {
    const float u = std::clamp(static_cast<float>(kAffine ? x : x / w), 0.0f, max_u);
    const float v = std::clamp(static_cast<float>(kAffine ? y : y / w), 0.0f, max_v);
    ++count[c];
    AddSample<T, kBands, kInterpolation>(win, u, v, sum + c * kBands);
  }
}

// Interpolates the correction grid along virtual row V into per-column (du, dv) for [first, last].
void CorrectionAlongRow(const MapCorrectionGrid& g, double V, int first, int last, float* duv) {
  const double gv = V / g.step_px;
  const int j = std::min(static_cast<int>(gv), g.rows - 2);
  const float fv = static_cast<float>(gv - j);
  const float* top = g.duv.data() + 2 * static_cast<size_t>(j) * g.cols;
  const float* bottom = top + 2 * g.cols;
  const float inv_step = 1.0f / g.step_px;
  for (int c = first; c <= last; ++c) {
    const float gu = c * inv_step;
    const int i = std::min(static_cast<int>(gu), g.cols - 2);
    const float fu = gu - i;
    for (int k = 0; k < 2; ++k) {
      const float t = top[2 * i + k] + fu * (top[2 * i + 2 + k] - top[2 * i + k]);
      const float b = bottom[2 * i + k] + fu * (bottom[2 * i + 2 + k] - bottom[2 * i + k]);
      duv[2 * (c - first) + k] = t + fv * (b - t);
    }
  }
}

// With a correction grid: (u, v) = projectivity + interpolated correction, coverage per pixel.
// The projectivity is stepped from column `first` (0: the whole row), the correction is per
// column; only `columns` are sampled.
template <typename T, int kBands, Interpolation kInterpolation>
void AccumulateCorrectedRow(const Window& win, const RowTask& row) {
  const auto [V, first, last, columns, sum, count] = row;
  const int from = std::max(first, columns.first), to = std::min(last, columns.last);
  if (from > to) return;
  thread_local std::vector<float> duv;
  duv.resize(2 * static_cast<size_t>(to - from + 1));
  CorrectionAlongRow(*win.correction, V, from, to, duv.data());
  const Eigen::Matrix3d& m = win.sub_from_virtual;
  double x = m(0, 0) * first + m(0, 1) * V + m(0, 2);
  double y = m(1, 0) * first + m(1, 1) * V + m(1, 2);
  double w = m(2, 0) * first + m(2, 1) * V + m(2, 2);
  const float max_u = static_cast<float>(win.width_px - 1),
              max_v = static_cast<float>(win.height_px - 1);
  for (int c = first; c < from; ++c) x += m(0, 0), y += m(1, 0), w += m(2, 0);
  for (int c = from; c <= to; ++c, x += m(0, 0), y += m(1, 0), w += m(2, 0)) {
    const float su = static_cast<float>(x / w) + duv[2 * (c - from)];
    const float sv = static_cast<float>(y / w) + duv[2 * (c - from) + 1];
    if (!(w > 0 && su >= 0.0f && su <= max_u && sv >= 0.0f && sv <= max_v)) continue;
    // The strip's window holds every such sample (ResampleVirtualImage); one outside it is
    // dropped, never clamped to the window's edge (that would be another pixel's value).
    const float u = su - win.x0, v = sv - win.y0;
    if (!(u >= 0.0f && u <= win.w - 1 && v >= 0.0f && v <= win.h - 1)) continue;
    ++count[c];
    AddSample<T, kBands, kInterpolation>(win, u, v, sum + c * kBands);
  }
}

template <typename T, int kBands>
void AccumulateRow(const Window& win, Interpolation interpolation, const RowTask& row) {
  constexpr Interpolation kLinear = Interpolation::kBilinear, kCubic = Interpolation::kBicubic;
  if (win.correction) {
    if (interpolation == kLinear)
      AccumulateCorrectedRow<T, kBands, kLinear>(win, row);
    else
      AccumulateCorrectedRow<T, kBands, kCubic>(win, row);
    return;
  }
  const bool affine = win.sub_from_virtual(2, 0) == 0.0 && win.sub_from_virtual(2, 1) == 0.0 &&
                      win.sub_from_virtual(2, 2) == 1.0;
  if (interpolation == kLinear) {
    if (affine)
      AccumulateRow<T, kBands, kLinear, true>(win, row);
    else
      AccumulateRow<T, kBands, kLinear, false>(win, row);
  } else {
    if (affine)
      AccumulateRow<T, kBands, kCubic, true>(win, row);
    else
      AccumulateRow<T, kBands, kCubic, false>(win, row);
  }
}

// Virtual rows [y0, y0 + rows), columns `columns` (of a format `width` wide) into `strip`.
template <typename T, int kBands>
void ResampleStrip(std::vector<Window>& windows,
                   const ResampleOptions& options,
                   int width,
                   ColumnSpan columns,
                   int y0,
                   int rows,
                   std::vector<std::uint8_t>* strip,
                   std::uint8_t* coverage,
                   std::atomic<long>* covered,
                   std::atomic<long>* overlap) {
  const float max_value = static_cast<float>(std::numeric_limits<T>::max());
  const float fill = std::clamp(static_cast<float>(options.fill), 0.0f, max_value);
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    std::vector<float> sum(static_cast<size_t>(width) * kBands);  // indexed by virtual column
    std::vector<std::uint8_t> count(width);
    long n_covered = 0, n_overlap = 0;
    for (int r = range.begin(); r < range.end(); ++r) {
      std::fill(
          sum.begin() + columns.first * kBands, sum.begin() + (columns.last + 1) * kBands, 0.0f);
      std::fill(count.begin() + columns.first, count.begin() + columns.last + 1, 0);
      const double V = y0 + r;
      for (const Window& win : windows) {
        int first = 0, last = -1;
        if (!win.used || (!win.correction && !CoveredColumns(win, V, width, &first, &last)))
          continue;
        if (win.correction) {  // the corrected map may reach beyond the projectivity's columns
          first = 0;
          last = width - 1;
        }
        AccumulateRow<T, kBands>(
            win, options.interpolation, {V, first, last, columns, sum.data(), count.data()});
      }
      T* out =
          reinterpret_cast<T*>(strip->data()) + static_cast<size_t>(r) * columns.Count() * kBands;
      for (int c = columns.first; c <= columns.last; ++c) {
        const int n = count[c];
        n_covered += n > 0;
        n_overlap += n > 1;
        const float scale = n > 0 ? 1.0f / n : 0.0f;
        const int o = (c - columns.first) * kBands;
        if (coverage)
          coverage[static_cast<size_t>(r) * columns.Count() + (c - columns.first)] =
              n > 0 ? 255 : 0;
        for (int b = 0; b < kBands; ++b) {
          const float value = n > 0 ? sum[c * kBands + b] * scale : fill;
          out[o + b] = static_cast<T>(std::clamp(value + 0.5f, 0.0f, max_value));
        }
      }
    }
    *covered += n_covered;
    *overlap += n_overlap;
  });
}

// One window per sub-image: its format, the inverse mapping (virtual -> sub-image) and its
// correction grid; InputError when a source does not match its sub-image or the first source.
std::vector<Window> MakeWindows(const calib::Camera& camera,
                                const std::vector<RasterSource*>& sources,
                                const std::vector<MapCorrectionGrid>& corrections) {
  const RasterInfo first = sources.front()->Info();
  std::vector<Window> windows(sources.size());
  for (size_t k = 0; k < sources.size(); ++k) {
    const auto& s = camera.subimages[k];
    const RasterInfo info = sources[k]->Info();
    if (info.width != s.width_px || info.height != s.height_px)
      throw InputError("sub-image " + s.id + ": image is " + std::to_string(info.width) + " x " +
                       std::to_string(info.height) + " px, the camera file says " +
                       std::to_string(s.width_px) + " x " + std::to_string(s.height_px));
    if (info.bits != first.bits || info.bands != first.bands)
      throw InputError("sub-image " + s.id + ": " + std::to_string(info.bits) + " bit, " +
                       std::to_string(info.bands) + " band(s), unlike sub-image " +
                       camera.subimages[0].id);
    windows[k].width_px = s.width_px;
    windows[k].height_px = s.height_px;
    windows[k].sub_from_virtual = calib::HomographyFromParams(s.model, s.params.data()).inverse();
    // Scaled so that w > 0 where the virtual ray lies in front of the sub-image (its pixel (0, 0)
    // maps to w = 1 through the inverse); CoveredColumns relies on it. A negative (2, 2) (virtual
    // pixel (0, 0) behind the sub-image's camera, e.g. a head tilted away from that corner) must
    // not flip the sign. Affine: the last row stays 0 0 1.
    windows[k].sub_from_virtual /= std::abs(windows[k].sub_from_virtual(2, 2));
    if (!corrections.empty() && corrections[k].step_px > 0) {
      const MapCorrectionGrid& g = corrections[k];
      AEROCAL_CHECK(g.cols >= 2 && g.rows >= 2 && (g.cols - 1) * g.step_px >= camera.width_px - 1 &&
                    (g.rows - 1) * g.step_px >= camera.height_px - 1 &&
                    g.duv.size() == 2 * static_cast<size_t>(g.cols) * g.rows)
          << "correction grid of sub-image " << s.id << " does not cover the virtual format";
      windows[k].correction = &g;
    }
  }
  return windows;
}

// The strip's rows [y0, y0 + rows) of a virtual image `width` wide, and how its windows are read.
struct StripGeometry {
  int width, y0, rows;
  int margin;  // interpolation support, px
  bool fast;   // the fast path (fast_strip.h) reads the windows
  RasterInfo source;
};

// The window of sub-image `win` for a strip: the bounding box of the strip's corners mapped into
// it, plus the interpolation margin and the correction's reach; read from `source` (or, on the
// fast path, pointed at in place).
void PrepareWindow(const StripGeometry& g, RasterSource* source, Window* win_out) {
  Window& win = *win_out;
  // A projectivity maps the strip's rectangle onto the quadrilateral of its corners when w > 0
  // at all four (w is affine in (U, V), so then positive over the whole strip, and straight
  // lines stay straight): the corners' bounding box is exact. A corner at or behind the
  // sub-image's horizon (w <= 0, a tilted head under a wide virtual image) makes the image
  // of the strip unbounded and the corners' box meaningless: then the whole format. A
  // correction moves (u, v) by up to max_abs_px.
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (double U : {0.0, g.width - 1.0})
    for (double V : {static_cast<double>(g.y0), g.y0 + g.rows - 1.0}) {
      const Eigen::Vector3d p = win.sub_from_virtual * Eigen::Vector3d(U, V, 1.0);
      if (!(p.z() > 0)) {
        u0 = v0 = -1e300;
        u1 = v1 = 1e300;
        break;
      }
      u0 = std::min(u0, p.x() / p.z());
      u1 = std::max(u1, p.x() / p.z());
      v0 = std::min(v0, p.y() / p.z());
      v1 = std::max(v1, p.y() / p.z());
    }
  u0 = std::max(u0, -1e9), v0 = std::max(v0, -1e9), u1 = std::min(u1, 1e9), v1 = std::min(v1, 1e9);
  const int extra =
      win.correction ? static_cast<int>(std::ceil(win.correction->max_abs_px)) + 1 : 0;
  const int x0 = std::max(0, static_cast<int>(std::floor(u0)) - g.margin - extra);
  const int x1 = std::min(win.width_px - 1, static_cast<int>(std::ceil(u1)) + g.margin + extra);
  const int wy0 = std::max(0, static_cast<int>(std::floor(v0)) - g.margin - extra);
  const int wy1 = std::min(win.height_px - 1, static_cast<int>(std::ceil(v1)) + g.margin + extra);
  win.used = x0 <= x1 && wy0 <= wy1;
  if (!win.used) return;
  win.x0 = x0;
  win.y0 = wy0;
  win.w = x1 - x0 + 1;
  win.h = wy1 - wy0 + 1;
  // Plus a row and two samples of padding: the fast path reads the last column's and row's
  // right and lower neighbours with weight 0.
  const int sample_bytes = g.source.bands * g.source.BytesPerSample();
  if (g.fast && source->Samples() && wy1 + 2 < win.height_px) {
    // In place: the padding the fast path reads (the next row and its next sample) exists.
    win.samples = source->Samples() + (static_cast<size_t>(wy0) * win.width_px + x0) * sample_bytes;
    win.stride = win.width_px;
    return;
  }
  win.bytes.resize(static_cast<size_t>(win.w) * (win.h + 1) * sample_bytes + 2 * sample_bytes);
  source->ReadWindow(win.x0, win.y0, win.w, win.h, win.bytes.data());
  win.samples = win.bytes.data();
  win.stride = win.w;
}

// Where a strip's output goes: its samples, its coverage bytes (none: nullptr) and the counts.
struct StripOutput {
  std::vector<std::uint8_t>* strip;
  std::uint8_t* coverage_rows;
  std::atomic<long>* covered;
  std::atomic<long>* overlap;
};

// Rows [r0, r0 + n) of the strip, `columns` of each, by the path and sample type of `g`.
void ResampleRows(std::vector<Window>& windows,
                  const ResampleOptions& options,
                  const StripGeometry& g,
                  float fill,
                  const ColumnSpan& columns,
                  int r0,
                  int n,
                  const StripOutput& o) {
  const int width = g.width;
  const bool eight = g.source.bits == 8, one_band = g.source.bands == 1;
  if (g.fast && eight)
    internal::ResampleStripFast<std::uint8_t>(windows,
                                              fill,
                                              width,
                                              columns,
                                              r0,
                                              n,
                                              o.strip->data(),
                                              o.coverage_rows,
                                              o.covered,
                                              o.overlap);
  else if (g.fast)
    internal::ResampleStripFast<std::uint16_t>(windows,
                                               fill,
                                               width,
                                               columns,
                                               r0,
                                               n,
                                               o.strip->data(),
                                               o.coverage_rows,
                                               o.covered,
                                               o.overlap);
  else if (eight && one_band)
    ResampleStrip<std::uint8_t, 1>(
        windows, options, width, columns, r0, n, o.strip, o.coverage_rows, o.covered, o.overlap);
  else if (eight)
    ResampleStrip<std::uint8_t, 3>(
        windows, options, width, columns, r0, n, o.strip, o.coverage_rows, o.covered, o.overlap);
  else if (one_band)
    ResampleStrip<std::uint16_t, 1>(
        windows, options, width, columns, r0, n, o.strip, o.coverage_rows, o.covered, o.overlap);
  else
    ResampleStrip<std::uint16_t, 3>(
        windows, options, width, columns, r0, n, o.strip, o.coverage_rows, o.covered, o.overlap);
}

// The options' region, or the whole format; LogicError when it leaves the format.
VirtualRegion CheckedRegion(const ResampleOptions& options, int width, int height) {
  const VirtualRegion region =
      options.region.Empty() ? VirtualRegion{0, 0, width, height} : options.region;
  AEROCAL_CHECK(region.x0 >= 0 && region.y0 >= 0 && region.height > 0 &&
                region.x0 + region.width <= width && region.y0 + region.height <= height)
      << "region " << region.x0 << " " << region.y0 << " " << region.width << " x " << region.height
      << " outside the virtual format " << width << " x " << height;
  return region;
}

}  // namespace

Interpolation ParseInterpolation(const std::string& name) {
  if (name == "bilinear") return Interpolation::kBilinear;
  if (name == "bicubic") return Interpolation::kBicubic;
  throw ConfigError("interpolation must be bilinear or bicubic (got '" + name + "')");
}

std::string MappingDescription(const calib::Camera& camera, const std::string& source) {
  std::string text = "aerocal virtual image " + std::to_string(camera.width_px) + " x " +
                     std::to_string(camera.height_px) + " px of camera '" + camera.name +
                     "'; mappings from " + source + "; sub-image model width height params:\n";
  char number[32];
  for (const auto& s : camera.subimages) {
    text += s.id + " " + std::string(calib::MappingModelName(s.model)) + " " +
            std::to_string(s.width_px) + " " + std::to_string(s.height_px);
    for (double p : s.params) {
      std::snprintf(number, sizeof(number), " %.17g", p);
      text += number;
    }
    text += "\n";
  }
  return text;
}

ResampleReport ResampleVirtualImage(const calib::Camera& camera,
                                    const std::vector<RasterSource*>& sources,
                                    RasterSink* sink,
                                    const ResampleOptions& options,
                                    const std::vector<MapCorrectionGrid>& corrections,
                                    RasterSink* coverage) {
  const Stopwatch resampling;
  AEROCAL_CHECK(corrections.empty() || corrections.size() == sources.size())
      << corrections.size() << " correction grids for " << sources.size() << " sources";
  AEROCAL_CHECK(sources.size() == camera.subimages.size())
      << sources.size() << " sources for " << camera.subimages.size() << " sub-images";
  AEROCAL_CHECK(options.strip_rows > 0) << options.strip_rows;
  const RasterInfo first = sources.front()->Info();
  std::vector<Window> windows = MakeWindows(camera, sources, corrections);
  const int width = camera.width_px, height = camera.height_px;
  const VirtualRegion region = CheckedRegion(options, width, height);
  const ColumnSpan columns{region.x0, region.x0 + region.width - 1};
  const int region_end = region.y0 + region.height;
  const RasterInfo out_info{region.width, region.height, first.bands, first.bits};
  std::vector<std::uint8_t> strip(out_info.RowBytes() * options.strip_rows);
  std::vector<std::uint8_t> coverage_strip(coverage ? region.width * options.strip_rows : 0);
  std::atomic<long> covered{0}, overlap{0};
  const StripOutput output{&strip, coverage ? coverage_strip.data() : nullptr, &covered, &overlap};
  tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
  StripGeometry g{
      width, 0, 0, options.interpolation == Interpolation::kBicubic ? 3 : 2, false, first};
  // The fast path (fast_strip.h): bilinear, one band, no correction grid.
  g.fast =
      !options.reference && options.interpolation == Interpolation::kBilinear && first.bands == 1 &&
      std::none_of(windows.begin(), windows.end(), [](const Window& w) { return w.correction; });
  const float fill =
      std::clamp(static_cast<float>(options.fill), 0.0f, first.bits == 8 ? 255.0f : 65535.0f);
  // The whole format's strips (from row 0), so that a region gets the same windows.
  for (g.y0 = region.y0 / options.strip_rows * options.strip_rows; g.y0 < region_end;
       g.y0 += options.strip_rows) {
    g.rows = std::min(options.strip_rows, height - g.y0);
    // Sources are distinct objects: their windows are read in parallel.
    arena.execute([&] {
      tbb::parallel_for(
          size_t{0}, windows.size(), [&](size_t k) { PrepareWindow(g, sources[k], &windows[k]); });
    });
    const int r0 = std::max(g.y0, region.y0), n = std::min(g.y0 + g.rows, region_end) - r0;
    arena.execute([&] { ResampleRows(windows, options, g, fill, columns, r0, n, output); });
    sink->WriteRows(r0 - region.y0, n, strip.data());
    if (coverage) coverage->WriteRows(r0 - region.y0, n, output.coverage_rows);
  }
  ResampleReport report;
  report.covered = covered;
  report.overlap = overlap;
  report.filled = static_cast<long>(region.width) * region.height - report.covered;
  report.seconds = resampling.Seconds();
  return report;
}

}  // namespace aerocal::stitch
