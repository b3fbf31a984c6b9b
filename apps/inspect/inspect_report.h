// What `inspect` found in one frame and the two documents it writes from it: manifest.json
// (machine-readable) and index.html (the passes in execution order, opened from disk).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace speculum::inspect {

struct ImageFile {
  std::string label, encoding;
  std::string png, exr;  // paths relative to the output directory
};

struct PortInfo {
  std::string port, resource, type, size;  // size: "" when the value was not seen
  bool previous_frame = false;
  bool drawable = false;
  std::vector<ImageFile> images;  // outputs only
};

struct LaunchInfo {
  std::string name;
  std::size_t elements = 0, chunks = 0;
  double ms = 0;
};

struct NodeInfo {
  std::string name, description;
  std::vector<std::pair<std::string, std::string>> parameters;
  double ms = 0;
  std::map<std::string, double> counters;  // integral values are written as JSON integers
  std::vector<PortInfo> inputs, outputs;
  std::vector<LaunchInfo> launches;
};

struct Report {
  std::string scene, technique;
  std::vector<std::pair<std::string, std::string>> settings;
  double frame_ms = 0;
  std::vector<NodeInfo> nodes;  // execution order
  std::vector<std::string> culled;
  std::string dot, svg;         // relative paths; svg "" when Graphviz is missing
  std::vector<std::string> files;  // every file written, relative
};

nlohmann::json manifest_json(const Report& report);
// Self-contained HTML (inline style and script, relative image paths). A script records
// images that fail to load and script errors into #inspect-status (data-state ok|error),
// which the browser test reads.
std::string index_html(const Report& report);

std::string html_escape(const std::string& s);
// A page's self-check, placed in its <head>: records images that fail and script errors,
// and after the load event writes into the element with id `status_id` how many images
// loaded (data-images, data-loaded, data-failed, data-errors, data-state ok|error) — what
// the headless-browser tests of `inspect` and `matrix` read.
std::string page_check_script(const std::string& status_id);

}  // namespace speculum::inspect
