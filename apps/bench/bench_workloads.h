// The two rasterizer yardstick workloads (the raster benchmark), built in memory so `bench raster` and
// llvmpipe can draw the same triangles: `bench:spheres-room` (100 UV spheres of ~10k
// triangles in a box room, ~1.02M) and `bench:random-triangles` (1M small random triangles
// filling a cube), each with the camera the figures were measured from.
#pragma once

#include <string>

#include "core/scene.h"

namespace speculum::pipeline {

bool is_bench_workload(const std::string& name);
// Throws InputError for an unknown workload name.
Scene make_bench_workload(const std::string& name);

// Writes the scene's triangles as a binary little-endian PLY (positions and faces), so the
// same geometry can be fed to other renderers. Throws InputError on I/O failure.
void write_ply(const std::string& path, const Scene& scene);

}  // namespace speculum::pipeline
