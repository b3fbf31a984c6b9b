// One frame of a technique: see render_frame.h.
#include "apps/techniques/render_frame.h"

namespace speculum::pipeline {

FrameResult render_frame(const Scene& scene, const Technique& technique,
                         const FrameSettings& settings, par::Executor& executor,
                         const par::CaptureHook& capture) {
  par::Graph graph;
  technique.add_passes(graph, &scene, settings);
  graph.request(kRadiance);
  graph.request(kDisplay);
  FrameResult result;
  result.report = graph.run(executor, capture);
  result.radiance = graph.get<ImageRGBA>(kRadiance);
  result.display = graph.get<ImageRGBA>(kDisplay);
  return result;
}

}  // namespace speculum::pipeline
