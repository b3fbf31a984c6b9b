// The technique table behind `speculum render --technique`, `speculum techniques` and
// `--help`: one entry per technique with its one-line summary, its recipe, and its
// parameters (`--param name=value`) with their defaults and valid ranges — the one place
// they are written.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "apps/techniques/frame_settings.h"

namespace speculum::pipeline {

struct TechniqueParam {
  std::string name;
  double fallback = 0;  // the default
  double min = 0, max = 0;
  bool integer = true;  // only whole numbers are valid
  std::string doc;      // one line
  // A parameter that picks one of several modes names them: value k is choices[k], so
  // `--param filter=triangles` and `--param filter=1` are the same (min 0, max size − 1).
  std::vector<std::string> choices = {};

  // choices[v] for a parameter with named choices, else the number ("1", "0.05").
  std::string value_text(double v) const;
  // "integer in [1, 16]", or "one of splat|triangles" for named choices.
  std::string range_text() const;
};

// A parameter whose value is one of `names` (its default `fallback`, by name).
TechniqueParam choice_param(std::string name, const std::string& fallback, std::vector<std::string> names,
                            std::string doc);

struct Technique {
  std::string name;
  std::string summary;  // one line
  std::function<FrameOutputs(par::Graph&, const Scene*, const FrameSettings&)> recipe;
  std::vector<TechniqueParam> params;
  // The most samples (width × height × spp) a frame may take. Rasterized frames keep every
  // sample (visibility, G-buffer, layers: memory); the sampled ones keep pixels and pay for
  // samples in time. Each figure is set from the technique's measured peak.
  double max_samples = double(1 << 23);
  // Samples per pixel when none are asked for (FrameSettings::spp = 0), lowered where the
  // frame would exceed max_samples.
  int default_spp = 1;

  // `settings` with every parameter of the table present (defaults where not given) and
  // spp resolved (default_spp where 0).
  // Throws InputError for an unknown, out-of-range or fractional-where-whole parameter.
  FrameSettings with_defaults(FrameSettings settings) const;
  // `spp`, or default_spp (lowered to fit max_samples, at least 1) where it is 0.
  int resolve_spp(int spp, int width, int height) const;
  // Adds the technique's passes to `graph` (the recipe, on with_defaults(settings)).
  FrameOutputs add_passes(par::Graph& graph, const Scene* scene, const FrameSettings& settings) const {
    return recipe(graph, scene, with_defaults(settings));
  }
  // "rounds=3  integer in [1, 16]  reflector map rounds" lines, one per parameter; "" when
  // it has none.
  std::string describe_params(const std::string& indent) const;
};

const std::vector<Technique>& techniques();
// Throws InputError listing the known names when `name` is unknown.
const Technique& find_technique(const std::string& name);
// Throws InputError naming the first parameter of `params` that `technique` does not take
// or whose value is outside its range, with the valid names or range.
void check_technique_params(const Technique& technique, const std::map<std::string, double>& params);
// One `--param` item, "name=value": the value a number or, for a parameter with named
// choices, one of the names. Throws InputError (an unknown parameter or name, not a number,
// out of range) naming the parameter and what it takes.
std::pair<std::string, double> parse_technique_param(const Technique& technique, const std::string& item);

}  // namespace speculum::pipeline
