// Lanes<W>: fixed-width SIMD lanes over std::experimental::simd, W ∈ {1, 4, 8, 16}, and the
// run-time lane-width dispatcher behind `--lanes W` (docs/architecture.md, "Stream
// constraints").
//
// Kernels are written once as templates on W and must give the same bits for every W.
// Element-wise IEEE operations (+ - * /, sqrt, compares, min/max/abs/select as defined
// here) are exact or correctly rounded per lane, so they are width-independent as long as
// the build forbids contraction (-ffp-contract=off, no -ffast-math; see CMakeLists.txt).
// What is NOT width-independent and must be avoided in kernels:
//  * keeping per-lane partial sums across iterations and combining them at the end: the
//    association of the additions then depends on W. Instead fold each vector into a scalar
//    accumulator in lane order with `Lanes<W>::accumulate(acc, v, active)`: for every W that
//    performs acc + x[0] + x[1] + ... in element order, i.e. the serial sum.
//  * `hadd(v)` is a sum of the W lanes in lane order; the result of summing n elements as a
//    sequence of hadd() results differs between widths. Use it only for values that are
//    exact (integers, counts) or where a single vector holds the whole reduction.
//  * stdx transcendental functions (sin, exp, ...) have vector implementations that differ
//    from libm; apply a scalar function per lane with `Lanes<W>::map` instead.
// Example (a width-generic kernel body):
//   template <int W> void scale(const float* x, float* y, std::size_t n, float k) {
//     using L = Lanes<W>;
//     for (std::size_t i = 0; i < n; i += W) {
//       const int count = int(std::min<std::size_t>(W, n - i));
//       L::store_partial(L::load_partial(x + i, count) * k, y + i, count);
//     }
//   }
//   dispatch_lanes(executor.lanes(), [&](auto w) { scale<decltype(w)::value>(x, y, n, 2.f); });
//
// Which kernels take W (what `--lanes` changes): map_lanes (stream.h); the 32-bit sum scans
// (scan_kernels.h); both compactions, stable partition, histogram, segmented min and the
// radix sort (compact.cpp, partition.cpp, chunk_counts.cpp, segmented.cpp, radix_sort.cpp),
// each `template <int W>` instantiated for 1, 4, 8 and 16 beside a plain overload that runs
// at the width of the Executor it is given (Executor::lanes()); and the tile rasterizer's
// coverage and depth test (RasterOptions::lanes, else the Executor's width). Their extra
// lane ops (prefix sums, streaming stores, left-packing, ...) are in lanes_stream.h and
// lanes_pack.h, with intrinsic paths where a width is one register. Scans and reductions with an
// arbitrary operator fold element by element (their association must not depend on W).
// Not width-generic: the G-buffer resolve, triangle setup and the BVH traversal kernels,
// written with fixed 8-wide AVX2 (the BVH for its 8-child node layout); they do the same IEEE
// or exact integer operations per element as their scalar tests, so their bits do not depend
// on W either.
#pragma once

// Masks of one width convert implicitly between element types of one size (float, int32,
// uint32), as fixed_size masks do; must precede every inclusion of <experimental/simd>.
#ifndef _GLIBCXX_SIMD_ENABLE_IMPLICIT_MASK_CAST
#define _GLIBCXX_SIMD_ENABLE_IMPLICIT_MASK_CAST 1
#endif
#include <experimental/simd>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>

namespace speculum::par {

namespace stdx = std::experimental;

// Widest lane count that maps to one native register of floats in this build.
#if defined(__AVX512F__)
inline constexpr int kNativeLanes = 16;
#elif defined(__AVX__)
inline constexpr int kNativeLanes = 8;
#else
inline constexpr int kNativeLanes = 4;
#endif

constexpr bool is_supported_lane_width(int w) { return w == 1 || w == 4 || w == 8 || w == 16; }

template <int W>
struct Lanes {
  static_assert(is_supported_lane_width(W), "Lanes<W>: W must be 1, 4, 8 or 16");
  static constexpr int width = W;

  // The native register ABI where W lanes of T fill one (their masks stay vector masks: a
  // fixed_size mask is a bit mask, and every compare then select went vector -> bits ->
  // vector), fixed_size otherwise.
  template <class T>
  using simd = stdx::simd<T, stdx::simd_abi::deduce_t<T, W>>;
  using f32 = simd<float>;
  using i32 = simd<std::int32_t>;
  using u32 = simd<std::uint32_t>;
  // Masks of the same width convert implicitly between these element types, so one
  // mask type serves float, int and uint comparisons.
  using mask = typename f32::mask_type;
  using imask = typename i32::mask_type;

