// The eleven built-in scenes (see procedural_scenes.h). Each divides its triangle budget
// among its objects by fixed fractions, so triangle counts track the size parameter.
#include "core/procedural_scenes.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/procedural_geometry.h"

namespace speculum {
namespace {

using namespace procedural;

std::uint64_t share(const BuiltinParams& p, double fraction) {
  return static_cast<std::uint64_t>(static_cast<double>(p.size) * fraction);
}

Camera camera(const char* name, glm::vec3 eye, glm::vec3 target, float vfov, float zfar) {
  Camera c;
  c.name = name;
  c.eye = eye;
  c.target = target;
  c.vfov_degrees = vfov;
  c.znear = 0.05f;
  c.zfar = zfar;
  return c;
}

Light point_light(const char* name, glm::vec3 position, float intensity, glm::vec3 color = glm::vec3(1.0f)) {
  Light l;
  l.name = name;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  l.color = color;
  return l;
}

Light sun_light(glm::vec3 toward_sun, float lux) {
  Light l;
  l.name = "sun";
  l.type = LightType::Directional;
  l.direction = -glm::normalize(toward_sun);
  l.intensity = lux;
  l.color = glm::vec3(1.0f, 0.95f, 0.85f);
  return l;
}

void set_sky(Scene& s, glm::vec3 sun) {
  s.environment.equirect = sky_equirect(512, 256, sun);
  s.environment.source = "procedural sky";
  s.environment.intensity = 1.0f;
}

// A textured material whose base colour multiplies a checker texture.
std::uint32_t checker_material(SceneBuilder& b, Material m, glm::vec3 a, glm::vec3 c, int cells) {
  m.base_color_texture.texture =
      b.add_texture(checker_texture(256, cells, a, c), "procedural checker " + m.name);
  return b.add_material(std::move(m));
}

// A box room from inward quads: floor, ceiling and four walls as separate objects.
void room(SceneBuilder& b, glm::vec3 lo, glm::vec3 hi, std::uint64_t budget,
          std::uint32_t floor_mat, std::uint32_t wall_mat, std::uint32_t ceiling_mat) {
  const int n = cells_for(budget / 6);
  const glm::vec3 d = hi - lo;
  b.add_object("floor", floor_mat, quad(lo, {0, 0, d.z}, {d.x, 0, 0}, n, n, d.x / 2.0f));
  b.add_object("ceiling", ceiling_mat, quad({lo.x, hi.y, lo.z}, {d.x, 0, 0}, {0, 0, d.z}, n, n));
  b.add_object("wall back", wall_mat, quad(lo, {d.x, 0, 0}, {0, d.y, 0}, n, n, 2.0f));
  b.add_object("wall front", wall_mat, quad({hi.x, lo.y, hi.z}, {-d.x, 0, 0}, {0, d.y, 0}, n, n, 2.0f));
  b.add_object("wall left", wall_mat, quad({lo.x, lo.y, hi.z}, {0, 0, -d.z}, {0, d.y, 0}, n, n, 2.0f));
  b.add_object("wall right", wall_mat, quad({hi.x, lo.y, lo.z}, {0, 0, d.z}, {0, d.y, 0}, n, n, 2.0f));
}

// A square ground plane at height y facing +Y.
MeshData ground(float half, float y, std::uint64_t budget, float uv_scale) {
  const int n = cells_for(budget);
  return quad({-half, y, half}, {2 * half, 0, 0}, {0, 0, -2 * half}, n, n, uv_scale);
}

glm::vec2 vase_profile(float t) {
  // Radius along the height: a foot, a belly and a neck (t in [0,1] bottom to top).
  const float r = 0.25f + 0.3f * std::sin(3.1415927f * std::min(t * 1.2f, 1.0f)) + 0.08f * t * t;
  return {r, 1.6f * t};
}

Scene sphere_in_room(const BuiltinParams& p) {
  SceneBuilder b("sphere-in-room");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.8f, 0.8f, 0.8f}, {0.1f, 0.1f, 0.12f}, 8);
  const auto walls = checker_material(b, diffuse("wall checker", glm::vec3(1.0f)),
                                      {0.75f, 0.3f, 0.25f}, {0.9f, 0.85f, 0.7f}, 8);
  const auto ceiling = b.add_material(diffuse("ceiling", glm::vec3(0.9f)));
  const auto chrome = b.add_material(mirror("mirror sphere"));
  const auto gold = b.add_material(glossy("glossy gold", {1.0f, 0.78f, 0.34f}, 0.3f));
  const auto blue = b.add_material(diffuse("blue box", {0.2f, 0.3f, 0.8f}));
  room(b, {-5, 0, -5}, {5, 6, 5}, share(p, 0.25), floor, walls, ceiling);
  b.add_object("mirror sphere", chrome, sphere({0, 1.5f, 0}, 1.5f, rings_for(share(p, 0.6))));
  b.add_object("glossy sphere", gold, sphere({2.6f, 0.6f, 1.6f}, 0.6f, rings_for(share(p, 0.1))));
  b.add_object("box", blue, box({-3.2f, 0, -2.0f}, {-2.0f, 1.2f, -0.8f}, cells_for(share(p, 0.05) / 6), false));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {3.8f, 3.0f, 4.6f}, {0, 1.3f, 0}, 60.0f, 30.0f));
  s.lights.push_back(point_light("ceiling light", {0, 5.5f, 0}, 60.0f));
  s.environment.constant = glm::vec3(0.05f);
  return s;
}

