// The `gbuffer` node: see gbuffer.h. Normal mapping is core's (core/normal_mapping.h, the
// glTF convention), the same as the ray tracers' hit shading.
#include "raster/gbuffer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <immintrin.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>

#include "core/error.h"
#include "core/normal_mapping.h"
#include "raster/frame_plane.h"
#include "raster/gbuffer_normals.h"
#include "raster/gbuffer_stream.h"
#include "raster/transpose8.h"

namespace speculum::raster {
namespace {

constexpr std::size_t kPixelChunk = 4096;

// Samples resolved per staging block: 64 makes every plane's share of a block a whole
// number of cache lines (4, 8, 12 and 44 bytes per sample).
constexpr std::size_t kBlock = 64;
// Frames at least this large (≈ 22 MB of G-buffer) are written with streaming stores: they
// cannot stay cached until a consumer reads them anyway. Smaller ones (cube-map faces) stay
// in cache for the next node.
constexpr std::size_t kStreamingMinSamples = std::size_t(1) << 18;
// How many samples ahead the triangle data of a sample is prefetched: enough to cover a
// DRAM miss at a few ns per sample.
constexpr std::size_t kPrefetchAhead = 24;

// What a sample needs of its material, looked up once per frame.
struct MaterialInfo {
  SurfaceParams constant;      // the parameters of untextured materials
  bool textured = false;       // parameters vary with uv: evaluate per sample
  bool normal_mapped = false;
  bool simple = false;         // neither: constant parameters, normals take the 8-wide path
  // A base colour texture and no other texture or normal map: the normal, its side and
  // is_specular are those of the constant parameters, so the normal takes the 8-wide path,
  // and only the base colour is looked up per sample (after the block's other work, see
  // PendingColour).
  bool colour_textured = false;
  std::uint32_t keep_side = 0; // all ones for refractors (see resolve_sample)
  bool specular = false;       // is_specular(constant)
};

// Per material, for the 8-lane path: one word gathered by material index whose bits say
// simple, keep_side (refractor), specular and colour_textured.
constexpr std::uint32_t kLaneSimple = 1, kLaneKeepSide = 2, kLaneSpecular = 4, kLaneColourTextured = 8;

struct SampleContext {
  const Scene& scene;
  const TriangleMesh& m;
  const VisibilityBuffer& vis;
  const glm::vec3& eye;
  const std::vector<MaterialInfo>& materials;
  const std::vector<std::uint32_t>& material_flags;  // kLane* bits per material
  SurfaceParams* own_surface;  // the surface plane's own entries (textured samples), or null
};

// One block's slots in the planes' staging buffers (see PlaneWriters).
struct StagingBlock {
  std::uint32_t* object;
  glm::vec3* position;
  glm::vec3* normal;
  glm::vec2* uv;
  std::uint32_t* surface;  // slots of the surface plane (core/surface_plane.h)
  std::uint32_t* reflector;
};

// Samples are written through a writer per plane that streams whole cache lines.
template <class T>
using PlaneWriter = detail::LineWriter<kBlock * sizeof(T)>;

template <class T>
T* slots(PlaneWriter<T>& w) {
  static_assert(alignof(T) <= 4);  // the staging phase is a multiple of 4 bytes
  return reinterpret_cast<T*>(w.next());
}

struct PlaneWriters {
  PlaneWriter<std::uint32_t> object, reflector, surface;
  PlaneWriter<glm::vec3> position, normal;
  PlaneWriter<glm::vec2> uv;

  PlaneWriters(GBuffer& g, std::size_t begin, bool stream)
      : object(g.object.pixels.data() + begin, stream),
        reflector(g.reflector.pixels.data() + begin, stream),
        surface(g.surface.slot.pixels.data() + begin, stream),
        position(g.position.pixels.data() + begin, stream),
        normal(g.normal.pixels.data() + begin, stream),
        uv(g.uv.pixels.data() + begin, stream) {}

