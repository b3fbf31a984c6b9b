// glTF materials and textures → speculum Materials and linear float textures
// (glTF 2.0 §3.9 metallic-roughness; KHR_materials_transmission/_ior/_emissive_strength,
// KHR_texture_transform). Converted lazily, so only what the scene uses is decoded.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <tiny_gltf.h>

#include "core/scene.h"
#include "core/scene_loader.h"

namespace speculum::gltf {

// Extensions this loader understands (a file *requiring* another one is rejected).
bool extension_supported(const std::string& name);

// The uv transform of a KHR_texture_transform object: uv' = T·R·S·(u, v, 1).
glm::mat3 texture_transform(const tinygltf::Value& transform);

class MaterialTable {
 public:
  // A texture image that is missing or cannot be decoded goes to report.substitute (left
  // out with a warning, or an error when strict).
  MaterialTable(const std::string& path, const tinygltf::Model& model, Scene& scene, LoadReport& report);
  // The scene material for glTF material `index` (-1: a default white dielectric).
  std::uint32_t scene_material(int index);
  void finish() {}

 private:
  Material convert(std::size_t index);
  // Fills `ref` from a textureInfo (index, texCoord, extensions); decodes the image.
  void bind(int texture, int texcoord, const tinygltf::ExtensionMap& ext, bool srgb,
            const std::string& what, TextureRef& ref);
  int scene_texture(int texture, bool srgb, const std::string& what);

  const std::string& path_;
  const tinygltf::Model& model_;
  Scene& scene_;
  LoadReport& report_;
  std::vector<int> material_map_;
  int default_material_ = -1;
  std::map<std::pair<int, bool>, int> texture_map_;
};

}  // namespace speculum::gltf
