// How `inspect` draws a captured node output (parallel/graph.h CapturedOutput): each known
// type becomes one or more views — a PNG picture (false colour for ids, normalised ramps for
// depth, distance and counters, n·0.5+0.5 for normals, tone-mapped radiance, cube maps as a
// cross) plus its raw values for an EXR. Unknown types, and outputs with nothing to show (no cube
// map in a list of them), are reported as not drawable.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "core/image.h"
#include "parallel/executor.h"
#include "parallel/graph.h"

namespace speculum::inspect {

struct View {
  std::string label;     // "" for the value itself, else the field shown ("normal", "light0")
  std::string encoding;  // how the PNG maps values to colours, e.g. "ramp 0.5..7.2"
  ImageRGBA picture;     // linear colour: write_image sRGB-encodes it into the PNG
  ImageRGBA raw_rgba;    // raw values for the EXR: raw_rgba or raw_scalar is set
  ImageF raw_scalar;
};

struct Drawing {
  bool drawable = false;
  std::string size;  // "64x48", "6 faces 8x8", "2 lights", ... ("" when unknown)
  std::vector<View> views;
};

// `executor` runs the tone mapping (use one that is not being profiled).
Drawing draw_output(const par::CapturedOutput& output, par::Executor& executor);

// Building blocks (tests check them).
// A colour per id from a hash of the id (stable across runs); kNoId is black. sRGB values.
glm::vec3 id_colour(std::uint32_t id);
// Six faces side by side as a horizontal cross (+Y above, −Y below the +Z face); empty
// faces and the unused cells are black. All faces must have the same size.
ImageRGBA cube_cross(const std::array<ImageRGBA, 6>& faces);

// Helpers shared with the trace-side drawers (apps/inspect/inspect_trace_images.cpp).
namespace draw {
std::string dims(int w, int h);
std::string fmt(double v);
glm::vec4 from_srgb(glm::vec3 c);  // a linear picture colour from an sRGB colour
// Grey ramp over the finite values outside `mask` (samples with mask id kNoId are black).
View scalar_view(std::string label, const ImageF& img, const IdBuffer* mask = nullptr);
View id_view(std::string label, const IdBuffer& ids);
View colour_cross_view(std::string label, const std::array<ImageRGBA, 6>& faces, par::Executor& executor);
View distance_cross_view(std::string label, const std::array<ImageF, 6>& faces);
bool has_faces(const std::array<ImageRGBA, 6>& faces);
bool has_faces(const std::array<ImageF, 6>& faces);
}  // namespace draw

}  // namespace speculum::inspect
