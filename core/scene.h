// The one scene representation every kernel streams over: all geometry flattened to
// world space into a single triangle soup with per-attribute arrays (structure of arrays)
// and per-triangle material and object ids; materials, cameras, lights, environment.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "core/image.h"

namespace speculum {

// A texture binding: an index into Scene::textures plus KHR_texture_transform
// (uv' = uv_transform * (u, v, 1)).
struct TextureRef {
  int texture = -1;  // -1: none
  int texcoord = 0;
  glm::mat3 uv_transform{1.0f};
  bool valid() const { return texture >= 0; }
};

// How a surface reflects, derived from the metallic-roughness parameters
// (Material::kind: transmission makes a refractor; a metallic surface is a mirror or glossy
// by the roughness thresholds below; anything else is diffuse).
enum class MaterialKind : std::uint8_t { Diffuse, Glossy, Mirror, Refractor };
const char* to_string(MaterialKind kind);

struct Material {
  std::string name;
  glm::vec4 base_color{1.0f};  // linear RGBA
  float metallic = 1.0f;       // glTF defaults
  float roughness = 1.0f;
  float transmission = 0.0f;   // KHR_materials_transmission
  float ior = 1.5f;            // KHR_materials_ior
  glm::vec3 emissive{0.0f};    // linear, already multiplied by any emissive strength
  float normal_scale = 1.0f;
  bool double_sided = false;
  TextureRef base_color_texture;          // sRGB-decoded at load time
  TextureRef metallic_roughness_texture;  // G: roughness, B: metallic (linear)
  TextureRef normal_texture;              // tangent space, linear
  TextureRef emissive_texture;
  TextureRef transmission_texture;        // R: transmission

  MaterialKind kind() const;
  // Phong exponent n of the lobe about the mirror direction R from roughness r: α = r²,
  // n = 1/α² − 1, clamped to [0, 1e6] so a perfect mirror stays finite. It matches the
  // peak of the GGX BRDF's reflected lobe: near R at normal incidence GGX falls as
  // exp(−θ² (1 − α²)/(2α²)) and cos^n θ as exp(−n θ²/2). (2/α² − 2, the half-vector
  // Blinn-Phong correspondence, would be √2 too narrow about R.) The one roughness →
  // lobe-width mapping: indirect glossy lobes (YU eq.4) sample and maps prefilter with
  // it, and their samples are weighted by the GGX BRDF itself (core/shading.h).
  float phong_exponent() const;
};

// The material of geometry that names none (glTF primitives without a material, OBJ faces
// without usemtl): a white, rough dielectric. (glTF's own default is a rough metal, which
// renders black under most lighting; a neutral dielectric shows the shape.)
Material default_material();

// Roughness thresholds for MaterialKind (documented once, used everywhere).
constexpr float kMirrorRoughness = 0.02f;   // at or below: mirror
constexpr float kGlossyRoughness = 0.6f;    // below (and smooth enough / metallic): glossy

// A named object: a contiguous range of triangles (one glTF mesh primitive instance, one
// procedural shape, or one loaded mesh file).
struct Object {
  std::string name;
  std::uint32_t first_triangle = 0;
  std::uint32_t triangle_count = 0;
  std::uint32_t material = 0;  // the material of its first triangle
};

// World-space triangle soup, attribute streams indexed by vertex; triangles index them.
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;   // unit, per vertex (computed when the input has none)
  std::vector<glm::vec4> tangents;  // xyz unit, w = handedness; empty if unknown
  std::vector<glm::vec2> uvs;       // TEXCOORD_0; zeros if absent
  std::vector<glm::vec2> uvs1;      // TEXCOORD_1; empty if absent
  std::vector<std::uint32_t> indices;          // 3 per triangle
  std::vector<std::uint32_t> triangle_material;
  std::vector<std::uint32_t> triangle_object;

  std::size_t triangle_count() const { return indices.size() / 3; }
  std::size_t vertex_count() const { return positions.size(); }
};

