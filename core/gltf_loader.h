// glTF 2.0 loader (tinygltf): .gltf + .bin, .glb, data URIs; the node hierarchy flattened
// to world space; materials with KHR transmission/ior/emissive_strength/texture_transform;
// KHR_lights_punctual; perspective cameras; the environment a speculum export keeps in the
// root extras (gltf_environment.h). Every accessor is validated before it is read.
#pragma once

#include <string>

#include "core/scene.h"
#include "core/scene_loader.h"

namespace speculum {

// Throws InputError(path, problem) for anything malformed. Points and lines primitives
// are skipped (counted in report->skipped_primitives with a warning); triangle strips and
// fans are converted to triangles. A file with no triangles at all is an error.
Scene load_gltf(const std::string& path, LoadReport* report = nullptr);

}  // namespace speculum