  StagingBlock block() {
    return {slots<std::uint32_t>(object), slots<glm::vec3>(position), slots<glm::vec3>(normal),
            slots<glm::vec2>(uv),         slots<std::uint32_t>(surface), slots<std::uint32_t>(reflector)};
  }
  void commit(std::size_t n) {
    object.commit(n * sizeof(std::uint32_t));
    position.commit(n * sizeof(glm::vec3));
    normal.commit(n * sizeof(glm::vec3));
    uv.commit(n * sizeof(glm::vec2));
    surface.commit(n * sizeof(std::uint32_t));
    reflector.commit(n * sizeof(std::uint32_t));
  }
  void finish() {
    object.finish();
    position.finish();
    normal.finish();
    uv.finish();
    surface.finish();
    reflector.finish();
  }
};

// Triangle data straight from the mesh arrays (no prepared records).
struct MeshCorners {
  const TriangleMesh& m;
  TriangleRecord operator()(std::uint32_t t) const { return triangle_record(m, t); }
  std::uint32_t material(std::uint32_t t) const { return m.triangle_material[t]; }
  // Two stages: the indices first, the corners once the indices have arrived.
  void prefetch_indices(std::uint32_t t) const {
    _mm_prefetch(reinterpret_cast<const char*>(m.indices.data() + 3 * std::size_t(t)), _MM_HINT_T0);
  }
  void prefetch(std::uint32_t t) const {
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t v = m.indices[3 * std::size_t(t) + k];
      _mm_prefetch(reinterpret_cast<const char*>(m.positions.data() + v), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(m.normals.data() + v), _MM_HINT_T0);
      _mm_prefetch(reinterpret_cast<const char*>(m.uvs.data() + v), _MM_HINT_T0);
    }
    _mm_prefetch(reinterpret_cast<const char*>(m.triangle_material.data() + t), _MM_HINT_T0);
  }
};

// Triangle data from the scene-static records (gbuffer_triangles.h).
struct RecordCorners {
  const TriangleRecord* records;
  const std::uint32_t* materials;
  const TriangleRecord& operator()(std::uint32_t t) const { return records[t]; }
  std::uint32_t material(std::uint32_t t) const { return materials[t]; }
  void prefetch_indices(std::uint32_t) const {}  // a record needs no indices
  void prefetch(std::uint32_t t) const {
    // 96 bytes at a multiple of 32: the lines of its first and its 65th byte.
    const char* p = reinterpret_cast<const char*>(records + t);
    _mm_prefetch(p, _MM_HINT_T0);
    _mm_prefetch(p + 64, _MM_HINT_T0);
    _mm_prefetch(reinterpret_cast<const char*>(materials + t), _MM_HINT_T0);
  }
};

// The unit normal of the triangle's plane (corner order): for a degenerate interpolated normal.
glm::vec3 face_normal(const TriangleRecord& r) {
  const glm::vec3 a = r.corner[0].position;
  return glm::normalize(glm::cross(r.corner[1].position - a, r.corner[2].position - a));
}

// TEXCOORD_1 of triangle t at barycentrics (1 − b.x − b.y, b.x, b.y), from the mesh (the
// records carry TEXCOORD_0 only); 0 when the mesh has none.
glm::vec2 second_uv(const TriangleMesh& m, std::uint32_t t, glm::vec2 b) {
  if (m.uvs1.empty()) return glm::vec2(0.0f);
  const float b0 = 1.0f - b.x - b.y;
  const std::uint32_t i0 = m.indices[3 * t], i1 = m.indices[3 * t + 1], i2 = m.indices[3 * t + 2];
  return b0 * m.uvs1[i0] + b.x * m.uvs1[i1] + b.y * m.uvs1[i2];
}

// Resolves covered visibility sample i of triangle t (corners r) into slot j of the block.
inline void resolve_sample(const SampleContext& c, std::size_t i, std::uint32_t t,
                           const TriangleRecord& r, std::uint32_t mat, const StagingBlock& out,
                           std::size_t j) {
  const std::uint32_t object = c.vis.object.pixels[i];
  const glm::vec2 b = c.vis.bary.pixels[i];
  const float b0 = 1.0f - b.x - b.y;
  const glm::vec3 p = r.lerp(&TriangleCorner::position, b0, b);
  glm::vec3 n = r.lerp(&TriangleCorner::normal, b0, b);
  const float nl = glm::length(n);
  if (nl > 1e-12f) {
    n = n / nl;
  } else {  // degenerate interpolated normal: fall back to the face normal
    n = face_normal(r);
  }
  const glm::vec2 uv = r.lerp(&TriangleCorner::uv, b0, b);
  const MaterialInfo& info = c.materials[mat];
  SurfaceParams sp;
  const glm::vec3 unmapped = n;  // decides the side (below); the map tilts within it
  if (info.textured || info.normal_mapped) {  // rare: the extra vertex streams come from the mesh
    const TriangleMesh& m = c.m;
    const glm::vec2 uv1 = second_uv(m, t, b);
    if (info.normal_mapped) {
      const Material& material = c.scene.materials[mat];
      n = normal_mapped(c.scene, material, n,
                        surface_tangent(m, t, b.x, b.y, n, material.normal_texture.texcoord), uv, uv1);
    }
    sp = info.textured ? surface_params(c.scene, mat, uv, uv1) : info.constant;
  } else {
    sp = info.constant;
  }
  if (info.textured) {
    c.own_surface[i] = sp;
    out.surface[j] = SurfacePlane::kOwn;
  } else {
    out.surface[j] = mat;  // the shared entry of an untextured material is its index
  }
  // Opaque surfaces are shaded on the side the camera sees (double-sided or not, a visible
  // back face would otherwise shade black); refractors keep their orientation so the
  // reflection node knows whether the ray enters or leaves. Only the sign of N·V matters,
  // so V is not normalized. The side is the unperturbed normal's: a normal map tilting the
  // normal past the horizon would otherwise be mirrored into the surface.
  if (!sp.is_refractor() && glm::dot(unmapped, c.eye - p) < 0.0f) n = -n;
  out.object[j] = object;
  out.position[j] = p;
  out.normal[j] = n;
  out.uv[j] = uv;
  out.reflector[j] = is_specular(sp) ? object : kNoId;
}

// A block's base-colour-textured samples (MaterialInfo::colour_textured): their texels are
// looked up where the sample is interpolated, and fetched while the block's other samples
// are, then read (finish) once the block is done, so that no sample waits alone on its
// texture's cache misses. Each sample's parameters are those of resolve_sample bit for bit:
// the constant ones with the base colour times the texture's value.
class PendingColour {
 public:
  void add(std::size_t i, std::uint32_t mat, const BilinearTaps& taps) { entries_[count_++] = {i, mat, taps}; }
  void finish(const SampleContext& c) {
    for (std::size_t k = 0; k < count_; ++k) {
      const Entry& e = entries_[k];
      SurfaceParams s = c.materials[e.mat].constant;
      s.base_color *= glm::vec3(e.taps.value());
      c.own_surface[e.i] = s;
    }
    count_ = 0;
  }

