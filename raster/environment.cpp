// The `environment` node: see environment.h. Prefiltering cascades: level l is level l−1
// convolved with the lobe whose variance is the difference of the two levels' target
// variances (lobes of small angle compose like Gaussians), so each level costs a fixed
// number of lookups whatever its lobe width.
#include "raster/environment.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include <glm/geometric.hpp>

#include "core/sampling.h"
#include "core/shading.h"
#include "parallel/lanes.h"
#include "raster/cube_bilinear_lanes.h"
#include "raster/cube_coord_lanes.h"

namespace speculum::raster {
namespace {

constexpr int kPrefilterSamples = 48;
constexpr float kLn2 = 0.69314718f;

// Half-power angle of a Phong lobe: cos^n θ = 1/2 → θ ≈ sqrt(2 ln 2 / n) for large n.
float lobe_angle(float n) { return std::sqrt(2.0f * kLn2 / std::max(n, 1e-6f)); }
float lobe_exponent(float angle) { return 2.0f * kLn2 / (angle * angle); }
float texel_angle(int size) { return 0.5f * kPi / static_cast<float>(size); }

// The Phong exponent of the cascade's step to level l ≥ 1 of a map of side `size`: the lobe
// that widens level l − 1's (none at level 0) to a half-power angle of one level-l texel.
float step_lobe_exponent(int size, int l) {
  const float target = texel_angle(std::max(1, size >> l));
  const float previous = l == 1 ? 0.0f : texel_angle(std::max(1, size >> (l - 1)));
  return lobe_exponent(std::sqrt(target * target - previous * previous));
}

// The widest of the prefiltering step's samples from its axis: the Hamersley point
// u.x = (N−1)/N of sample_phong_lobe, at cos θ = (1/N)^(1/(n+1)).
float widest_step_sample(int size, int l) {
  return std::acos(std::pow(1.0f / kPrefilterSamples, 1.0f / (step_lobe_exponent(size, l) + 1.0f)));
}

glm::vec4 bilinear_face(const ImageRGBA& img, glm::vec2 pixel) {
  const int s = img.width;
  const float fx = std::clamp(pixel.x - 0.5f, 0.0f, float(s - 1));
  const float fy = std::clamp(pixel.y - 0.5f, 0.0f, float(s - 1));
  const int x0 = int(fx), y0 = int(fy), x1 = std::min(x0 + 1, s - 1), y1 = std::min(y0 + 1, s - 1);
  const float tx = fx - x0, ty = fy - y0;
  return (img.at(x0, y0) * (1 - tx) + img.at(x1, y0) * tx) * (1 - ty) +
         (img.at(x0, y1) * (1 - tx) + img.at(x1, y1) * tx) * ty;
}

glm::vec3 lookup_level(const std::array<ImageRGBA, kCubeFaces>& level, const glm::vec3& d) {
  const int s = level[0].width;
  const CubeCoord c = cube_coord(d, s);
  return glm::vec3(bilinear_face(level[c.face], c.pixel));
}

// Prefiltered texel i of face `face` on a level of side s: the mean of previous-level
// lookups along the lobe directions `local` about the texel's axis (the scalar reference).
glm::vec3 prefilter_texel(const std::array<ImageRGBA, kCubeFaces>& previous, int face, int s, std::size_t i,
                          const glm::vec3* local, int count) {
  const glm::vec3 axis = cube_direction(face, {i % s + 0.5f, i / s + 0.5f}, s);
  const Onb onb(axis);
  glm::vec3 sum(0.0f);
  for (int k = 0; k < count; ++k) sum += lookup_level(previous, onb.to_world(local[k]));
  return sum;
}

// lookup_level for eight directions at once (d: lanes of x, y, z): per lane the operations
// of lookup_level in its order (cube_coord8 is cube_coord per lane; bilinear_rgb8 is
// bilinear_face per lane), so every lane has the bits of the scalar call. out: r, g, b.
[[gnu::always_inline]] inline void lookup_level8(const RgbaFaces& level, const par::Lanes<8>::f32 (&d)[3],
                                                 par::Lanes<8>::f32 (&out)[3]) {
  bilinear_rgb8(level, cube_coord8(d, level.side), out);
}

// Eight texels of one face at once, lane j = texel first + j: per lane the operations of
// prefilter_texel in its order (the lookups of lookup_level8, the sum over k in order), so
// the result has the same bits for every texel.
void prefilter_texels8(const std::array<ImageRGBA, kCubeFaces>& previous, int face, int s, std::size_t first,
                       const glm::vec3* local, int count, glm::vec3* out) {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  alignas(32) float t[3][8], b[3][8], n[3][8];
  for (int j = 0; j < 8; ++j) {
    const std::size_t i = first + static_cast<std::size_t>(j);
    const glm::vec3 axis = cube_direction(face, {i % s + 0.5f, i / s + 0.5f}, s);
    const Onb onb(axis);
    for (int c = 0; c < 3; ++c) t[c][j] = onb.t[c], b[c][j] = onb.b[c], n[c][j] = onb.n[c];
  }
  f32 tv[3], bv[3], nv[3];
  for (int c = 0; c < 3; ++c) tv[c] = L::load(t[c]), bv[c] = L::load(b[c]), nv[c] = L::load(n[c]);
  const RgbaFaces faces(previous);
  f32 sum[3] = {f32(0.0f), f32(0.0f), f32(0.0f)};
  for (int k = 0; k < count; ++k) {
    f32 d[3], texel[3];
    for (int c = 0; c < 3; ++c) d[c] = (local[k].x * tv[c] + local[k].y * bv[c]) + local[k].z * nv[c];
    lookup_level8(faces, d, texel);
    for (int c = 0; c < 3; ++c) sum[c] += texel[c];
  }
  for (int j = 0; j < 8; ++j) out[j] = glm::vec3(sum[0][j], sum[1][j], sum[2][j]);
}

// The 9 real SH basis functions (bands 0..2) at the unit direction (x, y, z); T is float or
// a lane type (the same operations per lane).
template <class T>
std::array<T, 9> sh_basis(const T& x, const T& y, const T& z) {
  return {T(0.282095f),      0.488603f * y,       0.488603f * z,
          0.488603f * x,     1.092548f * x * y,   1.092548f * y * z,
          0.315392f * (3.0f * z * z - 1.0f), 1.092548f * x * z, 0.546274f * (x * x - y * y)};
}

// The clamped cosine's SH convolution weights per coefficient: A0 = π, A1 = 2π/3, A2 = π/4.
constexpr float kCosineLobeSh[9] = {kPi, 2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4,
                                    kPi / 4, kPi / 4, kPi / 4, kPi / 4};

}  // namespace

EnvironmentMap build_environment(par::Executor& executor, const Environment& env, int size) {
  if (size <= 0)
    size = env.has_image() ? std::clamp(env.equirect.width / 4, 16, 512) : 8;
  EnvironmentMap map;
  map.size = size;
  const int levels = static_cast<int>(std::log2(static_cast<float>(size))) + 1;
  map.levels.resize(levels);
  // Level 0: 2×2 supersampled resampling of the environment.
  for (int face = 0; face < kCubeFaces; ++face) {
    ImageRGBA& img = map.levels[0][face];
    img = ImageRGBA(size, size);
    executor.parallel_for("environment.resample", img.size(), 1024,
                          [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        const int x = int(i % size), y = int(i / size);
        glm::vec3 sum(0.0f);
        for (int sy = 0; sy < 2; ++sy)
          for (int sx = 0; sx < 2; ++sx)
            sum += environment_radiance(
                env, cube_direction(face, {x + 0.25f + 0.5f * sx, y + 0.25f + 0.5f * sy}, size));
        img.pixels[i] = glm::vec4(sum * 0.25f, 1.0f);
      }
    });
  }
  return environment_from_faces(executor, std::move(map.levels[0]), true);
}

