// Environments and lights a user picks on the command line (`--env sky|COLOR|FILE`,
// `--env-rotate`) and the default studio light a scene without any light gets. Every preset
// is an ordinary Scene::environment (an equirect image or a constant) or an ordinary Light,
// so every technique and the reference tracer use it unchanged. The formulas are in
// docs/techniques.md, "Lighting from the command line".
#pragma once

#include <glm/vec3.hpp>

#include "core/image.h"
#include "core/scene.h"

namespace speculum {

// True when the environment sends no light: zero intensity, a black constant, or an image
// with no positive pixel.
bool environment_is_black(const Environment& environment);

// True when the scene has no light and a black environment (emission lights nothing).
bool scene_is_unlit(const Scene& scene);

// A clear sky with a sun, baked into a width × height equirect image. Relative sky
// luminance is the CIE standard clear sky (CIE S 011/E:2003 type 12, Perez form:
// a = −1, b = −0.32, c = 10, d = −3, e = 0.45), scaled to zenith radiance 0.25, tinted from
// blue at the zenith to white at the horizon; the ground below the horizon is a constant
// 0.08; the sun is a disk of angular radius 1.5° whose radiance makes its irradiance at
// normal incidence exactly kSkySunIrradiance over the baked pixels.
inline constexpr float kSkySunIrradiance = 3.0f;
inline constexpr float kSkySunRadiusDegrees = 1.5f;
ImageRGBA clear_sky_equirect(int width, int height, const glm::vec3& toward_sun);
// The default sun direction of `--env sky` (elevation 40°, from +X+Z), before --env-rotate.
glm::vec3 default_sky_sun();

// The equirect environment turned by `degrees` about +Y (right-handed): the rotated map's
// radiance towards R_y(degrees)·d is the original's towards d. Bilinear along each row.
ImageRGBA rotate_equirect(const ImageRGBA& equirect, float degrees);

// The default studio light: a neutral environment L(d) = 0.5 + 0.3 d_y (0.8 overhead, 0.5 at
// the horizon, 0.2 from below) as a 64 × 32 equirect, plus a white directional key light of
// illuminance kStudioKeyIrradiance arriving from the camera's upper left and from behind
// it: towards the light = normalize(−0.5 right + 0.8 up + 0.6 back), with `up` the world +Y
// made orthogonal to the view (the camera's own up when it looks straight up or down).
inline constexpr float kStudioKeyIrradiance = 2.0f;
Environment studio_environment();
Light studio_key_light(const Camera& camera);
// Replaces the environment by the studio environment and adds the key light.
void add_studio_light(Scene& scene, const Camera& camera);

}  // namespace speculum