// Perspective camera. The image aspect comes from the render target.
struct Camera {
  std::string name = "default";
  glm::vec3 eye{0.0f, 0.0f, 5.0f};
  glm::vec3 target{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float vfov_degrees = 45.0f;
  float znear = 0.01f;
  float zfar = 1000.0f;
  float aspect = 0.0f;   // width / height the file asks for (glTF aspectRatio); 0: none
  bool framed = false;   // made by framing_camera, not read from the file
};

enum class LightType : std::uint8_t { Point, Spot, Directional };
const char* to_string(LightType type);

struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;          // candela (point/spot) or lux (directional), as glTF
  glm::vec3 position{0.0f};
  glm::vec3 direction{0, 0, -1};   // direction the light travels (spot/directional)
  float range = 0.0f;              // 0: infinite
  float inner_cone = 0.0f;         // radians (spot)
  float outer_cone = 0.7853982f;   // radians (spot)
};

// Radiance arriving from infinity: a constant, or an equirectangular image
// (u = longitude, v = latitude from +Y at the top) times `intensity`.
struct Environment {
  glm::vec3 constant{0.0f};
  ImageRGBA equirect;  // empty: constant
  std::string source;  // file the image came from, for messages
  float intensity = 1.0f;
  bool has_image() const { return !equirect.empty(); }
};

struct Bounds {
  glm::vec3 lo{1e30f};
  glm::vec3 hi{-1e30f};
  void grow(const glm::vec3& p);
  bool valid() const { return lo.x <= hi.x; }
  glm::vec3 center() const { return (lo + hi) * 0.5f; }
  glm::vec3 extent() const { return hi - lo; }
};

struct Scene {
  std::string name;  // file path or built-in name
  TriangleMesh mesh;
  std::vector<Material> materials;  // at least one (a default is added when missing)
  std::vector<ImageRGBA> textures;  // decoded, linear
  std::vector<std::string> texture_sources;
  std::vector<Object> objects;
  std::vector<Camera> cameras;      // at least one after loading (a framing default)
  std::vector<Light> lights;
  Environment environment;

  Bounds bounds() const;
  // Checks every invariant kernels rely on (finite positions, indices in range, ids in
  // range, unit normals); throws InputError naming `name` on the first violation.
  void validate() const;
};

// The directions framing_camera looks from (towards the bounds' centre): front from +Z,
// back from −Z, left from −X, right from +X, top from +Y (image up −Z), three-quarter from
// azimuth 45° between +Z and +X at elevation 30°.
enum class View : std::uint8_t { Front, Back, Left, Right, Top, ThreeQuarter };
const char* to_string(View view);

// A camera looking at the bounds' centre from `view` whose view cone holds the bounds'
// bounding sphere (radius r = half the diagonal) for an image of `aspect` = width/height:
// distance r / sin(min(vfov, hfov)/2), so every corner of the bounds projects inside the
// image. Clip planes by sphere_clip_planes.
Camera framing_camera(const Bounds& bounds, View view = View::ThreeQuarter, float aspect = 1.0f,
                      float vfov_degrees = 45.0f);

// `camera` moved along its own view axis and re-aimed at the bounds' centre so that the
// bounding sphere fits as in framing_camera (fov, up and direction kept).
Camera fit_camera(Camera camera, const Bounds& bounds, float aspect);

// Near and far planes around a bounding sphere of radius `radius` whose centre lies
// `centre_depth` ahead of the eye along the view axis (negative: behind): far = depth + 2r,
// near = depth - 1.5r, or a small fraction of far (1e-4) when the eye is inside or close to
// the sphere. framing_camera uses this rule.
struct ClipPlanes {
  float znear = 0.0f;
  float zfar = 0.0f;
};
ClipPlanes sphere_clip_planes(float centre_depth, float radius);

// `camera` with znear/zfar recomputed for its own eye and view direction so that all of
// `bounds` lies between them: the sphere rule above on the sphere around the box, near pulled
// up to 0.9 x the box's nearest corner depth when the box is wholly in front of the eye.
// Unchanged when `bounds` is empty. For cameras moved away from where the scene put them.
Camera fit_clip_planes(Camera camera, const Bounds& bounds);

}  // namespace speculum