EnvironmentMap environment_from_faces(par::Executor& executor,
                                      std::array<ImageRGBA, kCubeFaces> faces, bool with_sh,
                                      int level_count, unsigned face_mask, const CubeTileMask* tiles,
                                      const PrefilterReuse* reuse) {
  EnvironmentMap map;
  const int size = faces[0].width;
  map.size = size;
  const int all = static_cast<int>(std::log2(static_cast<float>(size))) + 1;
  const int levels = level_count > 0 ? std::min(level_count, all) : all;
  map.levels.resize(levels);
  map.levels[0] = std::move(faces);
  // Coarser levels: glossy prefiltering of the previous level.
  for (int l = 1; l < levels; ++l) {
    const int s = std::max(1, size >> l);
    const float step_exponent = step_lobe_exponent(size, l);
    // The lobe's sample directions in the lobe's own frame are the same for every texel.
    std::array<glm::vec3, kPrefilterSamples> local;
    for (int k = 0; k < kPrefilterSamples; ++k)
      local[k] = sample_phong_lobe(hamersley(std::uint32_t(k), kPrefilterSamples), step_exponent);
    for (int face = 0; face < kCubeFaces; ++face) {
      ImageRGBA& img = map.levels[l][face];
      img = ImageRGBA(s, s);
      if (!((face_mask >> face) & 1u)) continue;
      // The texels `reuse` gives: prefiltered there (its faces and tiles), no input changed.
      const ImageRGBA* before = reuse && ((reuse->faces >> face) & 1u) && static_cast<std::size_t>(l) < reuse->from->levels.size() &&
                                        static_cast<std::size_t>(l) < reuse->changed.size()
                                    ? &reuse->from->levels[l][face]
                                    : nullptr;
      executor.parallel_for("environment.prefilter", img.size(), 256,
                            [&](std::size_t begin, std::size_t end) {
        const auto wanted = [&](std::size_t i) {
          return !tiles || tiles->covers(face, l, static_cast<int>(i % s), static_cast<int>(i / s));
        };
        const auto taken = [&](std::size_t i) {
          const int x = static_cast<int>(i % s), y = static_cast<int>(i / s);
          return before && (!reuse->tiles || reuse->tiles->covers(face, l, x, y)) && !reuse->changed[l].covers(face, l, x, y);
        };
        std::size_t i = begin;
        glm::vec3 sums[8];
        for (; i + 8 <= end; i += 8) {
          unsigned from_before = 0, computed = 0;
          for (std::size_t j = 0; j < 8; ++j)
            if (wanted(i + j)) (taken(i + j) ? from_before : computed) |= 1u << j;
          if (computed) prefilter_texels8(map.levels[l - 1], face, s, i, local.data(), kPrefilterSamples, sums);
          for (std::size_t j = 0; j < 8; ++j) {
            if ((from_before >> j) & 1u) img.pixels[i + j] = before->pixels[i + j];
            else if ((computed >> j) & 1u) img.pixels[i + j] = glm::vec4(sums[j] / float(kPrefilterSamples), 1.0f);
          }
        }
        for (; i < end; ++i) {
          if (!wanted(i)) continue;
          img.pixels[i] = taken(i) ? before->pixels[i]
                                   : glm::vec4(prefilter_texel(map.levels[l - 1], face, s, i, local.data(), kPrefilterSamples) /
                                                   float(kPrefilterSamples),
                                               1.0f);
        }
      });
    }
  }
  if (!with_sh) return map;
  // SH projection of level 0, serial in texel order (a fixed-order sum).
  std::array<glm::dvec3, 9> acc{};
  for (int face = 0; face < kCubeFaces; ++face)
    for (int y = 0; y < size; ++y)
      for (int x = 0; x < size; ++x) {
        const float u = 2.0f * (x + 0.5f) / size - 1.0f, v = 2.0f * (y + 0.5f) / size - 1.0f;
        const double solid_angle =
            (4.0 / (double(size) * size)) / std::pow(1.0 + u * u + v * v, 1.5);
        const glm::vec3 d = cube_direction(face, {x + 0.5f, y + 0.5f}, size);
        const auto basis = sh_basis(d.x, d.y, d.z);
        const glm::dvec3 L(glm::vec3(map.levels[0][face].at(x, y)));
        for (int k = 0; k < 9; ++k) acc[k] += L * (double(basis[k]) * solid_angle);
      }
  for (int k = 0; k < 9; ++k) map.sh[k] = glm::vec3(acc[k]);
  return map;
}

