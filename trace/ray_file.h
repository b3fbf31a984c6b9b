// The SPRY ray file of `speculum bench trace`: little-endian, magic "SPRY",
// uint32 version 1, uint64 count, then per ray 8 float32: origin xyz, tnear, direction
// xyz, tfar.
#pragma once

#include <string>

#include "trace/traversal.h"

namespace speculum::trace {

// Throws InputError(path, problem) for a missing, truncated or malformed file.
RayStream read_ray_file(const std::string& path);
// Written to a temporary file and renamed, so a failure leaves no partial file.
void write_ray_file(const std::string& path, const RayStream& rays);

}  // namespace speculum::trace
