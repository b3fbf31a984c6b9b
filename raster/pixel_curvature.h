// The `pixel_curvature` node: the mean curvature of the visible surface at every sample,
// interpolated with the visibility buffer's barycentrics from the per-vertex cotangent mean
// curvature of the mesh (core/mesh_processing), as a G-buffer interpolates normals. ROGER
// §5.2.2 reflects each pixel's cone off a sphere of this curvature.
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"
#include "parallel/executor.h"
#include "parallel/graph_node.h"
#include "raster/visibility.h"

namespace speculum::raster {

// Per sample: H interpolated at the sample's triangle and barycentrics, signed as seen from
// the eye: positive where the surface bends away from the viewer (the outside of a sphere of
// radius r reads 1/r), negative in a bowl seen from inside. 0 on the background. `per_vertex`
// holds one value per soup vertex (mesh::scene_mean_curvature). Kernel "pixel_curvature".
ImageF pixel_mean_curvature(par::Executor& executor, const Scene& scene, const std::vector<float>& per_vertex,
                            const VisibilityBuffer& vis, const glm::vec3& eye);

// Pass "pixel_curvature": computes the per-vertex curvature of the scene once per run
// (OpenMesh, cotangent Laplace–Beltrami) and interpolates it per sample.
struct PixelCurvaturePass {
  static constexpr const char* description =
      "Mean curvature per sample, interpolated from the per-vertex cotangent mean curvature of "
      "the mesh (signed as seen from the eye; the sphere ROGER §5.2.2 reflects the pixel cone off).";
  const Scene* scene = nullptr;
  glm::vec3 eye{0.0f};
  ImageF operator()(par::NodeContext& c, const VisibilityBuffer& visibility) const;
};

}  // namespace speculum::raster