namespace {

// The fractional mip level radiance() reads for a lobe of exponent n (before clamping to
// the levels a map has).
float lobe_level(int size, float phong_exponent) {
  if (phong_exponent >= 1e6f) return 0.0f;
  return std::max(std::log2(lobe_angle(phong_exponent) / texel_angle(size)), 0.0f);
}

// The fractional level radiance() reads on `map` for a lobe of exponent n (clamped to the
// levels it has).
float read_level(const EnvironmentMap& map, float phong_exponent) {
  return std::min(lobe_level(map.size, phong_exponent), float(static_cast<int>(map.levels.size()) - 1));
}

}  // namespace

int levels_for_lobes(int size, float min_phong_exponent) {
  const int all = static_cast<int>(std::log2(static_cast<float>(size))) + 1;
  if (!(min_phong_exponent > 0.0f)) return all;
  // radiance() reads level floor(l), and floor(l) + 1 when l has a fraction, for the widest
  // lobe's level l; the log2 is monotone in the exponent, so narrower lobes read no coarser
  // level.
  const float level = lobe_level(size, min_phong_exponent);
  if (!(level < float(all))) return all;
  const int whole = static_cast<int>(level);
  return std::min(all, whole + (level > float(whole) ? 2 : 1));
}

float lookup_reach(int size, int level_count, float phong_exponent) {
  const int last = std::max(level_count, 1) - 1;
  const int read = std::min(last, static_cast<int>(lobe_level(size, phong_exponent)) + 1);
  // Within a face the bilinear taps are under a texel's diagonal away: 2√2 / side radians
  // bounds it (a texel is 2/side wide on the unit-distance face plane).
  const auto texel_reach = [&](int l) { return 2.0f * 1.4142136f / static_cast<float>(std::max(1, size >> l)); };
  float reach = texel_reach(read);
  for (int l = 1; l <= read; ++l) reach += widest_step_sample(size, l) + texel_reach(l - 1);  // the cascade's steps
  return reach;
}

