// Sizing the per-frame planes of the visibility buffer and the G-buffer.
#pragma once

#include <cstddef>

#include "core/image.h"
#include "parallel/page_buffer.h"

namespace speculum::raster {

// Sizes `plane` to width × height pixels for a pass that overwrites every one: a plane that
// has the room already keeps its allocation (and whatever pixels it held; only growth within
// it is value-initialized), so a run of images of varying sizes (SOFF's depth images)
// allocates, initializes and faults in its planes once, not per image. Otherwise the plane
// is allocated value-initialized on 2 MiB pages where the kernel allows:
// the tile pass writes each tile row onto another 4 KiB page of every plane, and a 1080p
// frame's planes span tens of thousands of small pages, so on them nearly every row write and
// the resolve's streaming writes missed the TLB.
template <class Pixel>
void ensure_plane_size(Buffer2D<Pixel>& plane, int width, int height) {
  if (plane.width == width && plane.height == height) return;
  plane.width = width;
  plane.height = height;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  if (plane.pixels.capacity() >= n) plane.pixels.resize(n);
  else par::resize_on_huge_pages(plane.pixels, n);
}

}  // namespace speculum::raster
