// Wavefront OBJ with its .mtl materials and textures (tinyobjloader). Polygons are
// triangulated; corners that share a position but not a normal or uv become separate
// vertices. One object per OBJ object/group, one scene material per .mtl material used.
//
// .mtl → metallic-roughness (README.md, "Inputs and outputs", says the same for users):
//   Kd → base colour, map_Kd → base colour texture (sRGB decoded to linear, as glTF's);
//   Ns → roughness = (2 / (Ns + 2))^(1/4), the inverse of Material::phong_exponent;
//   Pr / Pm (the PBR extension) → roughness / metallic, Pr winning over Ns; metallic is 0
//   otherwise; Ke → emissive, map_Ke → emissive texture (sRGB); d < 1 (or Tr > 0) →
//   transmission 1 - d, a see-through surface being a refractor here; Ni ≥ 1 → ior.
// OBJ's v runs up the image and glTF's down: uvs are stored as (u, 1 - v).
// The .mtl files and textures resolve relative to the file that names them and must lie
// inside the OBJ's folder. One that is missing, outside or undecodable is left out (the
// default material, or the factors without the texture) through LoadReport::substitute.
#pragma once

#include <string>

#include "core/scene.h"
#include "core/scene_loader.h"

namespace speculum {

// Throws InputError(path, problem) for missing, empty or malformed files.
Scene load_obj(const std::string& path, LoadReport& report);

// Roughness whose Material::phong_exponent is `exponent` (a .mtl Ns): (1 / (n + 1))^(1/4),
// clamped to [0, 1].
float roughness_from_phong_exponent(float exponent);

}  // namespace speculum