// The same room around a mirror ellipsoid: a smooth star-shaped reflector whose reflection
// points leave the plane through its centre, eye and vertex (ROGER §2.2.3's general case).
Scene ellipsoid_in_room(const BuiltinParams& p) {
  SceneBuilder b("ellipsoid");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.8f, 0.8f, 0.8f}, {0.1f, 0.1f, 0.12f}, 8);
  const auto walls = checker_material(b, diffuse("wall checker", glm::vec3(1.0f)),
                                      {0.75f, 0.3f, 0.25f}, {0.9f, 0.85f, 0.7f}, 8);
  const auto ceiling = b.add_material(diffuse("ceiling", glm::vec3(0.9f)));
  const auto chrome = b.add_material(mirror("mirror ellipsoid"));
  const auto blue = b.add_material(diffuse("blue box", {0.2f, 0.3f, 0.8f}));
  const auto red = b.add_material(diffuse("red ball", {0.8f, 0.15f, 0.1f}));
  room(b, {-5, 0, -5}, {5, 6, 5}, share(p, 0.25), floor, walls, ceiling);
  b.add_object("mirror ellipsoid", chrome, ellipsoid({0, 1.3f, 0}, {1.9f, 1.1f, 1.2f}, rings_for(share(p, 0.6))));
  b.add_object("red ball", red, sphere({2.6f, 0.6f, 1.6f}, 0.6f, rings_for(share(p, 0.1))));
  b.add_object("box", blue, box({-3.2f, 0, -2.0f}, {-2.0f, 1.2f, -0.8f}, cells_for(share(p, 0.05) / 6), false));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {3.8f, 3.0f, 4.6f}, {0, 1.2f, 0}, 60.0f, 30.0f));
  s.lights.push_back(point_light("ceiling light", {0, 5.5f, 0}, 60.0f));
  s.environment.constant = glm::vec3(0.05f);
  return s;
}

Scene glossy_plane(const BuiltinParams& p) {
  SceneBuilder b("glossy-plane");
  Material plane_m = glossy("glossy floor", glm::vec3(1.0f), 0.25f);
  const auto plane = checker_material(b, plane_m, {0.7f, 0.7f, 0.72f}, {0.25f, 0.25f, 0.28f}, 16);
  const auto vase_m = b.add_material(diffuse("terracotta vase", {0.7f, 0.3f, 0.15f}));
  const auto red = b.add_material(diffuse("red sphere", {0.8f, 0.1f, 0.1f}));
  const auto gold = b.add_material(glossy("gold torus", {1.0f, 0.8f, 0.35f}, 0.1f));
  b.add_object("plane", plane, ground(20.0f, 0.0f, share(p, 0.1), 20.0f));
  b.add_object("vase", vase_m, lathe({0, 0, 0}, vase_profile, rings_for(share(p, 0.5))));
  b.add_object("sphere", red, sphere({-1.6f, 0.6f, 0.5f}, 0.6f, rings_for(share(p, 0.2))));
  b.add_object("torus", gold, torus({1.7f, 0.3f, 0.4f}, 0.6f, 0.3f, rings_for(share(p, 0.2) * 2)));
  Scene s = b.take();
  const glm::vec3 sun{0.4f, 0.8f, 0.3f};
  s.cameras.push_back(camera("main", {0, 2.2f, 6.5f}, {0, 0.7f, 0}, 45.0f, 100.0f));
  s.lights.push_back(sun_light(sun, 3.0f));
  set_sky(s, sun);
  return s;
}

