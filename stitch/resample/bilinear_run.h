// Bilinear samples of a sub-image window along a straight run of positions, in fixed point: the
// inner loop of the fast resampling path (virtual_image.h, fast_strip.h).
//
// Positions are window pixels (col u, row v; pixel centres at integers, CONVENTIONS.md) held in
// 32.32 fixed point (int64: integer part above bit 32, fraction below), so that stepping along a
// run adds integers and the position of every sample is exact to 2^-32 px per step however long
// the run (a float u near 4800 px is only good to 2^-11 px). The weights are the fraction's top
// 24 bits as a float, exact; the interpolation is float32 (a 16-bit value to ~0.004 DN):
//
//   top = a + fu (b - a),  bottom = c + fu (d - c),  value = top + fv (bottom - top)
//
// with a, b the samples at (iu, iv), (iu + 1, iv) and c, d the row below: the same formula as the
// reference path, so the two differ only by where (u, v) is rounded.
//
// Speed: when a run's u advances by about one window pixel per column and its v by much less (a
// sub-image at nearly the virtual image's scale, the multi-CCD case), a block of kBlock columns
// whose integer positions are iu0 + j and iv0 (checked per block from the fraction's range) reads
// two contiguous rows of kBlock + 1 samples: straight vector loads, no gathers, a loop body the
// compiler vectorises. Other blocks, and runs at another scale, go sample by sample with the same
// arithmetic, so the result is bit-identical whichever way a sample went.
#pragma once

#include <cmath>
#include <cstdint>

namespace aerocal::stitch::internal {

inline constexpr int kFractionBits = 32;
inline constexpr std::int64_t kOnePx = std::int64_t{1} << kFractionBits;
inline constexpr int kBlock = 16;  // columns per vector block

/// `x` px in 32.32 fixed point (|x| < 2^31 px), rounded to the nearest 2^-32 px.
inline std::int64_t ToFixed(double x) { return std::llround(std::ldexp(x, kFractionBits)); }

/// Positions (u + k du, v + k dv), k = 0 .. n - 1, window pixels in 32.32 fixed point.
struct FixedRun {
  std::int64_t u = 0, v = 0, du = 0, dv = 0;
  int n = 0;
};

/// A window of samples: rows of `stride` samples, `height` rows, followed by at least
/// stride + 2 samples of padding that may be read with weight 0 (the last column and row).
template <typename T>
struct SampleWindow {
  const T* data = nullptr;
  int stride = 0;  // = width, samples
};

/// Writes the bilinear value at every position of `run` (each inside [0, w-1] x [0, h-1] of the
/// window) to out[k], rounded (value + 0.5 truncated: values lie in the type's range).
template <typename T>
void SampleRunStore(const SampleWindow<T>& window, const FixedRun& run, T* out);

/// Adds the bilinear value at every position of `run` to sum[k] (float).
template <typename T>
void SampleRunAdd(const SampleWindow<T>& window, const FixedRun& run, float* sum);

/// The weight of a 32-bit fraction: its top 24 bits, exact in a float.
inline float Weight(std::uint32_t fraction) {
  return static_cast<float>(static_cast<std::int32_t>(fraction >> 8)) * 0x1p-24f;
}

/// The bilinear value at one fixed-point position (the arithmetic of both functions above).
template <typename T>
inline float SampleAt(const SampleWindow<T>& window, std::int64_t u, std::int64_t v) {
  const T* p = window.data + (v >> kFractionBits) * window.stride + (u >> kFractionBits);
  const float fu = Weight(static_cast<std::uint32_t>(u));
  const float fv = Weight(static_cast<std::uint32_t>(v));
  const float a = p[0], b = p[1], c = p[window.stride], d = p[window.stride + 1];
  const float top = a + fu * (b - a), bottom = c + fu * (d - c);
  return top + fv * (bottom - top);
}

}  // namespace aerocal::stitch::internal