float prefilter_reach(int size, int level) {
  // A sample's bilinear taps: within 1.5 texels of its point along each axis of the face
  // plane (clamped taps at the face's edge), 2/side per texel there, so 3√2 / side radians.
  return widest_step_sample(size, level) + 3.0f * 1.4142136f / static_cast<float>(std::max(1, size >> (level - 1)));
}

glm::vec3 EnvironmentMap::radiance(const glm::vec3& d, float phong_exponent) const {
  const int last = static_cast<int>(levels.size()) - 1;
  const float level = read_level(*this, phong_exponent);
  const int l0 = static_cast<int>(level), l1 = std::min(l0 + 1, last);
  const float t = level - l0;
  const glm::vec3 a = lookup_level(levels[l0], d);
  return t > 0.0f ? a * (1.0f - t) + lookup_level(levels[l1], d) * t : a;
}

void EnvironmentMap::radiance8(const glm::vec3* d, const float* phong_exponent, int count, glm::vec3* out) const {
  using L = par::Lanes<8>;
  using f32 = L::f32;
  const int last = static_cast<int>(levels.size()) - 1;
  // radiance's level per lane; a run of equal exponents (one material) computes it once.
  alignas(32) float level[8];
  for (int j = 0; j < 8; ++j) {
    const int k = j < count ? j : 0;  // lanes past `count` repeat lane 0, dropped below
    level[j] = k > 0 && phong_exponent[k] == phong_exponent[k - 1]
                   ? level[k - 1]
                   : read_level(*this, phong_exponent[k]);
  }
  // The lanes grouped by the first level they read (usually one group): each group's
  // lookups in lanes, the other lanes repeating the group's first direction (dropped).
  unsigned todo = (1u << count) - 1u;
  while (todo) {
    const int first = std::countr_zero(todo);
    const int l0 = static_cast<int>(level[first]);
    unsigned group = 0;
    for (int j = first; j < count; ++j)
      if (((todo >> j) & 1u) && static_cast<int>(level[j]) == l0) group |= 1u << j;
    todo &= ~group;
    alignas(32) float dir[3][8], from_l0[8];
    for (int j = 0; j < 8; ++j) {
      const int k = (group >> j) & 1u ? j : first;
      for (int c = 0; c < 3; ++c) dir[c][j] = d[k][c];
      from_l0[j] = level[k] - float(l0);
    }
    f32 dv[3];
    for (int c = 0; c < 3; ++c) dv[c] = L::load_aligned(dir[c]);
    f32 a[3];
    lookup_level8(RgbaFaces(levels[l0]), dv, a);
    const f32 t = L::load_aligned(from_l0);
    const L::mask blend = t > 0.0f;
    if (L::any(blend)) {
      f32 b[3];
      lookup_level8(RgbaFaces(levels[std::min(l0 + 1, last)]), dv, b);
      for (int c = 0; c < 3; ++c) a[c] = L::select(blend, a[c] * (1.0f - t) + b[c] * t, a[c]);
    }
    for (int j = first; j < count; ++j)
      if ((group >> j) & 1u) out[j] = glm::vec3(a[0][j], a[1][j], a[2][j]);
  }
}

glm::vec3 EnvironmentMap::irradiance(const glm::vec3& n) const {
  const auto basis = sh_basis(n.x, n.y, n.z);
  glm::vec3 e(0.0f);
  for (int k = 0; k < 9; ++k) e += sh[k] * (kCosineLobeSh[k] * basis[k]);
  return glm::max(e, glm::vec3(0.0f));
}

Vec3Lanes<8> EnvironmentMap::irradiance8(const Vec3Lanes<8>& n) const {
  using L = par::Lanes<8>;
  const auto basis = sh_basis(n.x, n.y, n.z);
  const L::f32 zero(0.0f);
  Vec3Lanes<8> e(zero, zero, zero);
  for (int k = 0; k < 9; ++k) e = e + Vec3Lanes<8>(sh[k]) * (kCosineLobeSh[k] * basis[k]);
  return {L::max(e.x, zero), L::max(e.y, zero), L::max(e.z, zero)};
}

EnvironmentMap EnvironmentPass::operator()(par::NodeContext& c) const {
  return build_environment(c.executor(), scene->environment, size);
}

}  // namespace speculum::raster
