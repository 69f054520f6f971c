#include "stitch/resample/bilinear_run.h"

#include <cstdlib>

// On x86-64 the kernels are compiled twice, for the baseline ISA and for AVX2, and the loader
// picks one (GCC/Clang target_clones). Both do the same IEEE float operations in the same order
// and neither may fuse a multiply-add (AVX2 does not enable FMA), so they give the same bits.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define AEROCAL_KERNEL_CLONES __attribute__((target_clones("avx2", "default")))
#define AEROCAL_INLINE_INTO_CLONES [[gnu::always_inline]] inline
#else
#define AEROCAL_KERNEL_CLONES
#define AEROCAL_INLINE_INTO_CLONES inline
#endif

namespace aerocal::stitch::internal {
namespace {

// Result of a sample: stored rounded into a T, or added to a float sum.
template <typename T, bool kAdd>
struct Output {
  T* out;
  float* sum;
  // Rounded through int32: float -> int32 is one vector instruction, float -> uint16 is not.
  void Put(int k, float value) const {
    if constexpr (kAdd)
      sum[k] += value;
    else
      out[k] = static_cast<T>(static_cast<std::int32_t>(value + 0.5f));
  }
};

// kBlock columns at integer positions (iu0 + j, iv0): rows p and p + stride, weights from the
// fractions fu0 + lane_u[j], fv0 + lane_v[j] (mod 2^32, known to stay within [0, 2^32)). The
// output does not overlap the samples (__restrict), so the loop with its stores vectorises.
template <typename T, bool kAdd>
AEROCAL_INLINE_INTO_CLONES void Block(const T* __restrict p,
                                      int stride,
                                      std::uint32_t fu0,
                                      std::uint32_t fv0,
                                      const std::uint32_t* __restrict lane_u,
                                      const std::uint32_t* __restrict lane_v,
                                      float* __restrict sum,
                                      T* __restrict out) {
  const T* __restrict q = p + stride;
  // The next virtual row reads the window row after q (a sub-image at about the virtual image's
  // scale): asked for now, it is in cache by then. Without it the loads of q waited for memory
  // (each row of a sub-image is a short stream of its own, which the hardware prefetcher misses).
#if defined(__GNUC__) || defined(__clang__)
  __builtin_prefetch(q + stride);
#endif
  for (int j = 0; j < kBlock; ++j) {  // vectorised: contiguous loads, no gathers
    const float fu = Weight(fu0 + lane_u[j]), fv = Weight(fv0 + lane_v[j]);
    const float a = p[j], b = p[j + 1], c = q[j], d = q[j + 1];
    const float top = a + fu * (b - a), bottom = c + fu * (d - c);
    const float value = top + fv * (bottom - top);
    if constexpr (kAdd)
      sum[j] += value;
    else
      out[j] = static_cast<T>(static_cast<std::int32_t>(value + 0.5f));
  }
}

template <typename T, bool kAdd>
AEROCAL_INLINE_INTO_CLONES void SampleRun(const SampleWindow<T>& window,
                                          const FixedRun& run,
                                          const Output<T, kAdd>& out) {
  std::int64_t u = run.u, v = run.v;
  int k = 0;
  // u = iu + 1 + eu per column; blocks pay when a block's fractions rarely wrap.
  const std::int64_t eu = run.du - kOnePx, span_u = (kBlock - 1) * eu,
                     span_v = (kBlock - 1) * run.dv;
  if (std::llabs(span_u) < kOnePx / 2 && std::llabs(span_v) < kOnePx / 2) {
    std::uint32_t lane_u[kBlock], lane_v[kBlock];
    for (int j = 0; j < kBlock; ++j) {
      lane_u[j] = static_cast<std::uint32_t>(j * eu);
      lane_v[j] = static_cast<std::uint32_t>(j * run.dv);
    }
    for (; k + kBlock <= run.n; k += kBlock) {
      const std::int64_t fu0 = u & (kOnePx - 1), fv0 = v & (kOnePx - 1);
      const std::int64_t fu1 = fu0 + span_u, fv1 = fv0 + span_v;  // the block's last fractions
      if (fu1 >= 0 && fu1 < kOnePx && fv1 >= 0 && fv1 < kOnePx) {
        const T* p = window.data + (v >> kFractionBits) * window.stride + (u >> kFractionBits);
        Block<T, kAdd>(p,
                       window.stride,
                       static_cast<std::uint32_t>(fu0),
                       static_cast<std::uint32_t>(fv0),
                       lane_u,
                       lane_v,
                       kAdd ? out.sum + k : nullptr,
                       kAdd ? nullptr : out.out + k);
        u += kBlock * run.du;
        v += kBlock * run.dv;
      } else {
        for (int j = 0; j < kBlock; ++j, u += run.du, v += run.dv)
          out.Put(k + j, SampleAt(window, u, v));
      }
    }
  }
  for (; k < run.n; ++k, u += run.du, v += run.dv) out.Put(k, SampleAt(window, u, v));
}

AEROCAL_KERNEL_CLONES void Store8(const SampleWindow<std::uint8_t>& w,
                                  const FixedRun& run,
                                  std::uint8_t* out) {
  SampleRun(w, run, Output<std::uint8_t, false>{out, nullptr});
}
AEROCAL_KERNEL_CLONES void Store16(const SampleWindow<std::uint16_t>& w,
                                   const FixedRun& run,
                                   std::uint16_t* out) {
  SampleRun(w, run, Output<std::uint16_t, false>{out, nullptr});
}
AEROCAL_KERNEL_CLONES void Add8(const SampleWindow<std::uint8_t>& w,
                                const FixedRun& run,
                                float* sum) {
  SampleRun(w, run, Output<std::uint8_t, true>{nullptr, sum});
}
AEROCAL_KERNEL_CLONES void Add16(const SampleWindow<std::uint16_t>& w,
                                 const FixedRun& run,
                                 float* sum) {
  SampleRun(w, run, Output<std::uint16_t, true>{nullptr, sum});
}

}  // namespace

template <>
void SampleRunStore(const SampleWindow<std::uint8_t>& w, const FixedRun& run, std::uint8_t* out) {
  Store8(w, run, out);
}
template <>
void SampleRunStore(const SampleWindow<std::uint16_t>& w, const FixedRun& run, std::uint16_t* out) {
  Store16(w, run, out);
}
template <>
void SampleRunAdd(const SampleWindow<std::uint8_t>& w, const FixedRun& run, float* sum) {
  Add8(w, run, sum);
}
template <>
void SampleRunAdd(const SampleWindow<std::uint16_t>& w, const FixedRun& run, float* sum) {
  Add16(w, run, sum);
}

}  // namespace aerocal::stitch::internal
