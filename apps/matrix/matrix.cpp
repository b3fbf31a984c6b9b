// The matrix's jobs: see matrix.h.
#include "apps/matrix/matrix.h"


#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

#include "apps/cli/frame_options.h"
#include "apps/cli/json_output.h"
#include "apps/inspect/inspect_run.h"
#include "apps/matrix/atlas.h"
#include "apps/techniques/render_frame.h"
#include "core/did_you_mean.h"
#include "core/error.h"
#include "core/image.h"
#include "core/image_flip.h"
#include "core/image_metrics.h"
#include "core/output_file.h"
#include "core/procedural_scenes.h"
#include "core/scene_loader.h"
#include "raster/gbuffer.h"

namespace speculum::matrix {

namespace fs = std::filesystem;
using cli::rounded;


namespace {

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(list);
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// "unknown technique 'envmp' (did you mean 'envmap'? known: a, b, ...)".
std::string unknown(const std::string& kind, const std::string& name, const std::vector<std::string>& known) {
  const std::string best = closest_name(name, known);
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  return "unknown " + kind + " '" + name + "' (" + (best.empty() ? "" : "did you mean '" + best + "'? ") +
         "known: " + list + ")";
}

// The techniques a cell may use: every technique of the table but the references, which judge.
bool is_reference_technique(const std::string& name) {
  return name == "reference" || name == "specular-reference";
}

std::vector<std::string> technique_names() {
  std::vector<std::string> names;
  for (const pipeline::Technique& t : pipeline::techniques())
    if (!is_reference_technique(t.name)) names.push_back(t.name);
  return names;
}

std::vector<std::string> scene_names() {
  std::vector<std::string> names;
  for (const BuiltinScene& s : builtin_scenes()) names.push_back(s.name);
  return names;
}

std::vector<std::string> pick(const std::string& option, const std::string& kind, const std::string& list,
                              const std::vector<std::string>& known) {
  if (list == "all") return known;
  std::vector<std::string> out;
  for (const std::string& name : split(list)) {
    if (std::find(known.begin(), known.end(), name) == known.end())
      throw InputError(option, unknown(kind, name, known));
    if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
  }
  if (out.empty()) throw InputError(option, "empty selection (give names separated by commas, or all)");
  return out;
}

// The --param values (technique:name=value) of one technique, as `--param name=value`.
std::vector<std::string> params_of(const MatrixOptions& o, const std::string& technique) {
  std::vector<std::string> out;
  for (const std::string& p : o.params) {
    const auto colon = p.find(':');
    if (colon != std::string::npos && p.substr(0, colon) == technique) out.push_back(p.substr(colon + 1));
  }
  return out;
}

std::string hex64(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}


double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

pipeline::FrameOptions frame_options(const MatrixOptions& o, const std::string& scene, const std::string& technique) {
  pipeline::FrameOptions f;
  f.scene = scene;
  f.technique = technique;
  f.width = o.width;
  f.height = o.height;
  f.seed = o.seed;
  f.bounces = o.bounces;
  f.exposure = "1";  // fixed: every image is judged at the same exposure
  f.params = params_of(o, technique);
  return f;
}

// What identifies a reference image: change any of it and the cache misses.
struct ReferenceKey {
  std::string text;  // human-readable, stored beside the image
  fs::path image, record;
  fs::path mask;  // specular references: white where the G-buffer surface is specular
};

std::string camera_text(const Camera& c) {
  char camera[256];
  std::snprintf(camera, sizeof camera, "eye %.9g %.9g %.9g target %.9g %.9g %.9g up %.9g %.9g %.9g fov %.9g",
                c.eye.x, c.eye.y, c.eye.z, c.target.x, c.target.y, c.target.z, c.up.x, c.up.y, c.up.z,
                static_cast<double>(c.vfov_degrees));
  return camera;
}

// The exact specular reference of `scene` at `bounces` specular bounces.
ReferenceKey specular_key(const MatrixOptions& o, const std::string& scene_name, const Scene& scene, int bounces) {
  const pipeline::FrameSettings f = pipeline::make_frame_settings(frame_options(o, scene_name, "specular-reference"), scene);
  ReferenceKey k;
  k.text = std::string(kReferenceVersion) + " specular scene " + scene_name + " camera " + camera_text(f.camera) +
           " size " + std::to_string(o.width) + "x" + std::to_string(o.height) + " glossy_samples " +
           std::to_string(o.glossy_samples) + " bounces " + std::to_string(bounces) + " seed " + std::to_string(o.seed);
  const fs::path dir = fs::path(o.output) / "references";
  const std::string stem = scene_name + "-specular-b" + std::to_string(bounces) + "-" + hex64(fnv1a(k.text));
  k.image = dir / (stem + ".png");
  k.record = dir / (stem + ".json");
  k.mask = dir / (stem + ".mask.png");
  return k;
}

ReferenceKey reference_key(const MatrixOptions& o, const std::string& scene_name, const Scene& scene) {
  const pipeline::FrameOptions fo = frame_options(o, scene_name, "reference");
  const pipeline::FrameSettings f = pipeline::make_frame_settings(fo, scene);
  ReferenceKey k;
  k.text = std::string(kReferenceVersion) + " scene " + scene_name + " camera " + camera_text(f.camera) + " size " +
           std::to_string(o.width) + "x" + std::to_string(o.height) + " spp " + std::to_string(o.spp_reference) +
           " bounces " + std::to_string(o.bounces) + " seed " + std::to_string(o.seed);
  const fs::path dir = fs::path(o.output) / "references";
  const std::string stem = scene_name + "-" + hex64(fnv1a(k.text));
  k.image = dir / (stem + ".png");
  k.record = dir / (stem + ".json");
  return k;
}

// The cached reference's record, or null when absent or for another key.
cli::OrderedJson cached_reference(const ReferenceKey& k) {
  if (!fs::exists(k.record) || !fs::exists(k.image) || (!k.mask.empty() && !fs::exists(k.mask))) return nullptr;
  try {
    cli::OrderedJson j = cli::OrderedJson::parse(read_text(k.record));
    if (j.value("key", "") == k.text) return j;
  } catch (const cli::OrderedJson::exception&) {
  }
  return nullptr;
}

Scene load(const std::string& name) { return load_scene(name); }

// Error metrics of `test` against `reference` (display images as the PNGs store them).
cli::OrderedJson error_json(const ImageRGBA& reference, const ImageRGBA& test) {
  const ImageError e = image_error(reference, test);
  const FlipResult flip = flip_error(reference, test);
  return {{"mae8", rounded(e.mae8, 6)}, {"rmse", rounded(e.rmse, 8)}, {"psnr", rounded(e.psnr, 4)},
          {"flip", rounded(flip.mean, 6)}};
}

// The errors on the pixels where mask is set only: mae8, rmse and psnr of their 8-bit values,
// the mean of the FLIP map over them, and their count.
cli::OrderedJson masked_error_json(const ImageRGBA& reference, const ImageRGBA& test, const ImageRGBA& mask) {
  if (reference.width != test.width || reference.height != test.height || mask.width != test.width ||
      mask.height != test.height)
    throw InputError("matrix", "specular reference and cell image differ in size");
  const FlipResult flip = flip_error(reference, test);
  double abs_sum = 0, sq_sum = 0, flip_sum = 0;
  std::size_t pixels = 0;
  for (std::size_t i = 0; i < test.size(); ++i) {
    if (mask.pixels[i].x < 0.5f) continue;
    ++pixels;
    flip_sum += flip.error.pixels[i];
    for (int c = 0; c < 3; ++c) {
      const double d = display_to_8bit(reference.pixels[i][c]) - display_to_8bit(test.pixels[i][c]);
      abs_sum += std::abs(d);
      sq_sum += d * d;
    }
  }
  const double n = 3.0 * double(std::max<std::size_t>(pixels, 1));
  const double rmse = std::sqrt(sq_sum / n) / 255.0;
  const double psnr = rmse > 0 ? 20.0 * std::log10(1.0 / rmse) : kPsnrIdentical;
  return {{"mae8", rounded(abs_sum / n, 6)}, {"rmse", rounded(rmse, 8)}, {"psnr", rounded(psnr, 4)},
          {"flip", rounded(pixels ? flip_sum / double(pixels) : 0.0, 6)}, {"pixels", pixels}};
}

// The specular bounces a technique follows, which its specular reference traces: the rounds
// of multi-reflection, the mirror depth of planar-mirror, the layered tracer's bounces, the
// two interfaces a refracted ray crosses, --bounces for ray-hierarchy; one otherwise.
int specular_bounces(const std::string& technique, const pipeline::FrameSettings& f) {
  if (technique == "multi-reflection") return int(f.param("rounds"));
  if (technique == "planar-mirror") return std::max(1, int(f.param("depth")));
  if (technique == "layered-distance-map") return std::max(int(f.param("bounces")), f.bounces);
  if (technique == "refraction") return 2;
  if (technique == "ray-hierarchy") return std::max(1, f.bounces);
  return 1;
}

pipeline::FrameSettings cell_settings(const MatrixOptions& o, const Cell& cell, const Scene& scene) {
  const pipeline::Technique& technique = pipeline::find_technique(cell.technique);
  return technique.with_defaults(pipeline::make_frame_settings(frame_options(o, cell.scene, cell.technique), scene));
}

}  // namespace

std::vector<Cell> select_cells(const MatrixOptions& o) {
  const auto techniques = pick("--techniques", "technique", o.techniques, technique_names());
  const auto scenes = pick("--scenes", "scene", o.scenes, scene_names());
  for (const std::string& p : o.params) {
    const auto colon = p.find(':');
    const std::string t = colon == std::string::npos ? "" : p.substr(0, colon);
    if (colon == std::string::npos || std::find(techniques.begin(), techniques.end(), t) == techniques.end())
      throw InputError("--param", "expected technique:name=value for a selected technique, got '" + p + "'");
    // name=value and its range, against the technique table (no scene needed).
    const std::string item = p.substr(colon + 1);
    if (item.find('=') == std::string::npos || item.front() == '=')
      throw InputError("--param", "expected technique:name=value, got '" + p + "'");
    pipeline::parse_technique_param(pipeline::find_technique(t), item);
  }
  std::vector<Cell> cells;
  for (const std::string& t : techniques)
    for (const std::string& s : scenes) cells.push_back({t, s});
  return cells;
}

std::vector<std::string> cell_scenes(const std::vector<Cell>& cells) {
  std::vector<std::string> out;
  for (const Cell& c : cells)
    if (std::find(out.begin(), out.end(), c.scene) == out.end()) out.push_back(c.scene);
  return out;
}

Cell find_cell(const MatrixOptions& o, const std::string& id) {
  std::vector<std::string> ids;
  for (const Cell& c : select_cells(o)) {
    if (c.id() == id) return c;
    ids.push_back(c.id());
  }
  if (ids.size() > 12) ids.resize(12);
  throw InputError("--cell", unknown("cell", id, ids));
}

void prepare_output(const fs::path& dir) {
  if (dir.empty()) throw InputError("-o", "an output directory is required");
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) throw InputError(dir.string(), "is not a directory");
  fs::create_directories(dir / "references", ec);
  fs::create_directories(dir / "cells", ec);
  if (!fs::is_directory(dir / "cells", ec) || !fs::is_directory(dir / "references", ec))
    throw InputError(dir.string(), "cannot create the output directory");
}

