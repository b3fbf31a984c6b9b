// The passes that turn the raster G-buffer into trace/ ray streams: where raster/ and trace/
// meet, so they live in apps/ (raster/ and trace/ never include each other).
#pragma once

#include "raster/gbuffer.h"
#include "raster/visibility.h"
#include "trace/cone_tracing.h"
#include "trace/glossy_rays.h"
#include "trace/secondary_rays.h"

namespace speculum::pipeline {

// Pass "glossy_rays": N Phong-lobe rays per glossy pixel (YU §3.2, eq.4-5).
struct GlossyRaysPass {
  static constexpr const char* description =
      "N Phong-lobe rays per glossy pixel from a rotated Hamersley set, with their solid angles "
      "(YU §3.2, eq.4-5).";
  trace::GlossyRayOptions options;
  void parameters(par::Params& p) const { p.set("N", options.rays_per_pixel); }
  trace::GlossyRays operator()(par::NodeContext& c, const raster::GBuffer& gbuffer) const {
    trace::GlossyRays rays = trace::generate_glossy_rays(c.executor(), gbuffer.position, gbuffer.normal,
                                                         gbuffer.surface, gbuffer.object, gbuffer.eye,
                                                         options);
    c.count("glossy_pixels", rays.pixel.size());
    c.count("rays", rays.ray_count());
    c.count("below_horizon", rays.below_horizon);
    return rays;
  }
};

// Pass "secondary_rays": one reflected or refracted ray per specular pixel (ROGER §3.3.1).
struct SecondaryRaysPass {
  static constexpr const char* description =
      "One reflected or refracted ray per specular pixel (ROGER §3.3.1).";
  glm::vec3 eye{0.0f};
  trace::SecondaryRays operator()(par::NodeContext& c, const raster::GBuffer& gbuffer) const {
    trace::SecondaryRays rays = trace::secondary_rays(c.executor(), gbuffer.position, gbuffer.normal,
                                                      gbuffer.surface, gbuffer.object, eye);
    c.count("rays", rays.count);
    return rays;
  }
};

// Pass "pixel_cones": one cone per specular pixel (ROGER §5.2.2).
struct PixelConesPass {
  static constexpr const char* description =
      "One cone per specular pixel: the pixel's footprint reflected off a sphere of the pixel's "
      "mean curvature plus the material's glossy angle; double cones and refraction traced as "
      "rays (ROGER §5.2.2).";
  Camera camera;
  trace::PixelConeOptions options;
  void parameters(par::Params& p) const {
    p.set("footprint", options.footprint).set("gloss_angle", options.gloss_angle)
        .set("lobe_energy", options.lobe_energy).set("far_blur", options.far_blur);
  }
  trace::PixelCones operator()(par::NodeContext& c, const raster::GBuffer& gbuffer,
                               const raster::VisibilityBuffer& visibility, const ImageF& curvature) const {
    trace::PixelCones cones = trace::pixel_cones(c.executor(), gbuffer.position, gbuffer.normal, gbuffer.surface,
                                                 gbuffer.object, visibility.triangle, curvature, camera, options);
    c.count("rays", cones.axes.count);
    c.count("cones", cones.cones);
    c.count("fallback_double_cone", cones.ray_fallbacks);
    c.count("refraction_rays", cones.refraction_rays);
    c.count("horizon_clamped", cones.horizon_clamped);
    return cones;
  }
};

}  // namespace speculum::pipeline
