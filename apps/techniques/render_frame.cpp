// One frame of a technique: see render_frame.h.
#include "apps/techniques/render_frame.h"

namespace speculum::pipeline {

FrameResult render_frame(const Scene& scene, const Technique& technique,
                         const FrameSettings& settings, par::Executor& executor,
                         const par::CaptureHook& capture) {
  par::Graph graph;
  const FrameOutputs out = technique.add_passes(graph, &scene, settings);
  graph.request(out.radiance);
  graph.request(out.display);
  FrameResult result;
  result.report = graph.run(executor, capture);
  result.radiance = graph.get(out.radiance);
  result.display = graph.get(out.display);
  return result;
}

}  // namespace speculum::pipeline