Scene mirror_corridor(const BuiltinParams& p) {
  SceneBuilder b("mirror-corridor");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.85f, 0.85f, 0.85f}, {0.1f, 0.1f, 0.1f}, 12);
  const auto glass_m = b.add_material(mirror("planar mirror", glm::vec3(0.92f)));
  const auto red = b.add_material(diffuse("red sphere", {0.8f, 0.15f, 0.1f}));
  const auto green = b.add_material(glossy("green torus", {0.2f, 0.8f, 0.3f}, 0.2f));
  const auto box_m = b.add_material(diffuse("yellow box", {0.9f, 0.8f, 0.2f}));
  const int mn = cells_for(share(p, 0.05));
  b.add_object("mirror left", glass_m, quad({-2, 0, 6}, {0, 0, -12}, {0, 3, 0}, mn, mn));
  b.add_object("mirror right", glass_m, quad({2, 0, -6}, {0, 0, 12}, {0, 3, 0}, mn, mn));
  b.add_object("floor", floor, quad({-2, 0, 6}, {4, 0, 0}, {0, 0, -12}, cells_for(share(p, 0.1)),
                                    cells_for(share(p, 0.1)), 4.0f));
  b.add_object("sphere", red, sphere({-0.6f, 0.5f, 0.0f}, 0.5f, rings_for(share(p, 0.4))));
  b.add_object("torus", green, torus({0.7f, 0.35f, -1.5f}, 0.45f, 0.2f, rings_for(share(p, 0.3) * 2)));
  b.add_object("box", box_m, box({0.3f, 0, 1.0f}, {1.0f, 0.7f, 1.7f}, cells_for(share(p, 0.1) / 6), false));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {-1.2f, 1.5f, 5.0f}, {1.2f, 1.0f, -2.0f}, 55.0f, 60.0f));
  s.lights.push_back(point_light("light", {0, 2.8f, 0.5f}, 30.0f));
  s.environment.constant = glm::vec3(0.02f);
  return s;
}

Scene living_room(const BuiltinParams& p) {
  SceneBuilder b("living-room");
  Material floor_m = glossy("glossy wood floor", glm::vec3(1.0f), 0.35f);
  const auto floor = checker_material(b, floor_m, {0.55f, 0.35f, 0.2f}, {0.4f, 0.24f, 0.12f}, 10);
  const auto walls = checker_material(b, diffuse("wallpaper", glm::vec3(1.0f)),
                                      {0.85f, 0.82f, 0.75f}, {0.75f, 0.72f, 0.65f}, 20);
  const auto ceiling = b.add_material(diffuse("ceiling", glm::vec3(0.9f)));
  const auto wall_mirror = b.add_material(mirror("wall mirror"));
  const auto wood = b.add_material(diffuse("table wood", {0.45f, 0.28f, 0.15f}));
  const auto chrome = b.add_material(mirror("chrome ball"));
  const auto glass_m = b.add_material(glass("glass ball"));
  const auto copper = b.add_material(glossy("copper torus", {0.95f, 0.64f, 0.54f}, 0.15f));
  const auto silver = b.add_material(mirror("silver bowl", {0.97f, 0.96f, 0.91f}));
  const auto satin = b.add_material(glossy("satin vase", {0.6f, 0.6f, 0.65f}, 0.45f));
  const auto bumpy = b.add_material(glossy("bumpy steel", {0.8f, 0.8f, 0.8f}, 0.05f));
  room(b, {-4, 0, -3}, {4, 3, 3}, share(p, 0.15), floor, walls, ceiling);
  const int mn = cells_for(share(p, 0.02));
  b.add_object("wall mirror", wall_mirror, quad({-1.5f, 0.8f, -2.98f}, {3, 0, 0}, {0, 1.6f, 0}, mn, mn));
  const int bn = cells_for(share(p, 0.01) / 6);
  b.add_object("table top", wood, box({-1.0f, 0.7f, -0.6f}, {1.0f, 0.78f, 0.6f}, bn, false));
  for (int i = 0; i < 4; ++i) {
    const float x = i % 2 ? 0.85f : -0.95f, z = i / 2 ? 0.45f : -0.55f;
    b.add_object("table leg " + std::to_string(i), wood, box({x, 0, z}, {x + 0.1f, 0.7f, z + 0.1f}, bn, false));
  }
  b.add_object("chrome ball", chrome, sphere({-0.4f, 1.08f, 0.0f}, 0.3f, rings_for(share(p, 0.15))));
  b.add_object("glass ball", glass_m, sphere({0.45f, 0.98f, 0.1f}, 0.2f, rings_for(share(p, 0.15))));
  b.add_object("copper torus", copper, torus({2.4f, 0.25f, 1.0f}, 0.5f, 0.25f, rings_for(share(p, 0.12) * 2)));
  b.add_object("silver bowl", silver, bowl({-2.5f, 0.6f, 1.2f}, 0.6f, 70.0f, rings_for(share(p, 0.12))));
  b.add_object("vase", satin, lathe({2.8f, 0, -2.2f}, vase_profile, rings_for(share(p, 0.13))));
  b.add_object("bumpy ball", bumpy, bumpy_sphere({-2.8f, 0.5f, -2.0f}, 0.45f, 0.06f, 10.0f, rings_for(share(p, 0.15))));
  // reflectors=N (SOFF §4's living room has 25): the eight above plus N − 8 small ones on the
  // side walls — chrome and gold balls, copper rings and mirror tiles, 1% of the budget each.
  const int extra = static_cast<int>(p.get("reflectors", 8.0)) - 8;
  if (extra > 0) {
    const auto gold = b.add_material(glossy("gold trinket", {1.0f, 0.78f, 0.34f}, 0.2f));
    for (int k = 0; k < extra; ++k) {
      const float side = k % 2 ? 3.75f : -3.75f;
      const int j = k / 2;
      const glm::vec3 at{side, 0.9f + 0.6f * float(j / 8), -2.1f + 0.6f * float(j % 8)};
      const std::string name = "trinket " + std::to_string(k);
      const std::uint64_t budget = share(p, 0.01);
      switch (k % 4) {
        case 0: b.add_object(name, chrome, sphere(at, 0.14f, rings_for(budget))); break;
        case 1: b.add_object(name, copper, torus(at, 0.14f, 0.045f, rings_for(budget * 2))); break;
        case 2: b.add_object(name, gold, sphere(at, 0.12f, rings_for(budget))); break;
        default: {
          // A mirror tile on the wall, facing into the room.
          const float inward = side > 0.0f ? -1.0f : 1.0f;
          const glm::vec3 o = at + glm::vec3(0.2f * inward, -0.15f, 0.15f * inward);
          b.add_object(name, wall_mirror, quad(o, {0, 0, -0.3f * inward}, {0, 0.3f, 0}, cells_for(budget), cells_for(budget)));
        }
      }
    }
  }
  Scene s = b.take();
  s.cameras.push_back(camera("main", {3.3f, 1.8f, 2.7f}, {-0.6f, 0.9f, -1.0f}, 60.0f, 30.0f));
  s.cameras.push_back(camera("mirror view", {0.0f, 1.5f, 2.8f}, {0.0f, 1.4f, -3.0f}, 50.0f, 30.0f));
  s.lights.push_back(point_light("lamp", {0.0f, 2.7f, 0.0f}, 25.0f, {1.0f, 0.9f, 0.75f}));
  s.lights.push_back(point_light("corner lamp", {-3.5f, 2.2f, 2.5f}, 10.0f));
  Light spot;
  spot.name = "spot on table";
  spot.type = LightType::Spot;
  spot.position = {2.0f, 2.9f, 1.5f};
  spot.direction = glm::normalize(glm::vec3(0.0f, 0.9f, 0.0f) - spot.position);
  spot.intensity = 40.0f;
  spot.inner_cone = 0.25f;
  spot.outer_cone = 0.5f;
  s.lights.push_back(spot);
  s.environment.constant = glm::vec3(0.03f);
  return s;
}