 private:
  struct Entry {
    std::size_t i;
    std::uint32_t mat;
    BilinearTaps taps;
  };
  Entry entries_[kBlock];
  std::size_t count_ = 0;
};

// The interpolation half of resolve_sample for a simple or colour-textured material (no
// normal map, the side and is_specular of its constant parameters): the normal step runs
// later over the block's lanes.
inline void interpolate_sample(const SampleContext& c, std::size_t i, std::uint32_t t, const TriangleRecord& r,
                               std::uint32_t mat, const StagingBlock& out,
                               detail::NormalLanes<kBlock>& lanes, std::size_t j, PendingColour& pending) {
  const MaterialInfo& info = c.materials[mat];
  const std::uint32_t object = c.vis.object.pixels[i];
  const glm::vec2 b = c.vis.bary.pixels[i];
  const float b0 = 1.0f - b.x - b.y;
  const glm::vec3 p = r.lerp(&TriangleCorner::position, b0, b);
  const glm::vec3 n = r.lerp(&TriangleCorner::normal, b0, b);
  lanes.nx[j] = n.x, lanes.ny[j] = n.y, lanes.nz[j] = n.z;
  lanes.px[j] = p.x, lanes.py[j] = p.y, lanes.pz[j] = p.z;
  lanes.keep_side[j] = info.keep_side;
  out.object[j] = object;
  out.position[j] = p;
  const glm::vec2 uv = r.lerp(&TriangleCorner::uv, b0, b);
  out.uv[j] = uv;
  if (info.colour_textured) {  // its texels are asked for now and read after the block
    const BilinearTaps taps =
        texture_taps(c.scene, c.scene.materials[mat].base_color_texture, uv, second_uv(c.m, t, b));
    taps.prefetch();
    pending.add(i, mat, taps);
    out.surface[j] = SurfacePlane::kOwn;
  } else {
    out.surface[j] = mat;  // the shared entry of an untextured material is its index
  }
  out.reflector[j] = info.specular ? object : kNoId;
}

// Stores 8 vec3 given as x, y, z lanes to dst[0..7] (array of structures).
inline void store_vec3x8(glm::vec3* dst, __m256 x, __m256 y, __m256 z) {
  float* d = &dst[0].x;
  for (int h = 0; h < 2; ++h) {
    __m128 r0 = h ? _mm256_extractf128_ps(x, 1) : _mm256_castps256_ps128(x);
    __m128 r1 = h ? _mm256_extractf128_ps(y, 1) : _mm256_castps256_ps128(y);
    __m128 r2 = h ? _mm256_extractf128_ps(z, 1) : _mm256_castps256_ps128(z);
    __m128 r3 = _mm_setzero_ps();
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);  // r_k = (x_k, y_k, z_k, 0)
    float* o = d + 12 * h;
    _mm_storeu_ps(o, r0);  // each 16-byte store's last float is overwritten by the next
    _mm_storeu_ps(o + 3, r1);
    _mm_storeu_ps(o + 6, r2);
    _mm_storel_pi(reinterpret_cast<__m64*>(o + 9), r3);
    _mm_store_ss(o + 11, _mm_movehl_ps(r3, r3));
  }
}

