// Block-wise output of the `gbuffer` node: samples are resolved into a small L1-resident
// staging buffer per plane, then copied to the G-buffer planes with whole-line 32-byte
// non-temporal (streaming) stores when the frame is far larger than the last-level cache
// (write bandwidth is the limit there). Whole-line streaming stores skip the
// read-for-ownership a normal store pays on every line of a 170 MB target and do not evict
// the scene data the gathers reuse.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include <immintrin.h>

namespace speculum::raster::detail {

// One plane's writer for a contiguous run of samples [begin, end) owned by one thread. The
// staging buffer mirrors the destination's cache-line phase, so every flush is of whole,
// 64-byte-aligned lines whatever the plane's base address (large std::vector storage sits at
// 16 mod 64): a plane written at another phase would leave two partial lines per block, and a
// partially written write-combining buffer costs a read-modify-write in the memory system.
// The lines at the two ends of the run, which may be shared with the neighbouring runs of
// other threads, are written with ordinary stores (coherent byte writes, no streaming).
// `kBlockBytes` is the most a single block appends.
template <std::size_t kBlockBytes>
class LineWriter {
 public:
  static constexpr std::size_t kLine = 64;

  LineWriter(void* dst_begin, bool stream) : stream_(stream) {
    const auto d = reinterpret_cast<std::uintptr_t>(dst_begin);
    line_ = reinterpret_cast<unsigned char*>(d & ~std::uintptr_t(kLine - 1));
    skip_ = fill_ = d & (kLine - 1);
  }

  // Where the next block's `bytes` (≤ kBlockBytes) go; call commit(bytes) once written.
  unsigned char* next() { return buf_ + fill_; }

  // Writes the complete lines out and keeps the last, partial one.
  void commit(std::size_t bytes) {
    fill_ += bytes;
    const std::size_t full = fill_ / kLine * kLine;
    if (full == 0) return;
    if (!stream_) {
      std::memcpy(line_ + skip_, buf_ + skip_, full - skip_);
    } else {
      std::size_t k = 0;
      if (skip_ != 0) {  // the run's first line starts before the run: ordinary stores
        std::memcpy(line_ + skip_, buf_ + skip_, kLine - skip_);
        k = kLine;
      }
      for (; k < full; k += 32)
        _mm256_stream_si256(reinterpret_cast<__m256i*>(line_ + k),
                            _mm256_load_si256(reinterpret_cast<const __m256i*>(buf_ + k)));
    }
    std::memcpy(buf_, buf_ + full, fill_ - full);
    line_ += full;
    fill_ -= full;
    skip_ = 0;
  }

  // Writes the remaining bytes (the run's last, partial line) with ordinary stores.
  void finish() {
    if (fill_ > skip_) std::memcpy(line_ + skip_, buf_ + skip_, fill_ - skip_);
    line_ += fill_;
    fill_ = skip_ = 0;
  }

 private:
  alignas(64) unsigned char buf_[kBlockBytes + kLine];
  unsigned char* line_;  // destination of buf_[0], line-aligned
  std::size_t fill_;     // bytes held in buf_, including the skipped head
  std::size_t skip_;     // leading bytes of buf_ before the run (only until the first flush)
  bool stream_;
};

// Streaming stores are weakly ordered: fence them before another thread (or the caller after
// the launch joins) reads the G-buffer.
inline void end_stores(bool stream) {
  if (stream) _mm_sfence();
}

}  // namespace speculum::raster::detail
