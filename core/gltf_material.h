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

namespace speculum::gltf {

// Extensions this loader understands (a file *requiring* another one is rejected).
bool extension_supported(const std::string& name);

class MaterialTable {
 public:
  MaterialTable(const std::string& path, const tinygltf::Model& model, Scene& scene);
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
  std::vector<int> material_map_;
  int default_material_ = -1;
  std::map<std::pair<int, bool>, int> texture_map_;
};

}  // namespace speculum::gltf