// interpolate_sample for 8 covered samples i .. i+7 of simple or colour-textured materials
// at once, each sample's attributes interpolated from its record's corners in one register:
// the same IEEE operations per component in the same order (b0 = (1 − b1) − b2, then
// (b0·a0 + b1·a1) + b2·a2), so the same bytes; the colour-textured samples' texels are asked
// for from the interpolated uv, as there. Returns kGroupSkipped, writing nothing, if a sample
// is background or neither kind; kGroupNormalsPending when a normal is degenerate (the
// normals are then left in `lanes` for the block's normal step).
enum GroupResult { kGroupSkipped, kGroupDone, kGroupNormalsPending };
inline GroupResult interpolate_group8(const SampleContext& c, const TriangleRecord* records,
                               const std::uint32_t* materials, std::size_t i,
                               const StagingBlock& out, detail::NormalLanes<kBlock>& lanes,
                               std::size_t j, PendingColour& pending) {
  static_assert(sizeof(TriangleRecord) == 24 * sizeof(float) && alignof(TriangleRecord) == 32 &&
                    offsetof(TriangleCorner, normal) == 12 && offsetof(TriangleCorner, uv) == 24,
                "the loads below read each corner as one register of 8 floats");
  const __m256i tri = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&c.vis.triangle.pixels[i]));
  const __m256i none = _mm256_set1_epi32(static_cast<int>(kNoId));
  if (!_mm256_testz_si256(_mm256_cmpeq_epi32(tri, none), _mm256_cmpeq_epi32(tri, none))) return kGroupSkipped;
  alignas(32) std::uint32_t triangle[8], material[8];
  _mm256_store_si256(reinterpret_cast<__m256i*>(triangle), tri);
  for (int k = 0; k < 8; ++k) material[k] = materials[triangle[k]];
  const __m256i mat = _mm256_load_si256(reinterpret_cast<const __m256i*>(material));
  // Eight samples of one material (most groups) read its flags once.
  const bool one_material = _mm256_movemask_epi8(_mm256_cmpeq_epi32(mat, _mm256_set1_epi32(static_cast<int>(material[0])))) == -1;
  const __m256i flags =
      one_material ? _mm256_set1_epi32(static_cast<int>(c.material_flags[material[0]]))
                   : _mm256_i32gather_epi32(reinterpret_cast<const int*>(c.material_flags.data()), mat, 4);
  auto has = [&](std::uint32_t bit) {
    const __m256i b = _mm256_set1_epi32(static_cast<int>(bit));
    return _mm256_cmpeq_epi32(_mm256_and_si256(flags, b), b);
  };
  const __m256i colour_textured = has(kLaneColourTextured);
  if (_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_or_si256(has(kLaneSimple), colour_textured))) != 0xff)
    return kGroupSkipped;
  const __m256i keep = has(kLaneKeepSide), specular = has(kLaneSpecular);
  // Barycentrics (b1, b2) of 8 samples, de-interleaved.
  const float* bary = &c.vis.bary.pixels[i].x;
  const __m256 lo = _mm256_loadu_ps(bary), hi = _mm256_loadu_ps(bary + 8);
  const __m256 b1 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0x88)), 0xd8));
  const __m256 b2 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0xdd)), 0xd8));
  const __m256 b0 = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), b1), b2);
  // Each sample's attributes (position, normal, uv: a corner's eight floats) interpolated in
  // one register from its record's three corners, then transposed to one register per
  // component.
  alignas(32) float w0[8], w1[8], w2[8];
  _mm256_store_ps(w0, b0), _mm256_store_ps(w1, b1), _mm256_store_ps(w2, b2);
  __m256 sample[8], component[8];
  for (int k = 0; k < 8; ++k) {
    const float* corner = &records[triangle[k]].corner[0].position.x;
    sample[k] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_broadcast_ss(w0 + k), _mm256_load_ps(corner)),
                                            _mm256_mul_ps(_mm256_broadcast_ss(w1 + k), _mm256_load_ps(corner + 8))),
                              _mm256_mul_ps(_mm256_broadcast_ss(w2 + k), _mm256_load_ps(corner + 16)));
  }
  detail::transpose8(sample, component);
  const __m256 px = component[0], py = component[1], pz = component[2];
  const __m256 nx = component[3], ny = component[4], nz = component[5];
  const __m256 u = component[6], v = component[7];
  // The normal step of normalize_and_face_eye in the same registers: the same operations.
  const __m256 len = _mm256_sqrt_ps(_mm256_add_ps(
      _mm256_add_ps(_mm256_mul_ps(nx, nx), _mm256_mul_ps(ny, ny)), _mm256_mul_ps(nz, nz)));
  const bool all_valid =
      _mm256_movemask_ps(_mm256_cmp_ps(len, _mm256_set1_ps(1e-12f), _CMP_GT_OQ)) == 0xff;
  if (all_valid) {
    const __m256 x = _mm256_div_ps(nx, len), y = _mm256_div_ps(ny, len), z = _mm256_div_ps(nz, len);
    const __m256 facing = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(x, _mm256_sub_ps(_mm256_set1_ps(c.eye.x), px)),
                      _mm256_mul_ps(y, _mm256_sub_ps(_mm256_set1_ps(c.eye.y), py))),
        _mm256_mul_ps(z, _mm256_sub_ps(_mm256_set1_ps(c.eye.z), pz)));
    const __m256 flip = _mm256_and_ps(
        _mm256_andnot_ps(_mm256_castsi256_ps(keep),
                         _mm256_cmp_ps(facing, _mm256_setzero_ps(), _CMP_LT_OQ)),
        _mm256_castsi256_ps(_mm256_set1_epi32(static_cast<int>(0x80000000u))));
    store_vec3x8(out.normal + j, _mm256_xor_ps(x, flip), _mm256_xor_ps(y, flip),
                 _mm256_xor_ps(z, flip));
  } else {  // a degenerate normal: the block's normal step and face-normal fallback
    _mm256_storeu_ps(lanes.nx + j, nx), _mm256_storeu_ps(lanes.ny + j, ny), _mm256_storeu_ps(lanes.nz + j, nz);
    _mm256_storeu_ps(lanes.px + j, px), _mm256_storeu_ps(lanes.py + j, py), _mm256_storeu_ps(lanes.pz + j, pz);
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(lanes.keep_side + j), keep);
  }
  const __m256i object = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&c.vis.object.pixels[i]));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.object + j), object);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.reflector + j),
                      _mm256_blendv_epi8(none, object, specular));
  store_vec3x8(out.position + j, px, py, pz);
  const __m256 uv_lo = _mm256_unpacklo_ps(u, v), uv_hi = _mm256_unpackhi_ps(u, v);
  float* uv = &out.uv[j].x;
  _mm256_storeu_ps(uv, _mm256_permute2f128_ps(uv_lo, uv_hi, 0x20));
  _mm256_storeu_ps(uv + 8, _mm256_permute2f128_ps(uv_lo, uv_hi, 0x31));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.surface + j), mat);  // simple: the shared entry
  // The colour-textured samples: their own entry, its base colour after the block (as in
  // interpolate_sample).
  for (int textured = _mm256_movemask_ps(_mm256_castsi256_ps(colour_textured)); textured != 0;
       textured &= textured - 1) {
    const int k = std::countr_zero(static_cast<unsigned>(textured));
    const std::size_t at = i + static_cast<std::size_t>(k);
    const std::uint32_t m = out.surface[j + k];
    const BilinearTaps taps = texture_taps(c.scene, c.scene.materials[m].base_color_texture, out.uv[j + k],
                                           second_uv(c.m, c.vis.triangle.pixels[at], c.vis.bary.pixels[at]));
    taps.prefetch();
    pending.add(at, m, taps);
    out.surface[j + k] = SurfacePlane::kOwn;
  }
  return all_valid ? kGroupDone : kGroupNormalsPending;
}