Scene glass_sphere(const BuiltinParams& p) {
  SceneBuilder b("glass-sphere");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.9f, 0.9f, 0.9f}, {0.2f, 0.25f, 0.4f}, 20);
  const auto glass_m = b.add_material(glass("glass", 1.5f));
  b.add_object("plane", floor, ground(10.0f, 0.0f, share(p, 0.2), 10.0f));
  b.add_object("glass sphere", glass_m, sphere({0, 1.2f, 0}, 1.0f, rings_for(share(p, 0.8))));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {0, 2.6f, 5.0f}, {0, 0.8f, 0}, 45.0f, 50.0f));
  s.lights.push_back(point_light("point light", {1.5f, 5.0f, 1.0f}, 120.0f));
  set_sky(s, {0.3f, 0.9f, -0.4f});
  s.environment.intensity = 0.3f;
  return s;
}

Scene bowl_scene(const BuiltinParams& p) {
  SceneBuilder b("bowl");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.8f, 0.8f, 0.8f}, {0.3f, 0.1f, 0.1f}, 16);
  Material bowl_m = mirror("concave mirror");
  bowl_m.double_sided = true;
  const auto reflector = b.add_material(bowl_m);
  const auto ball = b.add_material(diffuse("ball", {0.1f, 0.5f, 0.9f}));
  b.add_object("plane", floor, ground(10.0f, 0.0f, share(p, 0.15), 10.0f));
  b.add_object("bowl", reflector, bowl({0, 2.0f, 0}, 2.0f, 75.0f, rings_for(share(p, 0.7))));
  b.add_object("ball", ball, sphere({0.4f, 0.45f, 0.2f}, 0.4f, rings_for(share(p, 0.15))));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {0, 4.2f, 4.5f}, {0, 0.8f, 0}, 50.0f, 50.0f));
  s.lights.push_back(point_light("light", {0.5f, 5.0f, 2.0f}, 80.0f));
  set_sky(s, {-0.5f, 0.7f, 0.5f});
  s.environment.intensity = 0.5f;
  return s;
}

