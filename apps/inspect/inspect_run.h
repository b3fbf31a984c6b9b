// One frame's inspect report, written into a directory: what `speculum inspect` writes, and
// what `speculum matrix --inspect` writes beside each cell.
#pragma once

#include <filesystem>

#include "apps/cli/commands.h"
#include "apps/cli/frame_options.h"

namespace speculum::cli {

// Runs one frame of `frame` and writes every pass's outputs (PNG + EXR), graph.dot (and
// graph.svg when `svg` and Graphviz is installed), manifest.json and index.html into `dir`
// (created). Returns the path of index.html. InputError on bad options or an unwritable dir.
std::filesystem::path write_inspect_report(const pipeline::FrameOptions& frame,
                                           const std::filesystem::path& dir,
                                           const GlobalOptions& global, bool svg);

}  // namespace speculum::cli
