// manifest.json and index.html of `inspect`: see inspect_report.h.
#include "apps/inspect/inspect_report.h"

#include "apps/cli/json_output.h"

#include <cstdio>
#include <sstream>

namespace speculum::inspect {

namespace {

nlohmann::json port_json(const PortInfo& p, bool output) {
  nlohmann::json j{{"port", p.port}, {"resource", p.resource}, {"type", p.type}, {"size", p.size}};
  if (p.previous_frame) j["previous_frame"] = true;
  if (output) {
    j["drawable"] = p.drawable;
    nlohmann::json images = nlohmann::json::array();
    for (const auto& im : p.images)
      images.push_back({{"label", im.label}, {"encoding", im.encoding}, {"png", im.png}, {"exr", im.exr}});
    j["images"] = std::move(images);
  }
  return j;
}

std::string ms_text(double ms) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f ms", ms);
  return buf;
}


constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 1.5em; max-width: 1400px; color: #222; }
section { border-top: 1px solid #ccc; padding: 0.5em 0 1em; }
h2 { margin: 0.3em 0; font-size: 1.2em; }
.desc { font-style: italic; }
table { border-collapse: collapse; margin: 0.3em 0; }
td, th { border: 1px solid #ddd; padding: 2px 8px; text-align: left; font-size: 0.9em; }
figure { display: inline-block; margin: 0.4em; vertical-align: top; max-width: 420px; }
figure img { height: 200px; max-width: 400px; object-fit: contain; image-rendering: pixelated; border: 1px solid #999; }
figcaption { font-size: 0.8em; }
.graph { overflow-x: auto; } .graph img { max-width: none; }
#inspect-status.good { color: #060; } #inspect-status.bad { color: #a00; font-weight: bold; }
.muted { color: #777; }
</style>)";

void kv_table(std::ostringstream& h, const std::vector<std::pair<std::string, std::string>>& rows) {
  if (rows.empty()) return;
  h << "<table>";
  for (const auto& [k, v] : rows) h << "<tr><th>" << html_escape(k) << "</th><td>" << html_escape(v) << "</td></tr>";
  h << "</table>\n";
}

}  // namespace

std::string page_check_script(const std::string& status_id) {
  return R"(<script>
window.pageErrors = [];
window.addEventListener('error', function (e) {
  var t = e.target;
  if (t && t.tagName === 'IMG') window.pageErrors.push('image failed: ' + t.getAttribute('src'));
  else window.pageErrors.push('script error: ' + (e.message || e));
}, true);
window.addEventListener('load', function () {
  var images = document.images, loaded = 0, failed = [];
  for (var i = 0; i < images.length; i++) {
    if (images[i].complete && images[i].naturalWidth > 0) loaded++;
    else failed.push(images[i].getAttribute('src'));
  }
  var s = document.getElementById(')" + status_id + R"(');
  var bad = failed.length > 0 || window.pageErrors.length > 0;
  s.setAttribute('data-images', String(images.length));
  s.setAttribute('data-loaded', String(loaded));
  s.setAttribute('data-failed', failed.join(' '));
  s.setAttribute('data-errors', window.pageErrors.join(' | '));
  s.setAttribute('data-state', bad ? 'error' : 'ok');
  s.textContent = loaded + ' of ' + images.length + ' images loaded' +
      (bad ? ' — problems: ' + failed.concat(window.pageErrors).join(', ') : '');
  s.className = bad ? 'bad' : 'good';
});
</script>)";
}

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

nlohmann::json manifest_json(const Report& r) {
  nlohmann::json settings = nlohmann::json::object();
  for (const auto& [k, v] : r.settings) settings[k] = v;
  nlohmann::json nodes = nlohmann::json::array();
  for (const auto& n : r.nodes) {
    nlohmann::json params = nlohmann::json::object(), inputs = nlohmann::json::array(),
                   outputs = nlohmann::json::array(), launches = nlohmann::json::array();
    for (const auto& [k, v] : n.parameters) params[k] = v;
    for (const auto& p : n.inputs) inputs.push_back(port_json(p, false));
    for (const auto& p : n.outputs) outputs.push_back(port_json(p, true));
    for (const auto& l : n.launches)
      launches.push_back({{"name", l.name}, {"elements", l.elements}, {"chunks", l.chunks}, {"ms", l.ms}});
    nodes.push_back({{"name", n.name}, {"description", n.description}, {"parameters", params},
                     {"time_ms", n.ms}, {"counters", cli::counters_json(n.counters)}, {"inputs", inputs},
                     {"outputs", outputs}, {"launches", launches}});
  }
  return {{"scene", r.scene}, {"technique", r.technique}, {"settings", settings},
          {"frame_ms", r.frame_ms}, {"nodes", nodes}, {"culled", r.culled},
          {"graph", {{"dot", r.dot}, {"svg", r.svg}}}, {"files", r.files}};
}

std::string index_html(const Report& r) {
  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>speculum inspect: "
    << html_escape(r.technique) << " on " << html_escape(r.scene) << "</title>\n"
    << kStyle << "\n" << page_check_script("inspect-status") << "\n</head><body>\n";
  h << "<h1>" << html_escape(r.technique) << " on " << html_escape(r.scene) << "</h1>\n";
  h << "<p id=\"inspect-status\" data-state=\"pending\">checking images…</p>\n";
  h << "<p>Frame " << ms_text(r.frame_ms) << ", " << r.nodes.size()
    << " passes in execution order. <a href=\"manifest.json\">manifest.json</a> · <a href=\""
    << html_escape(r.dot) << "\">graph (DOT)</a></p>\n";
  kv_table(h, r.settings);
  if (!r.culled.empty()) {
    h << "<p class=\"muted\">Culled (not needed for the requested outputs):";
    for (const auto& c : r.culled) h << " " << html_escape(c);
    h << "</p>\n";
  }
  if (!r.svg.empty())
    h << "<div class=\"graph\"><img src=\"" << html_escape(r.svg) << "\" alt=\"job graph\"></div>\n";
  for (std::size_t i = 0; i < r.nodes.size(); ++i) {
    const NodeInfo& n = r.nodes[i];
    h << "<section id=\"node-" << html_escape(n.name) << "\">\n<h2>" << i + 1 << ". "
      << html_escape(n.name) << " <span class=\"muted\">" << ms_text(n.ms) << "</span></h2>\n";
    h << "<p class=\"desc\">"
      << (n.description.empty() ? "(no description)" : html_escape(n.description)) << "</p>\n";
    kv_table(h, n.parameters);
    std::vector<std::pair<std::string, std::string>> counters;
    for (const auto& [k, v] : n.counters) counters.emplace_back(k, cli::counter_json(v).dump());
    if (!counters.empty()) h << "<p>Counters</p>", kv_table(h, counters);
    if (!n.inputs.empty()) {
      h << "<p>Reads:";
      for (const auto& p : n.inputs)
        h << " <code>" << html_escape(p.resource) << (p.previous_frame ? " (previous frame)" : "")
          << "</code> <span class=\"muted\">" << html_escape(p.type) << "</span>";
      h << "</p>\n";
    }
    if (!n.launches.empty()) {
      h << "<details><summary>" << n.launches.size() << " kernel launches</summary><table>"
        << "<tr><th>launch</th><th>elements</th><th>chunks</th><th>ms</th></tr>";
      for (const auto& l : n.launches)
        h << "<tr><td>" << html_escape(l.name) << "</td><td>" << l.elements << "</td><td>" << l.chunks
          << "</td><td>" << ms_text(l.ms) << "</td></tr>";
      h << "</table></details>\n";
    }
    for (const auto& p : n.outputs) {
      h << "<p>Writes <code>" << html_escape(p.resource) << "</code> <span class=\"muted\">"
        << html_escape(p.type) << (p.size.empty() ? "" : ", " + html_escape(p.size)) << "</span>"
        << (p.drawable ? "" : " — not drawable") << "</p>\n";
      for (const auto& im : p.images) {
        h << "<figure><a href=\"" << html_escape(im.png) << "\"><img src=\"" << html_escape(im.png)
          << "\" alt=\"" << html_escape(p.resource + " " + im.label) << "\"></a><figcaption>"
          << html_escape(im.label.empty() ? p.resource : im.label) << ": " << html_escape(im.encoding)
          << " · <a href=\"" << html_escape(im.exr) << "\">EXR</a></figcaption></figure>\n";
      }
    }
    h << "</section>\n";
  }
  h << "</body></html>\n";
  return h.str();
}

}  // namespace speculum::inspect