// Background samples get the ids and the planes' default values, so every byte of the
// G-buffer is defined (and the same for any thread count) whatever the buffer held before.
inline void resolve_background(const SampleContext& c, std::size_t i, const StagingBlock& out,
                               std::size_t j) {
  out.object[j] = c.vis.object.pixels[i];
  out.position[j] = glm::vec3(0.0f);
  out.normal[j] = glm::vec3(0.0f);
  out.uv[j] = glm::vec2(0.0f);
  out.surface[j] = static_cast<std::uint32_t>(c.materials.size());  // the background's entry
  out.reflector[j] = kNoId;
}

// resolve_background for 8 samples i .. i+7 at once when all eight are background (a cube
// face's texels outside the read tiles, the sky): true if it wrote them.
inline bool background_group8(const SampleContext& c, std::size_t i, const StagingBlock& out, std::size_t j) {
  const __m256i tri = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&c.vis.triangle.pixels[i]));
  const __m256i none = _mm256_set1_epi32(static_cast<int>(kNoId));
  if (_mm256_movemask_epi8(_mm256_cmpeq_epi32(tri, none)) != -1) return false;
  const __m256 zero = _mm256_setzero_ps();
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.object + j),
                      _mm256_loadu_si256(reinterpret_cast<const __m256i*>(&c.vis.object.pixels[i])));
  float* position = &out.position[j].x;
  float* normal = &out.normal[j].x;
  for (int k = 0; k < 24; k += 8) _mm256_storeu_ps(position + k, zero), _mm256_storeu_ps(normal + k, zero);
  _mm256_storeu_ps(&out.uv[j].x, zero), _mm256_storeu_ps(&out.uv[j].x + 8, zero);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.surface + j),
                      _mm256_set1_epi32(static_cast<int>(c.materials.size())));  // the background's entry
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.reflector + j), none);
  return true;
}

