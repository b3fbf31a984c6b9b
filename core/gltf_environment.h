// How speculum carries a Scene::environment through glTF, which has no environment concept:
// an object in the root `extras` (glTF 2.0 spec §5, glTFProperty `extras`: application-specific
// data, which other readers ignore). Not an extension: nothing goes into extensionsUsed. Written by write_gltf, read by
// load_gltf for any file that carries it; other glTF viewers will not show it.
//
//   "extras": {
//     "speculum_environment": {
//       "color": [r, g, b],      Environment::constant, linear radiance (finite numbers)
//       "intensity": x,          Environment::intensity (finite, >= 0)
//       "equirect": {            only when the environment is an image
//         "bufferView": i,       tightly packed rows, top row first, pixel (0,0) first
//         "width": w, "height": h,
//         "format": "RGBA32F"    4 little-endian IEEE-754 binary32 per pixel, R G B A
//       }
//     }
//   }
//
// Every key is optional (defaults: black, intensity 1, no image); keys not listed here are
// reported as loader warnings and otherwise ignored. The image pixels are stored as the
// renderer holds them (linear float), so the round trip is bit-exact. Not carried:
// Environment::source (the loaded scene names the glTF file instead).
#pragma once

namespace speculum::gltf {

inline constexpr const char* kEnvironmentExtrasKey = "speculum_environment";
inline constexpr const char* kEquirectFormat = "RGBA32F";
inline constexpr int kEquirectBytesPerPixel = 16;
// Largest equirect side we accept on load: far above any real map, small enough that the
// byte count cannot overflow.
inline constexpr int kMaxEquirectSide = 1 << 15;

}  // namespace speculum::gltf