fs::path cell_image(const fs::path& dir, const Cell& cell) { return dir / "cells" / (cell.id() + ".png"); }
fs::path cell_record(const fs::path& dir, const Cell& cell) { return dir / "cells" / (cell.id() + ".json"); }

namespace {

void ensure_specular_reference(const MatrixOptions& o, const std::string& scene_name, const Scene& scene,
                               int bounces, par::Executor& executor, bool quiet) {
  const ReferenceKey k = specular_key(o, scene_name, scene, bounces);
  if (!cached_reference(k).is_null()) return;
  const pipeline::Technique& technique = pipeline::find_technique("specular-reference");
  pipeline::FrameOptions fo = frame_options(o, scene_name, "specular-reference");
  fo.bounces = bounces;
  fo.params = {"glossy_samples=" + std::to_string(o.glossy_samples)};
  const pipeline::FrameSettings f = pipeline::make_frame_settings(fo, scene);
  if (!quiet)
    std::fprintf(stderr, "speculum: matrix: tracing the specular reference of %s (%dx%d, %d bounce%s)\n",
                 scene_name.c_str(), o.width, o.height, bounces, bounces == 1 ? "" : "s");
  ImageRGBA mask;
  const pipeline::FrameResult r = pipeline::render_frame(scene, technique, f, executor, [&](const par::CapturedOutput& out) {
    if (const auto* g = out.as<raster::GBuffer>()) {
      mask = ImageRGBA(g->width, g->height, glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
      for (std::size_t i = 0; i < g->object.size(); ++i)
        if (g->covered(i) && raster::is_specular(g->surface[i])) mask.pixels[i] = glm::vec4(1.0f);
    }
  });
  write_image(k.mask.string(), mask);
  write_image(k.image.string(), r.display);
  const cli::OrderedJson record{{"key", k.text}, {"scene", scene_name}, {"bounces", bounces},
                                {"glossy_samples", o.glossy_samples}, {"ms", rounded(r.report.duration_ns * 1e-6, 3)}};
  write_text_file(k.record.string(), cli::json_document(record));
}

}  // namespace

void ensure_reference(const MatrixOptions& o, const std::string& scene_name, par::Executor& executor, bool quiet,
                      const std::vector<std::string>& techniques) {
  const Scene scene = load(scene_name);
  std::set<int> bounces;
  for (const std::string& t : techniques) bounces.insert(specular_bounces(t, cell_settings(o, {t, scene_name}, scene)));
  for (int b : bounces) ensure_specular_reference(o, scene_name, scene, b, executor, quiet);
  const ReferenceKey k = reference_key(o, scene_name, scene);
  if (!cached_reference(k).is_null()) return;
  const pipeline::Technique& technique = pipeline::find_technique("reference");
  pipeline::FrameOptions fo = frame_options(o, scene_name, "reference");
  fo.spp = o.spp_reference;
  pipeline::FrameSettings f = pipeline::make_frame_settings(fo, scene);
  if (!quiet)
    std::fprintf(stderr, "speculum: matrix: tracing the reference of %s (%dx%d, %d spp)\n", scene_name.c_str(),
                 o.width, o.height, o.spp_reference);
  const pipeline::FrameResult r = pipeline::render_frame(scene, technique, f, executor);
  write_image(k.image.string(), r.display);
  const cli::OrderedJson record{{"key", k.text}, {"scene", scene_name}, {"spp", o.spp_reference},
                                {"bounces", o.bounces}, {"ms", rounded(r.report.duration_ns * 1e-6, 3)}};
  write_text_file(k.record.string(), cli::json_document(record));  // last: the record marks the image complete
}

cli::OrderedJson run_cell(const MatrixOptions& o, const Cell& cell, par::Executor& executor, bool quiet) {
  ensure_reference(o, cell.scene, executor, quiet, {cell.technique});
  const Scene scene = load(cell.scene);
  const ReferenceKey k = reference_key(o, cell.scene, scene);
  const cli::OrderedJson ref = cached_reference(k);
  const pipeline::Technique& technique = pipeline::find_technique(cell.technique);
  const pipeline::FrameSettings f = cell_settings(o, cell, scene);
  const int bounces = specular_bounces(cell.technique, f);
  const ReferenceKey sk = specular_key(o, cell.scene, scene, bounces);
  const cli::OrderedJson spec_ref = cached_reference(sk);

  std::vector<double> frame_ms;
  std::map<std::string, std::vector<double>> node_ms;
  pipeline::FrameResult last;
  for (int i = 0; i < o.repeat; ++i) {
    pipeline::FrameResult r = pipeline::render_frame(scene, technique, f, executor);
    frame_ms.push_back(r.report.duration_ns * 1e-6);
    for (const auto& n : r.report.nodes) node_ms[n.name].push_back(n.duration_ns * 1e-6);
    last = std::move(r);
  }
  const fs::path dir = o.output;
  write_image(cell_image(dir, cell).string(), last.display);
  // Judge the images as stored: both read back from their PNGs, so a cached reference and a
  // fresh one give the same numbers.
  const ImageRGBA reference = read_image(k.image.string());
  const ImageRGBA image = read_image(cell_image(dir, cell).string());
  const ImageRGBA specular_reference = read_image(sk.image.string());
  const ImageRGBA mask = read_image(sk.mask.string(), false);
  const fs::path frame_heat = dir / "cells" / (cell.id() + ".frame-diff.png");
  const fs::path specular_heat = dir / "cells" / (cell.id() + ".specular-diff.png");
  write_image(frame_heat.string(), difference_heat_map(reference, image));
  write_image(specular_heat.string(), difference_heat_map(specular_reference, image, &mask));

  cli::OrderedJson nodes = cli::OrderedJson::array();
  cli::OrderedJson counters = cli::OrderedJson::object();
  for (const auto& n : last.report.nodes) {
    cli::OrderedJson node_counters = cli::OrderedJson::object();
    for (const auto& [name, value] : n.counters) {
      // *_ns counters are wall times: kept out so a record is a function of the inputs.
      if (name.size() > 3 && name.compare(name.size() - 3, 3, "_ns") == 0) continue;
      node_counters[name] = cli::counter_json(value);
      counters[n.name + "/" + name] = cli::counter_json(value);
    }
    nodes.push_back({{"name", n.name}, {"ms", rounded(median(node_ms[n.name]), 3)}});
  }
  cli::OrderedJson options{{"width", f.width}, {"height", f.height}, {"spp", f.spp}, {"bounces", f.bounces},
                           {"seed", f.seed}, {"exposure", 1.0}};
  cli::OrderedJson params = cli::OrderedJson::object();
  for (const auto& [name, value] : f.params) params[name] = cli::counter_json(value);
  options["params"] = params;
  cli::OrderedJson record{{"id", cell.id()},
                          {"technique", cell.technique},
                          {"scene", cell.scene},
                          {"options", options},
                          {"ms", rounded(median(frame_ms), 3)},
                          {"repeat", o.repeat},
                          {"nodes", nodes},
                          {"frame", error_json(reference, image)},
                          {"specular", masked_error_json(specular_reference, image, mask)},
                          {"counters", counters},
                          {"reference", {{"spp", o.spp_reference}, {"ms", ref.value("ms", 0.0)},
                                         {"image", fs::relative(k.image, dir).string()}}},
                          {"specular_reference", {{"bounces", bounces}, {"glossy_samples", o.glossy_samples},
                                                  {"ms", spec_ref.value("ms", 0.0)},
                                                  {"image", fs::relative(sk.image, dir).string()},
                                                  {"mask", fs::relative(sk.mask, dir).string()}}},
                          {"image", fs::relative(cell_image(dir, cell), dir).string()},
                          {"frame_heat_map", fs::relative(frame_heat, dir).string()},
                          {"specular_heat_map", fs::relative(specular_heat, dir).string()}};
  if (o.inspect) {
    // Every pass of the cell, one by one: the same page `speculum inspect` writes for these
    // options (its frame is not the timed one, so the times above are unaffected).
    const fs::path page = cli::write_inspect_report(frame_options(o, cell.scene, cell.technique),
                                                    dir / "cells" / (cell.id() + ".inspect"),
                                                    cli::GlobalOptions{executor.threads(), executor.lanes(), true},
                                                    /*svg=*/true);
    record["inspect"] = fs::relative(page, dir).string();
  }
  write_text_file(cell_record(dir, cell).string(), cli::json_document(record));
  return record;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

cli::OrderedJson merge(const MatrixOptions& o, const std::vector<Cell>& cells) {
  const fs::path dir = o.output;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(dir.string(), "is not a directory");
  std::vector<std::string> missing;
  cli::OrderedJson list = cli::OrderedJson::array();
  for (const Cell& c : cells) {
    const fs::path record = cell_record(dir, c);
    if (!fs::exists(record) || !fs::exists(cell_image(dir, c))) {
      missing.push_back(c.id());
      continue;
    }
    try {
      list.push_back(cli::OrderedJson::parse(read_text(record)));
    } catch (const cli::OrderedJson::exception&) {
      throw InputError(record.string(), "is not a cell record (interrupted job? run it again)");
    }
  }
  if (!missing.empty()) {
    std::string names;
    for (const std::string& m : missing) names += (names.empty() ? "" : ", ") + m;
    throw InputError(dir.string(), std::to_string(missing.size()) + " of " + std::to_string(cells.size()) +
                                       " cells missing: " + names);
  }
  cli::OrderedJson results{{"version", kReferenceVersion}, {"width", o.width}, {"height", o.height},
                           {"spp_reference", o.spp_reference}, {"glossy_samples", o.glossy_samples},
                           {"cells", list}};
  write_text_file((dir / "results.json").string(), cli::json_document(results));
  return results;
}

}  // namespace speculum::matrix