// SOFF §4's second scene: a bathroom of ~90K triangles at the default size with 15
// reflective objects (Fig. 3): a wall mirror and a cabinet mirror, chrome taps, shower head,
// towel ring and ball, a glossy tub, basin, sink and soap dish, glossy floor and wall tiles
// and a satin vase; about half the triangles are non-diffuse, as in SOFF §4.
Scene bathroom(const BuiltinParams& p) {
  SceneBuilder b("bathroom");
  const auto floor_tiles = checker_material(b, glossy("glossy floor tiles", glm::vec3(1.0f), 0.3f),
                                            {0.75f, 0.75f, 0.78f}, {0.25f, 0.28f, 0.32f}, 12);
  const auto wall_tiles = checker_material(b, glossy("glossy wall tiles", glm::vec3(1.0f), 0.35f),
                                           {0.55f, 0.7f, 0.75f}, {0.85f, 0.9f, 0.9f}, 16);
  const auto paint = checker_material(b, diffuse("painted wall", glm::vec3(1.0f)), {0.9f, 0.86f, 0.78f},
                                      {0.82f, 0.78f, 0.7f}, 6);
  const auto ceiling = b.add_material(diffuse("ceiling", glm::vec3(0.92f)));
  const auto mirror_m = b.add_material(mirror("bathroom mirror", glm::vec3(0.93f)));
  const auto chrome = b.add_material(mirror("chrome", glm::vec3(0.9f, 0.9f, 0.92f)));
  const auto ceramic = b.add_material(glossy("white ceramic", glm::vec3(0.92f), 0.12f));
  const auto enamel = b.add_material(glossy("tub enamel", {0.95f, 0.95f, 0.9f}, 0.2f));
  const auto satin = b.add_material(glossy("satin vase", {0.3f, 0.45f, 0.7f}, 0.4f));
  const auto wood = b.add_material(diffuse("cabinet wood", {0.5f, 0.33f, 0.2f}));
  const auto towel = b.add_material(diffuse("towel", {0.8f, 0.25f, 0.2f}));
  const auto rug = b.add_material(diffuse("rug", {0.2f, 0.45f, 0.3f}));
  const auto porcelain = b.add_material(diffuse("matte porcelain", {0.85f, 0.85f, 0.82f}));
  const glm::vec3 lo{-1.5f, 0.0f, -1.75f}, hi{1.5f, 2.6f, 1.75f};
  const glm::vec3 d = hi - lo;
  const int wn = cells_for(share(p, 0.04));
  b.add_object("floor", floor_tiles, quad(lo, {0, 0, d.z}, {d.x, 0, 0}, cells_for(share(p, 0.06)),
                                          cells_for(share(p, 0.06)), 2.0f));
  b.add_object("ceiling", ceiling, quad({lo.x, hi.y, lo.z}, {d.x, 0, 0}, {0, 0, d.z}, cells_for(share(p, 0.02)),
                                        cells_for(share(p, 0.02))));
  b.add_object("wall back", paint, quad(lo, {d.x, 0, 0}, {0, d.y, 0}, wn, wn, 2.0f));
  b.add_object("wall front", paint, quad({hi.x, lo.y, hi.z}, {-d.x, 0, 0}, {0, d.y, 0}, wn, wn, 2.0f));
  b.add_object("wall left", paint, quad({lo.x, lo.y, hi.z}, {0, 0, -d.z}, {0, d.y, 0}, wn, wn, 2.0f));
  b.add_object("tiled wall", wall_tiles, quad({hi.x, lo.y, lo.z}, {0, 0, d.z}, {0, d.y, 0}, wn, wn, 2.0f));
  const int mn = cells_for(share(p, 0.01));
  b.add_object("wall mirror", mirror_m, quad({-1.25f, 1.1f, -1.74f}, {1.1f, 0, 0}, {0, 0.9f, 0}, mn, mn));
  b.add_object("cabinet mirror", mirror_m, quad({-1.49f, 1.2f, -1.3f}, {0, 0, 0.8f}, {0, 0.8f, 0}, mn, mn));
  b.add_object("sink", ceramic, bowl({-0.7f, 1.15f, -1.42f}, 0.28f, 75.0f, rings_for(share(p, 0.08))));
  b.add_object("sink tap", chrome, torus({-0.7f, 1.2f, -1.66f}, 0.06f, 0.016f, rings_for(share(p, 0.04) * 2)));
  b.add_object("tap handle", chrome, sphere({-0.52f, 1.0f, -1.66f}, 0.035f, rings_for(share(p, 0.02))));
  b.add_object("tub", enamel, box({-1.5f, 0.0f, -0.2f}, {-0.72f, 0.55f, 1.75f}, cells_for(share(p, 0.04) / 6), false));
  b.add_object("tub basin", enamel, bowl({-1.11f, 1.0f, 0.78f}, 0.42f, 62.0f, rings_for(share(p, 0.04))));
  b.add_object("tub faucet", chrome, torus({-1.11f, 0.95f, 1.62f}, 0.08f, 0.022f, rings_for(share(p, 0.05) * 2)));
  b.add_object("shower head", chrome, torus({-1.11f, 2.05f, 1.5f}, 0.11f, 0.035f, rings_for(share(p, 0.03) * 2)));
  b.add_object("towel ring", chrome, torus({1.2f, 1.15f, 0.35f}, 0.2f, 0.02f, rings_for(share(p, 0.04) * 2)));
  b.add_object("chrome ball", chrome, sphere({0.55f, 0.25f, -0.85f}, 0.25f, rings_for(share(p, 0.08))));
  b.add_object("soap dish", ceramic, bowl({-0.3f, 1.12f, -1.6f}, 0.09f, 70.0f, rings_for(share(p, 0.04))));
  b.add_object("vase", satin, lathe({1.2f, 0.8f, -1.52f}, [](float t) {
    return glm::vec2(0.06f + 0.06f * std::sin(3.1415927f * t), 0.45f * t);
  }, rings_for(share(p, 0.08))));
  b.add_object("cabinet", wood, box({0.9f, 0.0f, -1.75f}, {1.5f, 0.8f, -1.3f}, cells_for(share(p, 0.02) / 6), false));
  b.add_object("towel", towel, box({1.12f, 0.6f, 0.2f}, {1.22f, 1.12f, 0.5f}, cells_for(share(p, 0.01) / 6), false));
  b.add_object("rug", rug, quad({-0.3f, 0.005f, 1.1f}, {1.0f, 0, 0}, {0, 0, -0.8f}, cells_for(share(p, 0.01)),
                                cells_for(share(p, 0.01))));
  b.add_object("toilet", porcelain, lathe({0.3f, 0.0f, -1.4f}, [](float t) {
    return glm::vec2(0.2f + 0.06f * std::sin(3.1415927f * t), 0.45f * t);
  }, rings_for(share(p, 0.12))));
  b.add_object("laundry basket", wood, lathe({1.05f, 0.0f, 1.35f}, [](float t) {
    return glm::vec2(0.22f - 0.04f * t, 0.55f * t);
  }, rings_for(share(p, 0.04))));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {1.2f, 1.6f, 1.55f}, {-0.6f, 1.0f, -1.2f}, 60.0f, 20.0f));
  s.lights.push_back(point_light("ceiling light", {0.0f, 2.5f, 0.0f}, 14.0f, {1.0f, 0.95f, 0.85f}));
  s.lights.push_back(point_light("mirror light", {-0.7f, 2.2f, -1.3f}, 5.0f));
  s.environment.constant = glm::vec3(0.03f);
  return s;
}

