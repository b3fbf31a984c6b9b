// The caustic photon map (see photon_map.h).
#include "trace/photon_map.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
// Equal distances: the lower photon index first (the photons' order is fixed).
#define NANOFLANN_FIRST_MATCH
#include <nanoflann.hpp>

#include "core/sampling.h"

namespace speculum::trace {

namespace {

// nanoflann's dataset adaptor over the photons' positions.
struct Cloud {
  const std::vector<PhotonHit>* hits = nullptr;
  std::size_t kdtree_get_point_count() const { return hits->size(); }
  float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*hits)[i].p[static_cast<int>(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const { return false; }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud, 3, std::uint32_t>;

}  // namespace

struct PhotonMap::Index {
  Cloud cloud;
  Tree tree;
  explicit Index(const std::vector<PhotonHit>* hits)
      : cloud{hits}, tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16)) {}
};

PhotonMap::PhotonMap(std::vector<PhotonHit> hits, int k, float max_radius)
    : hits_(std::move(hits)), k_(std::clamp(k, 1, kMaxNeighbours)), max_radius_(max_radius) {
  if (!hits_.empty()) index_ = std::make_unique<Index>(&hits_);
}

PhotonMap::~PhotonMap() = default;

glm::vec3 PhotonMap::radiance(const glm::vec3& p, const glm::vec3& n, const glm::vec3& v, const SurfaceParams& s) const {
  if (!index_) return glm::vec3(0.0f);
  std::array<std::uint32_t, kMaxNeighbours> idx{};
  std::array<float, kMaxNeighbours> d2{};
  const float q[3] = {p.x, p.y, p.z};
  // The k nearest within the cap (the result set's worst distance starts at the cap, so the
  // search prunes beyond it): a sparse neighbourhood would otherwise smear a caustic
  // across the scene, and searching it would cost most of the time.
  const float r2_cap = max_radius_ * max_radius_;
  nanoflann::KNNResultSet<float, std::uint32_t> result(static_cast<std::size_t>(k_));
  result.init(idx.data(), d2.data());
  d2[static_cast<std::size_t>(k_) - 1] = r2_cap;
  index_->tree.findNeighbors(result, q, nanoflann::SearchParams());
  const std::size_t found = result.size();
  if (found == 0) return glm::vec3(0.0f);
  const float r2 = found == static_cast<std::size_t>(k_) ? d2[found - 1] : r2_cap;
  if (!(r2 > 0.0f)) return glm::vec3(0.0f);
  glm::vec3 sum(0.0f);
  for (std::size_t j = 0; j < found; ++j) {
    if (d2[j] > r2) break;  // sorted by distance
    const PhotonHit& h = hits_[idx[j]];
    // Photons on this side of this surface only (a thin wall's other side, or a surface of
    // another orientation within the disc, is not this point's light).
    if (glm::dot(h.ng, n) < 0.5f) continue;
    const float cos_in = glm::dot(n, h.wi);
    if (cos_in <= 1e-4f) continue;
    LightSample ls;
    ls.direction = h.wi;
    ls.distance = 1.0f;
    ls.irradiance = h.flux / cos_in;  // shade_light returns f (N·L) E: f Φ
    sum += shade_light(s, n, v, ls);
  }
  return sum / (kPi * r2);
}

}  // namespace speculum::trace
