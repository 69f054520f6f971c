#include "stitch/resample/fast_strip.h"

#include "calib/core/error.h"
#include "stitch/resample/bilinear_run.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bitset>
#include <cmath>
#include <limits>

namespace aerocal::stitch::internal {
namespace {

// One window's positions along virtual row V: u(c) = (xa c + xb) / (wa c + wb) - x0, likewise v,
// exact at the nodes first + i node_step, linear between nodes.
// Plain fields (no initialisers): a row keeps an array of them, set by MakeRowMap.
struct RowMap {
  int first, last;                // covered columns
  double xa, xb, ya, yb, wa, wb;  // x = xa c + xb, ... along the row (sub-image homogeneous)
  double x0, y0;                  // window origin in the sub-image
  std::int64_t max_u, max_v;      // (w - 1), (h - 1) in fixed point
  long node_step;                 // columns between exact nodes

  std::int64_t U(int c) const { return ToFixed((xa * c + xb) / (wa * c + wb) - x0); }
  std::int64_t V(int c) const { return ToFixed((ya * c + yb) / (wa * c + wb) - y0); }
  bool Inside(std::int64_t u, std::int64_t v) const {
    return u >= 0 && u <= max_u && v >= 0 && v <= max_v;
  }
};

RowMap MakeRowMap(const Window& win, double V, int first, int last) {
  const Eigen::Matrix3d& m = win.sub_from_virtual;
  RowMap map;
  map.first = first;
  map.last = last;
  map.xa = m(0, 0), map.xb = m(0, 1) * V + m(0, 2);
  map.ya = m(1, 0), map.yb = m(1, 1) * V + m(1, 2);
  map.wa = m(2, 0), map.wb = m(2, 1) * V + m(2, 2);
  map.x0 = win.x0, map.y0 = win.y0;
  map.max_u = static_cast<std::int64_t>(win.w - 1) << kFractionBits;
  map.max_v = static_cast<std::int64_t>(win.h - 1) << kFractionBits;
  map.node_step = std::numeric_limits<int>::max();
  if (map.wa != 0.0) {  // |u''| is largest where w is smallest: at an end of the run (w > 0)
    const double w_min = std::min(map.wa * first + map.wb, map.wa * last + map.wb);
    const double k = std::max(std::abs(map.xa * map.wb - map.xb * map.wa),
                              std::abs(map.ya * map.wb - map.yb * map.wa));
    const double curvature = 2.0 * std::abs(map.wa) * k / (w_min * w_min * w_min);
    if (curvature > 0)
      map.node_step = static_cast<long>(
          std::clamp(std::floor(std::sqrt(8.0 * kChordPx / curvature)), 1.0, 1e9));
  }
  return map;
}

// Calls fn(run, column) for runs covering columns [s, e) of `map` (within [first, last]). A
// position that rounding put outside the window's box (by ~1e-9 px at an edge) is clamped onto it
// and sampled alone, as the reference path does.
template <typename Fn>
void ForEachRun(const RowMap& map, int s, int e, Fn&& fn) {
  for (int c = s; c < e;) {
    const long n0 = map.first + (c - map.first) / map.node_step * map.node_step;
    const long n1 = std::min<long>(n0 + map.node_step, map.last);
    const int end = static_cast<int>(std::min<long>(e, n0 + map.node_step));
    const std::int64_t u0 = map.U(static_cast<int>(n0)), v0 = map.V(static_cast<int>(n0));
    std::int64_t du = 0, dv = 0;
    if (n1 > n0) {
      du = (map.U(static_cast<int>(n1)) - u0) / (n1 - n0);
      dv = (map.V(static_cast<int>(n1)) - v0) / (n1 - n0);
    }
    FixedRun run{u0 + (c - n0) * du, v0 + (c - n0) * dv, du, dv, end - c};
    auto clamped = [&](std::int64_t u, std::int64_t v) {
      return FixedRun{std::clamp<std::int64_t>(u, 0, map.max_u),
                      std::clamp<std::int64_t>(v, 0, map.max_v),
                      0,
                      0,
                      1};
    };
    while (run.n > 0 && !map.Inside(run.u, run.v)) {
      fn(clamped(run.u, run.v), c);
      run.u += du, run.v += dv, ++c, --run.n;
    }
    while (run.n > 0) {
      const std::int64_t u1 = run.u + (run.n - 1) * du, v1 = run.v + (run.n - 1) * dv;
      if (map.Inside(u1, v1)) break;
      fn(clamped(u1, v1), c + run.n - 1);
      --run.n;
    }
    if (run.n > 0) fn(run, c);
    c = end;
  }
}

constexpr int kMaxWindows = 64;

// One virtual row's columns `columns` into out[0 .. columns.Count()): the maps (runs, nodes) are
// the whole row's, only the cuts are clipped to the columns, so each pixel is the whole row's.
template <typename T>
void ResampleRow(const std::vector<Window>& windows,
                 T fill,
                 int width,
                 ColumnSpan columns,
                 double V,
                 T* out_row,
                 std::uint8_t* coverage_row,
                 std::vector<float>* sum,
                 long* covered,
                 long* overlap) {
  RowMap maps[kMaxWindows];
  int cuts[2 * kMaxWindows + 2], n_cuts = 0;
  std::bitset<kMaxWindows> seen;
  const int begin = columns.first, end = columns.last + 1;
  cuts[n_cuts++] = begin;
  cuts[n_cuts++] = end;
  for (size_t k = 0; k < windows.size(); ++k) {
    int first = 0, last = -1;
    if (!windows[k].used || !CoveredColumns(windows[k], V, width, &first, &last)) continue;
    maps[k] = MakeRowMap(windows[k], V, first, last);
    seen[k] = true;
    cuts[n_cuts++] = std::clamp(first, begin, end);
    cuts[n_cuts++] = std::clamp(last + 1, begin, end);
  }
  const auto out = [&](int c) { return out_row + (c - begin); };  // column c's sample
  std::sort(cuts, cuts + n_cuts);
  n_cuts = static_cast<int>(std::unique(cuts, cuts + n_cuts) - cuts);
  for (int i = 0; i + 1 < n_cuts; ++i) {
    const int s = cuts[i], e = cuts[i + 1];
    int n = 0, only = -1;
    for (size_t k = 0; k < windows.size(); ++k)
      if (seen[k] && maps[k].first <= s && maps[k].last >= e - 1) ++n, only = static_cast<int>(k);
    if (coverage_row)  // the rule of the values: covered where a sub-image is sampled
      std::fill(coverage_row + (s - begin), coverage_row + (e - begin), n > 0 ? 255 : 0);
    if (n == 0) {
      std::fill(out(s), out(e), fill);
      continue;
    }
    *covered += e - s;
    const auto window_of = [&](size_t k) {
      return SampleWindow<T>{reinterpret_cast<const T*>(windows[k].samples), windows[k].stride};
    };
    if (n == 1) {
      ForEachRun(maps[only], s, e, [&](const FixedRun& run, int c) {
        SampleRunStore(window_of(only), run, out(c));
      });
      continue;
    }
    *overlap += e - s;
    float* acc = sum->data();
    std::fill(acc + s, acc + e, 0.0f);
    for (size_t k = 0; k < windows.size(); ++k) {  // in sub-image order, as the reference path
      if (!(seen[k] && maps[k].first <= s && maps[k].last >= e - 1)) continue;
      ForEachRun(maps[k], s, e, [&](const FixedRun& run, int c) {
        SampleRunAdd(window_of(k), run, acc + c);
      });
    }
    const float scale = 1.0f / n, max_value = std::numeric_limits<T>::max();
    for (int c = s; c < e; ++c)
      *out(c) = static_cast<T>(std::clamp(acc[c] * scale + 0.5f, 0.0f, max_value));
  }
}

}  // namespace

template <typename T>
void ResampleStripFast(const std::vector<Window>& windows,
                       float fill,
                       int width,
                       ColumnSpan columns,
                       int y0,
                       int rows,
                       std::uint8_t* strip,
                       std::uint8_t* coverage,
                       std::atomic<long>* covered,
                       std::atomic<long>* overlap) {
  AEROCAL_CHECK(windows.size() <= static_cast<size_t>(kMaxWindows))
      << windows.size() << " sub-images";
  const T fill_value = static_cast<T>(fill + 0.5f);
  tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& range) {
    std::vector<float> sum(width);
    long n_covered = 0, n_overlap = 0;
    for (int r = range.begin(); r < range.end(); ++r) {
      const size_t at = static_cast<size_t>(r) * columns.Count();
      ResampleRow<T>(windows,
                     fill_value,
                     width,
                     columns,
                     y0 + r,
                     reinterpret_cast<T*>(strip) + at,
                     coverage ? coverage + at : nullptr,
                     &sum,
                     &n_covered,
                     &n_overlap);
    }
    *covered += n_covered;
    *overlap += n_overlap;
  });
}

template void ResampleStripFast<std::uint8_t>(const std::vector<Window>&,
                                              float,
                                              int,
                                              ColumnSpan,
                                              int,
                                              int,
                                              std::uint8_t*,
                                              std::uint8_t*,
                                              std::atomic<long>*,
                                              std::atomic<long>*);
template void ResampleStripFast<std::uint16_t>(const std::vector<Window>&,
                                               float,
                                               int,
                                               ColumnSpan,
                                               int,
                                               int,
                                               std::uint8_t*,
                                               std::uint8_t*,
                                               std::atomic<long>*,
                                               std::atomic<long>*);

}  // namespace aerocal::stitch::internal
