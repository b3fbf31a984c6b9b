// The shared shading model (see core/shading.h for the model in full).
#include "core/shading.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "core/brdf.h"
#include "core/optics.h"
#include "core/sampling.h"

namespace speculum {

SurfaceParams surface_params(const Material& m) {
  SurfaceParams s;
  s.base_color = glm::vec3(m.base_color);
  s.metallic = std::clamp(m.metallic, 0.0f, 1.0f);
  s.roughness = std::clamp(m.roughness, 0.0f, 1.0f);
  s.transmission = std::clamp(m.transmission, 0.0f, 1.0f);
  s.ior = m.ior;
  s.emissive = m.emissive;
  s.phong_exponent = m.phong_exponent();
  return s;
}

int repeat_index(long long i, int n) {
  // Most lookups land inside the image or on a power-of-two side (a repeating texture's
  // usual size, where two's complement makes the mask the positive remainder): no division
  // for those, and a 32-bit one while i fits (the same index every way).
  if (i >= 0 && i < n) return static_cast<int>(i);
  if ((n & (n - 1)) == 0) return static_cast<int>(i & static_cast<long long>(n - 1));
  if (i >= std::numeric_limits<int>::min() && i <= std::numeric_limits<int>::max()) {
    const int r = static_cast<int>(i) % n;
    return r < 0 ? r + n : r;
  }
  const long long r = i % n;
  return static_cast<int>(r < 0 ? r + n : r);
}

namespace {
const glm::vec4 kOne(1.0f);  // what a missing image or texture reads
// The taps of a lookup that is one texel itself.
BilinearTaps single_texel(const glm::vec4& texel) {
  BilinearTaps t;
  t.texel[0] = &texel, t.single = true;
  return t;
}
}  // namespace

BilinearTaps bilinear_repeat_taps(const ImageRGBA& image, glm::vec2 uv) {
  if (image.empty()) return single_texel(kOne);
  const float fx = uv.x * static_cast<float>(image.width) - 0.5f;
  const float fy = uv.y * static_cast<float>(image.height) - 0.5f;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return single_texel(image.pixels[0]);
  BilinearTaps t;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  t.ax = fx - x0f, t.ay = fy - y0f;
  const long long x0 = static_cast<long long>(x0f), y0 = static_cast<long long>(y0f);
  // The next texel wraps from the first: repeat_index(x0 + 1) without a second remainder.
  const int xa = repeat_index(x0, image.width), xb = xa + 1 < image.width ? xa + 1 : 0;
  const int ya = repeat_index(y0, image.height), yb = ya + 1 < image.height ? ya + 1 : 0;
  t.texel[0] = &image.at(xa, ya), t.texel[1] = &image.at(xb, ya);
  t.texel[2] = &image.at(xa, yb), t.texel[3] = &image.at(xb, yb);
  return t;
}

glm::vec4 BilinearTaps::value() const {
  if (single) return *texel[0];
  const glm::vec4 top = *texel[0] * (1.0f - ax) + *texel[1] * ax;
  const glm::vec4 bottom = *texel[2] * (1.0f - ax) + *texel[3] * ax;
  return top * (1.0f - ay) + bottom * ay;
}

void BilinearTaps::prefetch() const {
  const auto line = [](const glm::vec4* p) { __builtin_prefetch(p, 0, 3); };
  line(texel[0]);
  if (single) return;
  for (int k = 1; k < 4; ++k) line(texel[k]);
}

glm::vec4 sample_bilinear_repeat(const ImageRGBA& image, glm::vec2 uv) { return bilinear_repeat_taps(image, uv).value(); }

BilinearTaps texture_taps(const Scene& scene, const TextureRef& ref, glm::vec2 uv, glm::vec2 uv1) {
  if (!ref.valid() || static_cast<std::size_t>(ref.texture) >= scene.textures.size()) return single_texel(kOne);
  const glm::vec2 base = ref.texcoord == 1 ? uv1 : uv;
  const glm::vec3 t = ref.uv_transform * glm::vec3(base, 1.0f);
  return bilinear_repeat_taps(scene.textures[static_cast<std::size_t>(ref.texture)], glm::vec2(t));
}

namespace {
glm::vec4 lookup(const Scene& scene, const TextureRef& ref, glm::vec2 uv, glm::vec2 uv1) {
  return texture_taps(scene, ref, uv, uv1).value();
}
}  // namespace

SurfaceParams surface_params(const Scene& scene, std::uint32_t material_index, glm::vec2 uv,
                             glm::vec2 uv1) {
  if (material_index >= scene.materials.size()) return SurfaceParams{};
  const Material& m = scene.materials[material_index];
  SurfaceParams s = surface_params(m);
  if (m.base_color_texture.valid())
    s.base_color *= glm::vec3(lookup(scene, m.base_color_texture, uv, uv1));
  if (m.metallic_roughness_texture.valid()) {
    const glm::vec4 mr = lookup(scene, m.metallic_roughness_texture, uv, uv1);
    s.metallic = std::clamp(s.metallic * mr.z, 0.0f, 1.0f);
    s.roughness = std::clamp(s.roughness * mr.y, 0.0f, 1.0f);
    Material tmp;
    tmp.roughness = s.roughness;
    s.phong_exponent = tmp.phong_exponent();
  }
  if (m.emissive_texture.valid()) s.emissive *= glm::vec3(lookup(scene, m.emissive_texture, uv, uv1));
  if (m.transmission_texture.valid())
    s.transmission = std::clamp(s.transmission * lookup(scene, m.transmission_texture, uv, uv1).x, 0.0f, 1.0f);
  return s;
}

LightSampler::LightSampler(const Light& light) : light_(&light) {
  if (light.type == LightType::Point) return;
  direction_ = glm::normalize(light.direction);
  if (light.type != LightType::Spot) return;
  // glTF KHR_lights_punctual reference falloff: linear in cos between the cones, squared.
  cos_outer_ = std::cos(light.outer_cone);
  const float cos_inner = std::cos(light.inner_cone);
  cone_scale_ = 1.0f / std::max(0.001f, cos_inner - cos_outer_);
}

LightSample sample_light(const Light& light, const glm::vec3& position) { return LightSampler(light)(position); }

glm::vec3 specular_f0(const SurfaceParams& s) {
  const float dielectric = fresnel_f0(s.ior);
  return glm::vec3(dielectric) * (1.0f - s.metallic) + s.base_color * s.metallic;
}

glm::vec3 specular_reflectance(const SurfaceParams& s, float cos_nv) {
  cos_nv = std::clamp(cos_nv, 0.0f, 1.0f);
  // A mirror's lobe is the delta limit α → 0, where the albedo is Schlick's F at N·V itself.
  if (s.is_mirror_lobe()) return fresnel_schlick(cos_nv, specular_f0(s));
  return specular_albedo(cos_nv, s.roughness * s.roughness)(specular_f0(s));
}

namespace {
// What shade_light's coupled Lambert lobe (core/brdf.h) reflects under uniform light:
// base (1 − E(N·V)), E the dielectric specular layer's albedo at N·V and the same α.
glm::vec3 diffuse_albedo_over_pi_of(const SurfaceParams& s, float e) {
  return s.base_color * ((1.0f - s.metallic) * (1.0f - s.transmission) * (1.0f - e) / kPi);
}
}  // namespace

glm::vec3 diffuse_albedo_over_pi(const SurfaceParams& s, const BrdfAtView& view) {
  // view.alpha is the punctual α (≥ kMinPunctualRoughness², so its clamp to kMinAlpha changed
  // nothing) and the table clamps N·V to [0, 1] either way: the same lookup as below.
  return diffuse_albedo_over_pi_of(s, SpecularAlbedo{view.scale_at_view, view.bias_at_view}(view.dielectric_f0));
}

glm::vec3 diffuse_albedo_over_pi(const SurfaceParams& s, float cos_nv) {
  const BrdfParams p = brdf_params_for_punctual_light(s);
  return diffuse_albedo_over_pi_of(s, specular_albedo(std::clamp(cos_nv, 0.0f, 1.0f), p.alpha)(p.dielectric_f0));
}

LobeSample sample_specular_lobe(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v, glm::vec2 u) {
  return SpecularLobeSampler(s, n, v)(u);
}

namespace {
glm::vec3 local_view(const Onb& frame, const glm::vec3& v) {
  return {glm::dot(v, frame.t), glm::dot(v, frame.b), glm::dot(v, frame.n)};
}
}  // namespace

SpecularLobeSampler::SpecularLobeSampler(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v)
    : frame_(n),
      v_(v),
      alpha_(s.roughness * s.roughness),
      cos_nv_(local_view(frame_, v).z),
      g1_(smith_g1(cos_nv_, std::max(alpha_, kMinAlpha))),
      above_(cos_nv_ > 0.0f),
      normals_(local_view(frame_, v), alpha_),
      f0_(specular_f0(s)) {}

LobeSample SpecularLobeSampler::operator()(glm::vec2 u) const {
  if (!above_) return {};
  const glm::vec3 h = frame_.to_world(normals_(u));
  const float cos_vh = glm::dot(v_, h);
  const glm::vec3 wi = glm::normalize(2.0f * cos_vh * h - v_);
  const float w = ggx_sample_weight(glm::dot(wi, frame_.n), cos_nv_, alpha_, g1_);
  if (!(w > 0.0f)) return {};
  return {wi, fresnel_schlick(std::clamp(cos_vh, 0.0f, 1.0f), f0_) * w};
}

BrdfParams brdf_params_for_punctual_light(const SurfaceParams& s) {
  BrdfParams p;
  p.base_color = s.base_color;
  p.metallic = s.metallic;
  const float r = std::max(s.roughness, kMinPunctualRoughness);
  p.alpha = r * r;
  p.dielectric_f0 = fresnel_f0(s.ior);
  p.transmission = s.transmission;
  return p;
}

glm::vec3 shade_light(const SurfaceParams& s, const BrdfAtView& view, const glm::vec3& n, const glm::vec3& v,
                      const LightSample& light) {
  const float cos_nl = glm::dot(n, light.direction);
  if (cos_nl <= 0.0f) return glm::vec3(0.0f);
  const BrdfValue f = gltf_brdf(view, n, light.direction, v);
  // Mirror-class surfaces: the delta lobe's image of a point light is a point of zero solid
  // angle, which camera rays never see directly either, so it adds nothing (see shading.h).
  const glm::vec3 brdf = s.is_mirror_lobe() ? f.diffuse : f.total();
  return brdf * (cos_nl * light.irradiance);
}

glm::vec3 shade_light(const SurfaceParams& s, const glm::vec3& n, const glm::vec3& v,
                      const LightSample& light) {
  if (glm::dot(n, light.direction) <= 0.0f) return glm::vec3(0.0f);
  return shade_light(s, brdf_at_view(brdf_params_for_punctual_light(s), n, v), n, v, light);
}

glm::vec2 equirect_uv(const glm::vec3& d) {
  const float u = 0.5f + std::atan2(d.x, -d.z) / (2.0f * kPi);
  const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) / kPi;
  return {u, v};
}