// Resolves samples [begin, end) block by block; `corners` fetches and prefetches triangles.
template <class Corners>
void resolve_range(const SampleContext& c, const Corners& corners, std::size_t begin,
                   std::size_t end, bool stream, GBuffer& g) {
  PlaneWriters writers(g, begin, stream);
  detail::NormalLanes<kBlock> lanes{};
  PendingColour pending;
  bool simple[kBlock];
  const std::uint32_t* tri = c.vis.triangle.pixels.data();
  const std::size_t total = c.vis.triangle.size();
  // Prefetch each run of samples on one triangle once: `near` samples ahead for the corner
  // data, twice as far for the indices the corner prefetch reads.
  auto prefetch_at = [&](std::size_t k) {
    if (k < total && tri[k] != kNoId && (k == begin || tri[k] != tri[k - 1])) corners.prefetch(tri[k]);
  };
  auto prefetch_indices_at = [&](std::size_t k) {
    if (k < total && tri[k] != kNoId && (k == begin || tri[k] != tri[k - 1]))
      corners.prefetch_indices(tri[k]);
  };
  for (std::size_t k = begin; k < begin + 2 * kPrefetchAhead; ++k) prefetch_indices_at(k);
  for (std::size_t k = begin; k < begin + kPrefetchAhead; ++k) prefetch_at(k);
  for (std::size_t b = begin; b < end; b += kBlock) {
    const std::size_t n = std::min(kBlock, end - b);
    const StagingBlock blk = writers.block();
    bool normals_pending = false;  // a sample left its normal to the block's normal step
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t i = b + j;
      if (j + 8 <= n && background_group8(c, i, blk, j)) {
        for (std::size_t k = i; k < i + 8; ++k) {
          prefetch_indices_at(k + 2 * kPrefetchAhead);
          prefetch_at(k + kPrefetchAhead);
        }
        std::fill(simple + j, simple + j + 8, false);  // their lanes are not read
        j += 7;
        continue;
      }
      if constexpr (std::is_same_v<Corners, RecordCorners>) {
        const GroupResult group =
            j + 8 <= n ? interpolate_group8(c, corners.records, corners.materials, i, blk, lanes, j, pending)
                       : kGroupSkipped;
        if (group != kGroupSkipped) {
          for (std::size_t k = i; k < i + 8; ++k) prefetch_at(k + kPrefetchAhead);
          const bool pending = group == kGroupNormalsPending;
          std::fill(simple + j, simple + j + 8, pending);
          normals_pending |= pending;
          j += 7;
          continue;
        }
      }
      prefetch_indices_at(i + 2 * kPrefetchAhead);
      prefetch_at(i + kPrefetchAhead);
      const std::uint32_t t = tri[i];
      simple[j] = false;
      lanes.nx[j] = lanes.ny[j] = lanes.nz[j] = lanes.px[j] = lanes.py[j] = lanes.pz[j] = 0.0f;
      lanes.keep_side[j] = 0;
      if (t == kNoId) {
        resolve_background(c, i, blk, j);
        continue;
      }
      decltype(auto) r = corners(t);
      const std::uint32_t mat = corners.material(t);
      const MaterialInfo& info = c.materials[mat];
      if (info.simple || info.colour_textured) {
        interpolate_sample(c, i, t, r, mat, blk, lanes, j, pending);
        simple[j] = true;
        normals_pending = true;
      } else {
        resolve_sample(c, i, t, r, mat, blk, j);
      }
    }
    pending.finish(c);
    if (!normals_pending) {
      writers.commit(n);
      continue;
    }
    // Lanes of samples already done hold zeros or an earlier sample's values: their results
    // are not read.
    for (std::size_t j = n; j < (n + 7) / 8 * 8; ++j) {  // tail lanes of a partial block
      lanes.nx[j] = lanes.ny[j] = lanes.nz[j] = lanes.px[j] = lanes.py[j] = lanes.pz[j] = 0.0f;
      lanes.keep_side[j] = 0;
    }
    detail::normalize_and_face_eye(lanes, n, c.eye);
    for (std::size_t j = 0; j < n; ++j) {
      if (!simple[j]) continue;
      if (lanes.valid[j]) {
        blk.normal[j] = glm::vec3(lanes.nx[j], lanes.ny[j], lanes.nz[j]);
      } else {  // degenerate interpolated normal: the face normal, turned as in resolve_sample
        glm::vec3 fn = face_normal(corners(tri[b + j]));
        if (!lanes.keep_side[j] && glm::dot(fn, c.eye - blk.position[j]) < 0.0f) fn = -fn;
        blk.normal[j] = fn;
      }
    }
    writers.commit(n);
  }
  writers.finish();
  detail::end_stores(stream);
}

