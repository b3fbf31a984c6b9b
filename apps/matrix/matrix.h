// `speculum matrix`: every selected technique on every selected built-in scene, each cell
// timed and judged against references that are traced once and cached in the output
// directory. The work is split into jobs that a scheduler may run anywhere in any order
// (references, then cells), and a merge that builds results.json from the cells present;
// a plain `speculum matrix` runs the same jobs in one process, so both give the same files.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "parallel/executor.h"

namespace speculum::matrix {

// Bumped whenever a reference image would change for the same key (tracer, shading, metrics):
// cached references with another version are retraced.
inline constexpr const char* kReferenceVersion = "speculum-reference-3";

struct MatrixOptions {
  std::string techniques = "all";  // comma-separated names or "all"
  std::string scenes = "all";      // comma-separated built-in scene names or "all"
  int width = 320, height = 240;
  int repeat = 3;
  int spp_reference = 64;
  int glossy_samples = 256;  // specular reference: GGX samples per glossy pixel
  int bounces = 0;           // 0: each technique's default (the frame reference: 8)
  std::uint32_t seed = 0;
  std::vector<std::string> params;  // technique:name=value
  std::string output;
  bool inspect = false;  // also write each cell's inspect report into DIR/cells/ID.inspect/
};

struct Cell {
  std::string technique, scene;
  std::string id() const { return technique + "@" + scene; }
};

// The cells of the selection (techniques × scenes, in table and scene-library order).
// Throws InputError for an unknown name (with a "did you mean"), an empty selection or a
// malformed --param.
std::vector<Cell> select_cells(const MatrixOptions& o);
// The scenes the cells use, in order, each once.
std::vector<std::string> cell_scenes(const std::vector<Cell>& cells);

// The output directory, created if missing; InputError when it is a file or cannot be made.
void prepare_output(const std::filesystem::path& dir);

// The references of `scene` in DIR/references, each traced unless cached: the converged
// `reference` (frame error) and the `specular-reference` at every specular bounce count the
// `techniques` follow (specular error).
void ensure_reference(const MatrixOptions& o, const std::string& scene, par::Executor& executor, bool quiet,
                      const std::vector<std::string>& techniques);
// Runs one cell (its reference first if it is not cached) into DIR/cells/ID.{png,json}.
nlohmann::ordered_json run_cell(const MatrixOptions& o, const Cell& cell, par::Executor& executor, bool quiet);
// Finds a cell of the selection by its id ("technique@scene"); InputError when none.
Cell find_cell(const MatrixOptions& o, const std::string& id);

// results.json from DIR/cells (written atomically); InputError naming the missing cells.
nlohmann::ordered_json merge(const MatrixOptions& o, const std::vector<Cell>& cells);

// The whole of a text file ("" when it cannot be read).
std::string read_text(const std::filesystem::path& path);

// Path of a cell's image and record.
std::filesystem::path cell_image(const std::filesystem::path& dir, const Cell& cell);
std::filesystem::path cell_record(const std::filesystem::path& dir, const Cell& cell);


}  // namespace speculum::matrix