Scene bumpy_sphere_scene(const BuiltinParams& p) {
  SceneBuilder b("bumpy-sphere");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.85f, 0.85f, 0.85f}, {0.15f, 0.15f, 0.15f}, 16);
  const auto steel = b.add_material(mirror("bumpy mirror", {0.9f, 0.9f, 0.92f}));
  const float n = static_cast<float>(p.get("n", 8.0));
  const float amplitude = static_cast<float>(p.get("amplitude", 0.06));
  b.add_object("plane", floor, ground(10.0f, 0.0f, share(p, 0.15), 10.0f));
  b.add_object("bumpy sphere", steel,
               bumpy_sphere({0, 1.2f, 0}, 1.0f, amplitude, n, rings_for(share(p, 0.85))));
  Scene s = b.take();
  const glm::vec3 sun{0.5f, 0.7f, 0.4f};
  s.cameras.push_back(camera("main", {0, 1.9f, 4.2f}, {0, 1.1f, 0}, 45.0f, 50.0f));
  s.lights.push_back(sun_light(sun, 3.0f));
  s.lights.push_back(point_light("fill", {-2.0f, 3.0f, 2.0f}, 20.0f));
  set_sky(s, sun);
  return s;
}

// An open metal ring (a short cylinder, mirror inside and out) on a plane, lit from the side
// by a low point light: the light reflected inside the ring gathers on the floor along the
// cusped caustic of a coffee cup (the cardioid of SURVEY §6's figures).
Scene caustic_ring(const BuiltinParams& p) {
  SceneBuilder b("caustic-ring");
  const auto floor = checker_material(b, diffuse("floor checker", glm::vec3(1.0f)),
                                      {0.85f, 0.85f, 0.85f}, {0.6f, 0.6f, 0.65f}, 12);
  Material ring_m = mirror("polished ring", {0.95f, 0.93f, 0.88f});
  ring_m.double_sided = true;
  const auto ring = b.add_material(ring_m);
  b.add_object("plane", floor, ground(8.0f, 0.0f, share(p, 0.3), 8.0f));
  b.add_object("ring", ring, lathe({0, 0, 0}, [](float t) { return glm::vec2(1.0f, 0.5f * t); },
                                   rings_for(share(p, 0.7))));
  Scene s = b.take();
  s.cameras.push_back(camera("main", {0.6f, 2.6f, 2.4f}, {0, 0.1f, -0.1f}, 50.0f, 40.0f));
  s.lights.push_back(point_light("side light", {-4.0f, 1.3f, 0.4f}, 60.0f));
  s.environment.constant = glm::vec3(0.08f);
  return s;
}