void resolve(par::Executor& executor, const Scene& scene, const GBufferTriangles* records,
             const VisibilityBuffer& vis, const glm::vec3& eye, GBuffer& g) {
  const int w = vis.width, h = vis.height;
  g.width = w;
  g.height = h;
  ensure_plane_size(g.object, w, h);
  ensure_plane_size(g.position, w, h);
  ensure_plane_size(g.normal, w, h);
  g.eye = eye;
  ensure_plane_size(g.uv, w, h);
  ensure_plane_size(g.surface.slot, w, h);
  ensure_plane_size(g.reflector, w, h);
  const TriangleMesh& m = scene.mesh;
  // Untextured materials have the same parameters everywhere: evaluate them once. They are
  // the surface plane's shared entries (by material index, then the background's defaults);
  // only textured samples write their own.
  std::vector<MaterialInfo> materials;
  std::vector<std::uint32_t> material_flags;
  g.surface.shared.clear();
  bool any_textured = false;
  for (const Material& mat : scene.materials) {
    MaterialInfo info;
    info.constant = surface_params(mat);
    info.textured = mat.base_color_texture.valid() || mat.metallic_roughness_texture.valid() ||
                    mat.emissive_texture.valid() || mat.transmission_texture.valid();
    info.normal_mapped = mat.normal_texture.valid();
    info.simple = !info.textured && !info.normal_mapped;
    info.colour_textured = mat.base_color_texture.valid() && !mat.metallic_roughness_texture.valid() &&
                           !mat.emissive_texture.valid() && !mat.transmission_texture.valid() &&
                           !info.normal_mapped;
    info.keep_side = info.constant.is_refractor() ? ~0u : 0u;
    info.specular = is_specular(info.constant);
    any_textured |= info.textured;
    g.surface.shared.push_back(info.constant);
    materials.push_back(info);
    material_flags.push_back((info.simple ? kLaneSimple : 0u) | (info.colour_textured ? kLaneColourTextured : 0u) |
                                   (info.keep_side ? kLaneKeepSide : 0u) |
                                   (info.specular ? kLaneSpecular : 0u));
  }
  g.surface.shared.push_back(SurfaceParams{});
  if (any_textured) ensure_plane_size(g.surface.own, w, h);
  else g.surface.own = {};
  const SampleContext ctx{scene, m, vis, eye, materials, material_flags,
                          any_textured ? g.surface.own.pixels.data() : nullptr};
  const bool stream = vis.triangle.size() >= kStreamingMinSamples;
  if (records) {
    const RecordCorners corners{records->data(), records->materials()};
    executor.parallel_for("gbuffer.resolve", vis.triangle.size(), kPixelChunk,
                          [&](std::size_t begin, std::size_t end) {
      resolve_range(ctx, corners, begin, end, stream, g);
    });
  } else {
    const MeshCorners corners{m};
    executor.parallel_for("gbuffer.resolve", vis.triangle.size(), kPixelChunk,
                          [&](std::size_t begin, std::size_t end) {
      resolve_range(ctx, corners, begin, end, stream, g);
    });
  }
}

}  // namespace

GBuffer resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                        const glm::vec3& eye) {
  GBuffer g;
  resolve(executor, scene, nullptr, vis, eye, g);
  return g;
}

void resolve_gbuffer(par::Executor& executor, const Scene& scene, const VisibilityBuffer& vis,
                     const glm::vec3& eye, GBuffer& g) {
  resolve(executor, scene, nullptr, vis, eye, g);
}