glm::vec3 equirect_direction(float u, float v) {
  const float phi = 2.0f * kPi * (u - 0.5f), theta = kPi * v;
  return {std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi)};
}

double equirect_pixel_solid_angle(int y, int width, int height) {
  return 2.0 * double(kPi) / width *
         (std::cos(double(kPi) * y / height) - std::cos(double(kPi) * (y + 1) / height));
}

glm::vec3 environment_radiance(const Environment& env, const glm::vec3& d) {
  if (!env.has_image()) return env.constant * env.intensity;
  const glm::vec2 uv = equirect_uv(glm::normalize(d));
  // Repeat in u is the longitude wrap; v is clamped to the row centres by construction of
  // acos range, and the one-texel wrap at the poles is a negligible blend.
  const ImageRGBA& img = env.equirect;
  const float fy = std::clamp(uv.y * img.height - 0.5f, 0.0f, static_cast<float>(img.height - 1));
  const glm::vec2 clamped{uv.x, (fy + 0.5f) / static_cast<float>(img.height)};
  return glm::vec3(sample_bilinear_repeat(img, clamped)) * env.intensity;
}

glm::vec3 environment_mean_radiance(const Environment& env) {
  if (!env.has_image()) return env.constant * env.intensity;
  const ImageRGBA& img = env.equirect;
  glm::dvec3 sum(0.0);
  double weight = 0.0;
  for (int y = 0; y < img.height; ++y) {
    const double w = std::sin(kPi * (y + 0.5) / img.height);  // the row's solid angle share
    for (int x = 0; x < img.width; ++x) sum += w * glm::dvec3(glm::vec3(img.at(x, y)));
    weight += w * img.width;
  }
  return glm::vec3(sum / weight) * env.intensity;
}

std::vector<std::uint8_t> refractor_objects(const Scene& scene) {
  std::vector<std::uint8_t> out(scene.objects.size(), 0);
  for (std::size_t t = 0; t < scene.mesh.triangle_count(); ++t) {
    const std::uint32_t o = scene.mesh.triangle_object[t], mat = scene.mesh.triangle_material[t];
    if (o < out.size() && mat < scene.materials.size() &&
        surface_params(scene.materials[mat]).is_refractor())
      out[o] = 1;
  }
  return out;
}


}  // namespace speculum
