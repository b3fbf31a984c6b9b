// Streams and the element-wise primitives over them: SoA streams, map (scalar and over
// Lanes<W>), gather and chunk-order reduce (docs/architecture.md, "Stream constraints" and
// "Determinism").
// Every primitive runs on the Executor over chunks of a fixed size (kStreamChunk by
// default) that never depends on the thread count, so results are bit-identical for any
// thread count; launch names are "<name>/<phase>".
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include "parallel/executor.h"
#include "parallel/lanes.h"

namespace speculum::par {

// Default elements per chunk: large enough to amortize scheduling, small enough that two
// threads get many chunks at 1M elements. A multiple of every lane width.
inline constexpr std::size_t kStreamChunk = 1 << 14;

// Marks "no element" in index outputs (e.g. an empty segment's argmin).
inline constexpr std::uint32_t kNoIndex = 0xffffffffu;

inline std::string launch_name(std::string_view name, std::string_view phase) {
  std::string s(name);
  s += '/';
  s += phase;
  return s;
}

// A structure-of-arrays stream: one array per field, all of the same length.
//   SoaStream<float, float, std::uint32_t> hits;  // t, u, primitive
//   hits.resize(n); hits.field<0>()[i] = t;
// Only resize changes the length, and it resizes every field: field<I>() is a span over the
// field's elements (their values can change, their number cannot), so the fields never
// disagree on size(). A span is invalidated by the next resize.
template <class... Fields>
class SoaStream {
  static_assert(sizeof...(Fields) > 0, "SoaStream needs at least one field");

 public:
  std::size_t size() const { return std::get<0>(fields_).size(); }
  void resize(std::size_t n) {
    std::apply([n](auto&... f) { (f.resize(n), ...); }, fields_);
  }
  template <std::size_t I> auto field() { return std::span(std::get<I>(fields_)); }
  template <std::size_t I> auto field() const { return std::span(std::get<I>(fields_)); }
  // out[k] = this[index[k]] for every field (the gather that follows a compaction or sort).
  SoaStream gather(Executor& ex, std::string_view name, std::span<const std::uint32_t> index) const;

 private:
  std::tuple<std::vector<Fields>...> fields_;
};

// out[i] = f(in[i]).
template <class T, class U, class F>
void map(Executor& ex, std::string_view name, std::span<const T> in, std::span<U> out, F&& f,
         std::size_t chunk = kStreamChunk) {
  ex.parallel_for(name, in.size(), chunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) out[i] = f(in[i]);
  });
}

// body(first, active) per group of W consecutive elements starting at `first`, with
// `active` masking the tail; the width-generic kernel form (chunk is rounded to W).
template <int W, class Body>
void map_lanes(Executor& ex, std::string_view name, std::size_t n, Body&& body,
               std::size_t chunk = kStreamChunk) {
  using L = Lanes<W>;
  chunk = std::max<std::size_t>(W, chunk / W * W);
  ex.parallel_for(name, n, chunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; i += W) body(i, L::first_n(int(std::min<std::size_t>(W, e - i))));
  });
}

// out[k] = src[index[k]].
template <class T>
void gather(Executor& ex, std::string_view name, std::span<const T> src,
            std::span<const std::uint32_t> index, std::span<T> out, std::size_t chunk = kStreamChunk) {
  ex.parallel_for(name, index.size(), chunk, [&](std::size_t b, std::size_t e) {
    for (std::size_t k = b; k < e; ++k) out[k] = src[index[k]];
  });
}

// op-fold of in, each chunk folded left to right from `identity` (which must be a true
// identity of op: every chunk starts from it), chunk results folded in
// chunk order: the association is fixed by the chunk size alone.
template <class T, class Op>
T reduce(Executor& ex, std::string_view name, std::span<const T> in, T identity, Op op,
         std::size_t chunk = kStreamChunk) {
  return ex.parallel_reduce(
      name, in.size(), chunk, identity,
      [&](std::size_t b, std::size_t e) {
        T acc = identity;
        for (std::size_t i = b; i < e; ++i) acc = op(acc, in[i]);
        return acc;
      },
      op);
}

template <class... Fields>
SoaStream<Fields...> SoaStream<Fields...>::gather(Executor& ex, std::string_view name,
                                                  std::span<const std::uint32_t> index) const {
  SoaStream out;
  out.resize(index.size());
  ex.parallel_for(name, index.size(), kStreamChunk, [&](std::size_t b, std::size_t e) {
    auto one = [&](auto& dst, const auto& src) {
      for (std::size_t k = b; k < e; ++k) dst[k] = src[index[k]];
    };
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (one(std::get<I>(out.fields_), std::get<I>(fields_)), ...);
    }(std::index_sequence_for<Fields...>{});
  });
  return out;
}

}  // namespace speculum::par