void resolve_gbuffer(par::Executor& executor, const Scene& scene, const GBufferTriangles* triangles,
                     const VisibilityBuffer& vis, const glm::vec3& eye, GBuffer& g) {
  if (triangles && !triangles->matches(scene.mesh))
    throw InputError(scene.name, "G-buffer triangle records were built from another mesh");
  resolve(executor, scene, triangles, vis, eye, g);
}

void visible_distances(const TriangleMesh& m, const VisibilityBuffer& vis, const glm::vec3& from, std::size_t begin,
                       std::size_t end, float* out) {
  const std::uint32_t* tri = vis.triangle.pixels.data();
  const __m256i none = _mm256_set1_epi32(static_cast<int>(kNoId));
  std::size_t i = begin;
  for (; i + 8 <= end; i += 8) {
    const __m256i t = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(tri + i));
    const int covered = ~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(t, none))) & 0xff;
    if (!covered) continue;
    // The corners, component-major: c[3k + a] holds component a of corner k in each lane.
    // Runs of one triangle (most of a map's texels) load its corners once.
    alignas(32) float c[9][8];
    const __m256i same = _mm256_cmpeq_epi32(t, _mm256_set1_epi32(static_cast<int>(tri[i])));
    if (covered == 0xff && _mm256_movemask_epi8(same) == -1) {
      for (int k = 0; k < 3; ++k) {
        const glm::vec3& p = m.positions[m.indices[3 * std::size_t(tri[i]) + k]];
        for (int a = 0; a < 3; ++a) _mm256_store_ps(c[3 * k + a], _mm256_set1_ps(p[a]));
      }
    } else {
      for (int j = 0; j < 8; ++j) {
        const std::size_t ti = (covered >> j) & 1 ? tri[i + j] : tri[i + std::countr_zero(unsigned(covered))];
        for (int k = 0; k < 3; ++k) {
          const glm::vec3& p = m.positions[m.indices[3 * ti + k]];
          for (int a = 0; a < 3; ++a) c[3 * k + a][j] = p[a];
        }
      }
    }
    // (b1, b2) of the 8 samples, de-interleaved; b0 = (1 − b1) − b2.
    const float* bary = &vis.bary.pixels[i].x;
    const __m256 lo = _mm256_loadu_ps(bary), hi = _mm256_loadu_ps(bary + 8);
    const __m256 b1 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0x88)), 0xd8));
    const __m256 b2 = _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(lo, hi, 0xdd)), 0xd8));
    const __m256 b0 = _mm256_sub_ps(_mm256_sub_ps(_mm256_set1_ps(1.0f), b1), b2);
    __m256 d[3];
    for (int a = 0; a < 3; ++a) {
      // (b0·p0 + b1·p1) + b2·p2, then minus `from`: visible_position's order.
      const __m256 p = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(b0, _mm256_load_ps(c[a])),
                                                   _mm256_mul_ps(b1, _mm256_load_ps(c[3 + a]))),
                                     _mm256_mul_ps(b2, _mm256_load_ps(c[6 + a])));
      d[a] = _mm256_sub_ps(p, _mm256_set1_ps(from[a]));
    }
    // glm::length: the root of (x·x + y·y) + z·z.
    const __m256 len = _mm256_sqrt_ps(_mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(d[0], d[0]), _mm256_mul_ps(d[1], d[1])), _mm256_mul_ps(d[2], d[2])));
    const __m256i keep = _mm256_xor_si256(_mm256_cmpeq_epi32(t, none), _mm256_set1_epi32(-1));
    _mm256_maskstore_ps(out + (i - begin), keep, len);
  }
  for (; i < end; ++i)
    if (tri[i] != kNoId) out[i - begin] = glm::length(visible_position(m, vis, i) - from);
}

ImageF specular_level_image(const GBuffer& g) {
  ImageF out(g.width, g.height, 0.0f);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!g.covered(i) || !is_specular(g.surface[i])) continue;
    const glm::vec3 f0 = specular_f0(g.surface[i]);
    out.pixels[i] = std::max({f0.x, f0.y, f0.z});
  }
  return out;
}

ImageF glossiness_image(const GBuffer& g) {
  ImageF out(g.width, g.height, 0.0f);
  for (std::size_t i = 0; i < out.size(); ++i)
    if (g.covered(i)) out.pixels[i] = g.surface[i].phong_exponent;
  return out;
}

GBuffer GBufferPass::operator()(par::NodeContext& c, const VisibilityBuffer& visibility) const {
  // The records cost about one pass over the mesh and halve the resolve's time.
  FrameRecords records;
  GBuffer g;
  resolve_gbuffer(c.executor(), *scene, records.of(c.executor(), *scene), visibility, eye, g);
  return g;
}

}  // namespace speculum::raster
