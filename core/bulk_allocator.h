// An allocator for the big arrays a build fills in parallel (a BVH's references, leaf
// triangles and triangle packs: tens of MB rebuilt every frame or bench run).
// - resize() and n-element construction leave the new elements' bytes unwritten when the
//   element is trivially copyable and destructible and either trivially default
//   constructible or an aggregate (whose default member initialisers are then skipped:
//   a BVH node's "empty box"): one thread would otherwise write tens of MB that the
//   parallel fill overwrites. Such elements must be written before they are read.
// - Otherwise it is std::allocator (aligned operator new). Huge pages (madvise
//   MADV_HUGEPAGE on 2 MiB-aligned blocks) were measured and left out: 4.5x fewer page
//   faults but 2-3x the kernel time (clear_page on every fresh 2 MiB page was 30% of a
//   build's samples), while plain blocks below glibc's mmap threshold are reused.
// The bytes a program reads are the ones it wrote: no output depends on the allocator.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace speculum {

template <class T>
struct BulkAllocator {
  using value_type = T;
  BulkAllocator() = default;
  template <class U>
  BulkAllocator(const BulkAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t{alignof(T)}));
  }
  void deallocate(T* p, std::size_t) noexcept { ::operator delete(p, std::align_val_t{alignof(T)}); }

  // Elements a bulk fill writes whole: implicit-lifetime types, whose objects the
  // allocation itself creates (C++20 [intro.object]), so nothing needs to run.
  template <class U>
  static constexpr bool kLeftUnwritten =
      std::is_trivially_copyable_v<U> && std::is_trivially_destructible_v<U> &&
      (std::is_trivially_default_constructible_v<U> || std::is_aggregate_v<U>);

  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    if constexpr (!kLeftUnwritten<U>) ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  friend bool operator==(const BulkAllocator&, const BulkAllocator&) { return true; }
};

template <class T>
using BulkVector = std::vector<T, BulkAllocator<T>>;

}  // namespace speculum
