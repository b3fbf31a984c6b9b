// The technique table behind `speculum render --technique` and `speculum techniques`: one
// entry per technique, its one-line description and the recipe that builds its graph.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "apps/techniques/envmap.h"

namespace speculum::pipeline {

struct Technique {
  std::string name;
  std::string summary;  // one line
  // Adds the technique's passes; they must produce kRadiance and kDisplay.
  std::function<void(par::Graph&, const Scene*, const FrameSettings&)> add_passes;
  // The names its recipe reads through FrameSettings::param (`--param name=value`); any
  // other name is an input error (check_technique_params).
  std::vector<std::string> params;
};

const std::vector<Technique>& techniques();
// Throws InputError listing the known names when `name` is unknown.
const Technique& find_technique(const std::string& name);
// Throws InputError naming the first parameter in `params` that `technique` does not read,
// and listing the ones it does.
void check_technique_params(const Technique& technique,
                            const std::map<std::string, double>& params);

}  // namespace speculum::pipeline