  // ---- construction -------------------------------------------------------------------
  // Lane indices 0..W-1 (offset by `first`), e.g. the element index of each lane.
  static i32 iota(std::int32_t first = 0) {
    return i32([first](auto i) { return first + std::int32_t(i); });
  }
  // Lanes [0, count) active: the tail mask of a stream that is not a multiple of W.
  static mask first_n(int count) {
    return iota() < count;  // int mask converts to the float mask (same width)
  }

  // ---- memory ---------------------------------------------------------------------------
  template <class T>
  static auto load(const T* p) {
    return simd<T>(p, stdx::element_aligned);
  }
  // p must be aligned to stdx::memory_alignment_v (alignof the simd type).
  template <class T>
  static auto load_aligned(const T* p) {
    return simd<T>(p, stdx::vector_aligned);
  }
  // Reads only p[0, count); other lanes get `fill`. Never touches memory past the stream.
  template <class T>
  static auto load_partial(const T* p, int count, T fill = T{}) {
    return simd<T>([&](auto i) { return int(i) < count ? p[i] : fill; });
  }
  // base[index[lane]] for every lane (gather is free on the GPU model). The lanes go through
  // memory: the generator constructor was left a call per gather.
  template <class T, class Index>
  [[gnu::always_inline]] static auto gather(const T* base, const simd<Index>& index) {
    alignas(64) Index at[W];
    alignas(64) T out[W];
    index.copy_to(at, stdx::element_aligned);
    for (int i = 0; i < W; ++i) out[i] = base[at[i]];
    return simd<T>(out, stdx::element_aligned);
  }
  // Gathers only active lanes (inactive indices may be out of range); others get `fill`.
  template <class T, class Index, class M>
  static auto gather(const T* base, const simd<Index>& index, const M& active, T fill = T{}) {
    return simd<T>([&](auto i) { return active[i] ? base[index[i]] : fill; });
  }
  template <class T>
  static void store(const simd<T>& v, T* p) {
    v.copy_to(p, stdx::element_aligned);
  }
  template <class T>
  static void store_aligned(const simd<T>& v, T* p) {
    v.copy_to(p, stdx::vector_aligned);
  }
  template <class T>
  static void store_partial(const simd<T>& v, T* p, int count) {
    if (count >= W) return store(v, p);
    for (int i = 0; i < count; ++i) p[i] = v[i];
  }
  // Writes only the active lanes to p[lane] (contiguous; not a scatter).
  template <class T, class M>
  static void store_masked(const simd<T>& v, T* p, const M& active) {
    for (int i = 0; i < W; ++i)
      if (active[i]) p[i] = v[i];
  }

  // ---- element-wise ---------------------------------------------------------------------
  // select(m, a, b) = m ? a : b per lane.
  template <class T, class M>
  static simd<T> select(const M& m, const simd<T>& a, simd<T> b) {
    stdx::where(typename simd<T>::mask_type(m), b) = a;
    return b;
  }
  // min/max are defined as the scalar `b < a ? b : a` (and `a < b ? b : a`) so that NaN
  // and ±0 behave identically for every W (hardware min picks operands differently).
  template <class T>
  static simd<T> min(const simd<T>& a, const simd<T>& b) {
    return select(b < a, b, a);
  }
  template <class T>
  static simd<T> max(const simd<T>& a, const simd<T>& b) {
    return select(a < b, b, a);
  }
  // std::clamp per lane, in its order (v < lo first, then hi < v): a NaN stays NaN.
  // Always inlined: GCC kept it as a call taking and returning lanes through memory (5 % of
  // a cube-map technique's frame).
  template <class T>
  [[gnu::always_inline]] static simd<T> clamp(const simd<T>& v, const simd<T>& lo, const simd<T>& hi) {
    return select(v < lo, lo, select(hi < v, hi, v));
  }
  static f32 sqrt(const f32& v) { return stdx::sqrt(v); }  // correctly rounded per lane
  static f32 abs(const f32& v) { return stdx::abs(v); }
  static f32 floor(const f32& v) { return stdx::floor(v); }  // exact
  static i32 abs(const i32& v) { return stdx::abs(v); }
  // f(lane value) per lane: the width-independent way to use scalar math (std::exp, ...).
  template <class T, class F>
  static auto map(const simd<T>& v, F&& f) {
    using R = std::invoke_result_t<F&, T>;
    return simd<R>([&](auto i) { return f(T(v[i])); });
  }
  static i32 to_int(const f32& v) { return stdx::static_simd_cast<i32>(v); }  // truncates
  static f32 to_float(const i32& v) { return stdx::static_simd_cast<f32>(v); }
  static u32 to_uint(const i32& v) { return stdx::static_simd_cast<u32>(v); }
  static i32 to_int(const u32& v) { return stdx::static_simd_cast<i32>(v); }