// The surface of a water-like slab: a few crossing waves about height `level`.
float wave_height(float x, float z, float level, float amplitude) {
  return level + amplitude * (std::sin(2.7f * x + 0.4f) * std::cos(2.1f * z) + 0.6f * std::sin(3.9f * z - 1.7f * x));
}

// A closed slab of water, |x|, |z| ≤ half, from `bottom` to the wavy top: the top grid, a
// flat bottom and four side walls that follow the waves' edge.
MeshData wavy_slab(float half, float bottom, float level, float amplitude, int n) {
  MeshData out;
  const auto append = [&](MeshData m) {
    const auto base = static_cast<std::uint32_t>(out.positions.size());
    out.positions.insert(out.positions.end(), m.positions.begin(), m.positions.end());
    out.uvs.insert(out.uvs.end(), m.uvs.begin(), m.uvs.end());
    for (std::uint32_t i : m.indices) out.indices.push_back(base + i);
  };
  const float w = 2.0f * half;
  // Each grid's du × dv points out of the slab.
  append(parametric_grid(n, n, [&](float u, float v) {
    const float x = -half + w * v, z = -half + w * u;
    return glm::vec3(x, wave_height(x, z, level, amplitude), z);
  }));
  append(parametric_grid(n, n, [&](float u, float v) { return glm::vec3(-half + w * u, bottom, -half + w * v); }));
  const int sides = std::max(1, n / 8);
  for (int side = 0; side < 4; ++side)
    append(parametric_grid(n, sides, [&](float u, float v) {
      // Walls at z = +half, x = +half, z = −half, x = −half, walked so du × dv faces out.
      float x = 0.0f, z = 0.0f;
      const float t = -half + w * u;
      if (side == 0) x = t, z = half;
      else if (side == 1) x = half, z = -t;
      else if (side == 2) x = -t, z = -half;
      else x = -half, z = t;
      return glm::vec3(x, bottom + (wave_height(x, z, level, amplitude) - bottom) * v, z);
    }));
  return out;
}

// A slab of water (ior 1.33) with a wavy top over a tiled floor, lit by a high sun: the
// waves focus the light into a net of caustics on the floor.
Scene water_slab(const BuiltinParams& p) {
  SceneBuilder b("water-slab");
  const auto floor = checker_material(b, diffuse("pool tiles", glm::vec3(1.0f)),
                                      {0.9f, 0.9f, 0.88f}, {0.35f, 0.55f, 0.7f}, 16);
  Material water_m = glass("water", 1.33f);
  water_m.base_color = glm::vec4(0.92f, 0.97f, 1.0f, 1.0f);
  const auto water = b.add_material(water_m);
  b.add_object("floor", floor, ground(6.0f, 0.0f, share(p, 0.2), 6.0f));
  const int n = std::max(4, static_cast<int>(std::lround(std::sqrt(static_cast<double>(share(p, 0.8)) / 5.0))));
  b.add_object("water", water, wavy_slab(1.6f, 0.35f, 1.0f, 0.05f, n));
  Scene s = b.take();
  const glm::vec3 sun{0.25f, 1.0f, 0.35f};
  s.cameras.push_back(camera("main", {0.0f, 3.4f, 3.6f}, {0, 0.3f, 0}, 45.0f, 40.0f));
  s.lights.push_back(sun_light(sun, 3.0f));
  set_sky(s, sun);
  s.environment.intensity = 0.4f;
  return s;
}

