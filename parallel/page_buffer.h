// A cache-line-aligned scratch area backed by transparent huge pages where the kernel
// allows them (madvise), for the scatter targets of the stream primitives.
// A radix scatter writes to thousands of places at once; on 4 KiB pages nearly every line
// flush goes to a page the TLB does not hold, on 2 MiB pages it does.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <new>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <sys/mman.h>

namespace speculum::par {

class PageBuffer {
 public:
  static constexpr std::size_t kHugePage = std::size_t(2) << 20;

  // Room for n elements of T, 2 MiB aligned; contents unspecified (scratch only). Capacity
  // only grows, so a reused buffer keeps its pages and pays no page faults per call.
  template <class T>
  T* reserve(std::size_t n) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::size_t bytes = n * sizeof(T);
    if (bytes > capacity_) {
      const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
      void* p = std::aligned_alloc(kHugePage, rounded);
      if (!p) throw std::bad_alloc();
      ::madvise(p, rounded, MADV_HUGEPAGE);  // advice only: may stay 4 KiB pages
      data_.reset(static_cast<std::byte*>(p));
      capacity_ = rounded;
    }
    return reinterpret_cast<T*>(data_.get());
  }

 private:
  struct Free {
    void operator()(std::byte* p) const { std::free(p); }
  };
  std::unique_ptr<std::byte, Free> data_;
  std::size_t capacity_ = 0;
};

// Asks the kernel for 2 MiB pages over the whole huge pages inside [data, data + bytes)
// (advice only). For big per-frame streams held in std::vector: on 4 KiB pages their
// first-touch page faults can cost as much as filling them.
inline void advise_huge_pages(const void* data, std::size_t bytes) {
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + PageBuffer::kHugePage - 1) / PageBuffer::kHugePage * PageBuffer::kHugePage;
  const std::uintptr_t last = (begin + bytes) / PageBuffer::kHugePage * PageBuffer::kHugePage;
  if (last > first) ::madvise(reinterpret_cast<void*>(first), last - first, MADV_HUGEPAGE);
}

// Sizes v to n value-initialized elements, advising huge pages before the first touch.
template <class T>
void resize_on_huge_pages(std::vector<T>& v, std::size_t n) {
  v.clear();
  v.reserve(n);
  advise_huge_pages(v.data(), n * sizeof(T));
  v.resize(n);
}

}  // namespace speculum::par