  // ---- horizontal -----------------------------------------------------------------------
  template <class M> static bool any(const M& m) { return stdx::any_of(m); }
  template <class M> static bool all(const M& m) { return stdx::all_of(m); }
  template <class M> static bool none(const M& m) { return stdx::none_of(m); }
  template <class M> static int count(const M& m) { return stdx::popcount(m); }
  // Index of the first active lane, -1 if none.
  template <class M> static int first_active(const M& m) {
    return stdx::any_of(m) ? stdx::find_first_set(m) : -1;
  }
  // Minimum / maximum over lanes, folded in lane order with the scalar min/max above so
  // that ties, NaN and ±0 resolve like a serial loop.
  template <class T>
  static T hmin(const simd<T>& v) {
    T r = v[0];
    for (int i = 1; i < W; ++i) r = T(v[i]) < r ? T(v[i]) : r;
    return r;
  }
  template <class T>
  static T hmax(const simd<T>& v) {
    T r = v[0];
    for (int i = 1; i < W; ++i) r = r < T(v[i]) ? T(v[i]) : r;
    return r;
  }
  // Lane of the minimum; ties go to the lowest lane (the serial argmin).
  template <class T>
  static int argmin(const simd<T>& v) {
    int best = 0;
    for (int i = 1; i < W; ++i)
      if (T(v[i]) < T(v[best])) best = i;
    return best;
  }
  // Sum of the lanes in lane order ((v0 + v1) + v2) + ...: ORDER-SENSITIVE for floats — see
  // the header comment; use accumulate() to sum a stream identically for every W.
  // Through an array: reading the lanes one by one made GCC keep the caller's accumulator
  // in memory through its whole loop (a store and a reload per step: the fused scan kernel
  // took a third longer).
  template <class T>
  static T hadd(const simd<T>& v) {
    using V = simd<T>;
    alignas(stdx::memory_alignment_v<V>) T lanes[W];
    v.copy_to(lanes, stdx::vector_aligned);
    T r = lanes[0];
    for (int i = 1; i < W; ++i) r = r + lanes[i];
    return r;
  }
  // acc + v[0] + v[1] + ... over active lanes, in lane order: a serial element-order fold,
  // hence identical for every W when a kernel walks its elements in order.
  template <class T, class M>
  static T accumulate(T acc, const simd<T>& v, const M& active) {
    for (int i = 0; i < W; ++i)
      if (active[i]) acc = acc + T(v[i]);
    return acc;
  }
  template <class T>
  static T accumulate(T acc, const simd<T>& v) {
    for (int i = 0; i < W; ++i) acc = acc + T(v[i]);
    return acc;
  }
};

// Calls f(std::integral_constant<int, W>{}) for the requested width; w == 0 picks the
// build's native width. Every supported width is instantiated (fixed_size lanes wider than
// a register are emulated), so tests can compare all of them in one binary.
// The width `w` asks for: w itself if supported, kNativeLanes for 0. Throws
// std::invalid_argument for any other value.
inline int resolve_lane_width(int w) {
  if (w == 0) return kNativeLanes;
  if (!is_supported_lane_width(w))
    throw std::invalid_argument("unsupported lane width " + std::to_string(w) +
                                " (use 0 = native, 1, 4, 8 or 16)");
  return w;
}

template <class F>
decltype(auto) dispatch_lanes(int w, F&& f) {
  switch (resolve_lane_width(w)) {
    case 1: return std::forward<F>(f)(std::integral_constant<int, 1>{});
    case 4: return std::forward<F>(f)(std::integral_constant<int, 4>{});
    case 8: return std::forward<F>(f)(std::integral_constant<int, 8>{});
    default: return std::forward<F>(f)(std::integral_constant<int, 16>{});
  }
}

}  // namespace speculum::par