constexpr BuiltinScene kScenes[] = {
    {"sphere-in-room", "mirror sphere in a textured box room (SURVEY's classic set-up)", 20000, "",
     sphere_in_room},
    {"glossy-plane", "a vase, a ball and a torus standing on a glossy textured plane", 20000, "",
     glossy_plane},
    {"mirror-corridor", "two facing planar mirrors with objects between (inter-reflections)",
     20000, "", mirror_corridor},
    {"living-room", "a room with many reflectors: wall mirror, chrome, glass, copper, bowl", 50000,
     "reflectors=8 (8..40: small chrome, gold, copper and mirror pieces added; SOFF's room has 25)", living_room},
    {"glass-sphere", "a refracting glass sphere (ior 1.5) over a plane, lit by a point light",
     20000, "", glass_sphere},
    {"bowl", "a concave spherical mirror bowl with a ball inside", 20000, "", bowl_scene},
    {"bathroom", "SOFF's bathroom: 15 reflectors (mirrors, chrome, glossy tub, sink and tiles), ~90K tris",
     90000, "", bathroom},
    {"bumpy-sphere", "a mirror sphere displaced by cos(n x) cos(n y)", 40000,
     "n=8 (bump frequency), amplitude=0.06 (relative to the radius)", bumpy_sphere_scene},
    {"ellipsoid", "a mirror ellipsoid (radii 1.9, 1.1, 1.2) in the textured box room", 20000, "",
     ellipsoid_in_room},
    {"caustic-ring", "a mirror ring on a plane lit from the side: the cusped caustic inside the ring",
     20000, "", caustic_ring},
    {"water-slab", "a slab of water (ior 1.33) with a wavy top over a tiled floor under a high sun",
     20000, "", water_slab},
};

// Key cameras of one path: eyes and targets in pairs.
CameraPath path(const char* name, int frames, float vfov, std::initializer_list<std::pair<glm::vec3, glm::vec3>> keys) {
  CameraPath p;
  p.name = name;
  p.frames = frames;
  for (const auto& [eye, target] : keys) p.keys.push_back(camera(name, eye, target, vfov, 30.0f));
  return p;
}

}  // namespace

Camera CameraPath::at(int frame) const {
  if (keys.size() < 2 || frames < 2) return keys.front();
  const float s = float(std::clamp(frame, 0, frames - 1)) / float(frames - 1) * float(keys.size() - 1);
  const std::size_t k = std::min(keys.size() - 2, static_cast<std::size_t>(s));
  const float t = s - float(k);
  Camera c = keys.front();
  // (1 − t) a + t b: exactly the keys at t = 0 and t = 1.
  c.eye = keys[k].eye * (1.0f - t) + keys[k + 1].eye * t;
  c.target = keys[k].target * (1.0f - t) + keys[k + 1].target * t;
  return c;
}

std::vector<CameraPath> builtin_camera_paths(std::string_view name) {
  if (name == "bathroom")
    return {path("walk", 60, 60.0f,
                 {{{1.2f, 1.6f, 1.55f}, {-0.6f, 1.0f, -1.2f}},
                  {{0.7f, 1.55f, 0.9f}, {-0.7f, 1.1f, -1.5f}},
                  {{0.2f, 1.5f, 0.3f}, {-0.8f, 1.2f, -1.7f}}}),
            path("pan", 60, 60.0f,
                 {{{0.9f, 1.5f, 1.4f}, {-1.1f, 0.8f, 1.0f}},
                  {{0.9f, 1.5f, 1.4f}, {-0.8f, 1.3f, -1.6f}},
                  {{0.9f, 1.5f, 1.4f}, {1.2f, 0.9f, -1.5f}}})};
  if (name == "living-room")
    return {path("walk", 60, 60.0f,
                 {{{3.3f, 1.8f, 2.7f}, {-0.6f, 0.9f, -1.0f}},
                  {{2.0f, 1.6f, 2.2f}, {-0.5f, 1.0f, -1.8f}},
                  {{0.8f, 1.5f, 1.8f}, {-0.5f, 1.1f, -2.8f}}}),
            path("orbit", 60, 60.0f,
                 {{{3.0f, 1.7f, 1.2f}, {0.0f, 0.9f, 0.0f}},
                  {{2.2f, 1.7f, 2.2f}, {0.0f, 0.9f, 0.0f}},
                  {{0.6f, 1.7f, 2.7f}, {0.0f, 0.9f, 0.0f}},
                  {{-1.6f, 1.7f, 2.4f}, {0.0f, 0.9f, 0.0f}}})};
  return {};
}

std::span<const BuiltinScene> builtin_scenes() { return kScenes; }

const BuiltinScene* find_builtin_scene(std::string_view name) {
  for (const auto& s : kScenes)
    if (name == s.name) return &s;
  return nullptr;
}

}  // namespace speculum
