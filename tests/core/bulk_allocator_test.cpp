#include "core/bulk_allocator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <numeric>
#include <string>

namespace speculum {
namespace {

struct alignas(64) Wide {
  float v[16];
};

// Elements keep their alignment at every size (a 64-byte-aligned node type stays 64-byte
// aligned), and resize leaves an implicit-lifetime element's bytes to the fill.
TEST(BulkAllocator, KeepsTheElementsAlignment) {
  static_assert(BulkAllocator<Wide>::kLeftUnwritten<Wide>);
  static_assert(!BulkAllocator<std::string>::kLeftUnwritten<std::string>);
  for (std::size_t n : {1u, 3u, 1000u, 40000u, 300000u}) {
    BulkVector<Wide> w(n);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(w.data()) % 64, 0u) << n;
  }
  BulkVector<std::string> s(3);  // non-trivial elements are still constructed
  EXPECT_TRUE(s[2].empty());
}

// Growing moves every element (the allocator only changes where the bytes live), and
// values given at construction are kept.
TEST(BulkAllocator, GrowingKeepsTheValuesWritten) {
  BulkVector<std::uint32_t> v;
  for (std::uint32_t i = 0; i < 1200000; ++i) v.push_back(i * 2654435761u);
  for (std::uint32_t i = 0; i < 1200000; ++i) ASSERT_EQ(v[i], i * 2654435761u) << i;
  v.resize(3000000);
  v.resize(600000);
  for (std::uint32_t i = 0; i < 600000; ++i) ASSERT_EQ(v[i], i * 2654435761u) << i;
  const BulkVector<float> filled(700000, 0.25f);
  EXPECT_EQ(std::accumulate(filled.begin(), filled.end(), 0.0), 175000.0);
}

}  // namespace
}  // namespace speculum
