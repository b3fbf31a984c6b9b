// The technique table behind `speculum render --technique` and `speculum techniques`: one
// entry per technique, its one-line description and the recipe that builds its graph.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "apps/pipeline_envmap.h"

namespace speculum::pipeline {

struct Technique {
  std::string name;
  std::string summary;  // one line
  // Adds the technique's passes; they must produce kRadiance and kDisplay.
  std::function<void(par::Graph&, const Scene*, const FrameSettings&)> add_passes;
};

const std::vector<Technique>& techniques();
// Throws InputError listing the known names when `name` is unknown.
const Technique& find_technique(const std::string& name);

}  // namespace speculum::pipeline
