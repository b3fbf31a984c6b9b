// Runs one frame of a technique: builds its graph, requests the outputs and returns the
// images and the run report. Shared by render, the experiments, inspect and profile so
// they all measure and show exactly what `render` produces.
#pragma once

#include "apps/techniques/technique_table.h"

namespace speculum::pipeline {

struct FrameResult {
  ImageRGBA radiance;  // linear, width × height
  ImageRGBA display;   // tone-mapped, what a PNG stores
  par::RunReport report;
};

// `capture`, when set, sees every node output (graph.h CaptureHook) while the frame runs.
FrameResult render_frame(const Scene& scene, const Technique& technique,
                         const FrameSettings& settings, par::Executor& executor,
                         const par::CaptureHook& capture = {});

}  // namespace speculum::pipeline
