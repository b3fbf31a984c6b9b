// Block-wise output of the `gbuffer` node: samples are resolved into a small L1-resident
// staging block, then copied to the G-buffer planes with non-temporal (streaming) stores
// when the frame is far larger than the last-level cache (DESIGN.md "Stream constraints":
// write bandwidth). Whole-line streaming stores skip the read-for-ownership a normal store
// pays on every line of a 170 MB target and do not evict the scene data the gathers reuse.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include <immintrin.h>

namespace speculum::raster::detail {

// Copies `bytes` from the 16-byte-aligned `src` to `dst`: streaming 16-byte stores when
// `stream` is set and the destination allows them (16-byte aligned, length a multiple of 16),
// an ordinary copy otherwise. The bytes written are the same either way.
inline void store_block(void* dst, const void* src, std::size_t bytes, bool stream) {
  const auto d = reinterpret_cast<std::uintptr_t>(dst);
  if (!stream || (d & 15) != 0 || (bytes & 15) != 0) {
    std::memcpy(dst, src, bytes);
    return;
  }
  auto* out = static_cast<__m128i*>(dst);
  const auto* in = static_cast<const __m128i*>(src);
  for (std::size_t k = 0; k < bytes / 16; ++k) _mm_stream_si128(out + k, _mm_load_si128(in + k));
}

// Streaming stores are weakly ordered: fence them before another thread (or the caller after
// the launch joins) reads the G-buffer.
inline void end_stores(bool stream) {
  if (stream) _mm_sfence();
}

}  // namespace speculum::raster::detail
