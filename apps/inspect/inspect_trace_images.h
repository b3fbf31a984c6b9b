// How `inspect` draws the trace-side outputs: secondary ray generations, the ray
// hierarchy's levels and their hits (ROGER §3.3), YU's glossy rays and LOD hits (YU §3.2,
// §3.3) and layered distance maps (SURVEY §4.5) as per-pixel pictures, see inspect_images.h.
#pragma once

#include "apps/inspect/inspect_images.h"

namespace speculum::inspect {

// Fills `d` and returns true when `output` holds one of the trace-side types. Hit streams
// carry no pixel grid: they are drawn on the grid of the last ray generation with the same
// number of rays drawn before them (inspect captures in execution order, rays before hits);
// with none they stay not drawable.
bool draw_trace_output(const par::CapturedOutput& output, par::Executor& executor, Drawing& d);

// Forgets the ray grids remembered for hit streams (tests).
void forget_ray_grids();

}  // namespace speculum::inspect
