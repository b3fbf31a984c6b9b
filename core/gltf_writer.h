// Scene → glTF 2.0 (.glb or .gltf with embedded buffers) through tinygltf, so other
// viewers can open the built-in scenes: one mesh per object, materials with
// KHR_materials_transmission/_ior/_emissive_strength, embedded PNG textures, cameras and
// KHR_lights_punctual lights. glTF has no environment: it is carried in the root `extras`
// (constant colour, intensity and any equirect image, bit-exact; see gltf_environment.h),
// which load_gltf reads back and other viewers ignore. extensionsUsed lists exactly the
// extensions written.
#pragma once

#include <string>

#include "core/scene.h"

namespace speculum {

// Writes to a temporary file then renames, so a failure leaves no partial output.
// Throws InputError(path, problem) when the path is unsupported or cannot be written.
void write_gltf(const Scene& scene, const std::string& path);

}  // namespace speculum
