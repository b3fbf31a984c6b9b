// A caustic photon map (Jensen's density estimation) over the arrivals of the light tracer
// (trace/light_tracer.h), for the caustics a camera path sees after a specular bounce: a
// caustic on the floor seen through water or in a mirror, which the light tracer's direct
// connection to the eye cannot reach. The k nearest photons (nanoflann's kd-tree, built
// serially, so queries are deterministic) within a radius cap give the reflected radiance
// Σ f Φ / (π r²), r the distance of the k-th. Consistent, not unbiased: it blurs a caustic
// over r, which falls as photons grow.
#pragma once

#include <memory>
#include <vector>

#include "core/shading.h"
#include "trace/light_tracer.h"

namespace speculum::trace {

class PhotonMap {
 public:
  static constexpr int kMaxNeighbours = 256;
  // `k` (1..kMaxNeighbours) nearest photons, at most `max_radius` away.
  PhotonMap(std::vector<PhotonHit> hits, int k, float max_radius);
  ~PhotonMap();
  PhotonMap(const PhotonMap&) = delete;
  PhotonMap& operator=(const PhotonMap&) = delete;

  // Radiance towards v (unit, to the viewer) of the caustic light at p on a surface with
  // unit normal n (facing the viewer) and material s.
  glm::vec3 radiance(const glm::vec3& p, const glm::vec3& n, const glm::vec3& v, const SurfaceParams& s) const;
  std::size_t size() const { return hits_.size(); }

 private:
  struct Index;
  std::vector<PhotonHit> hits_;
  int k_;
  float max_radius_;
  std::unique_ptr<Index> index_;
};

}  // namespace speculum::trace
