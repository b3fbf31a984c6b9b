// The matrix atlas: see atlas.h.
#include "apps/matrix/atlas.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "apps/inspect/inspect_report.h"
#include "apps/matrix/matrix.h"
#include "core/error.h"
#include "core/image_metrics.h"
#include "core/output_file.h"

namespace speculum::matrix {

namespace fs = std::filesystem;
using inspect::html_escape;

namespace {


constexpr const char* kStyle = R"(<style>
body { font-family: sans-serif; margin: 1.5em; color: #222; }
table { border-collapse: collapse; }
td, th { border: 1px solid #ddd; padding: 4px; vertical-align: top; font-size: 0.8em; }
td img { width: 160px; image-rendering: pixelated; display: block; margin-bottom: 2px; }
.maps img { width: 78px; display: inline-block; }
figure { display: inline-block; margin: 0.5em; } figure img { width: 480px; }
#atlas-status.good { color: #060; } #atlas-status.bad { color: #a00; font-weight: bold; }
code { font-size: 0.9em; }
</style>)";

std::string fixed(double v, int digits) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", digits, v);
  return text;
}

std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

// Indices of the cells on the Pareto front of (ms, error): sorted by time, each faster-or-equal
// cell with a lower error than every faster one.
std::vector<std::size_t> pareto(const std::vector<double>& ms, const std::vector<double>& error) {
  std::vector<std::size_t> order(ms.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return ms[a] < ms[b] || (ms[a] == ms[b] && error[a] < error[b]);
  });
  std::vector<std::size_t> front;
  double best = 1e300;
  for (std::size_t i : order)
    if (error[i] < best) best = error[i], front.push_back(i);
  return front;
}

// charts/SCENE.svg: frame and specular mae8 against the median ms (log scale), technique names
// beside the points, the Pareto front of each as a line.
void chart(const fs::path& dir, const std::string& scene, const std::vector<const nlohmann::ordered_json*>& cells) {
  std::vector<double> ms, frame, specular;
  for (const auto* c : cells) {
    ms.push_back(std::max(1e-3, (*c)["ms"].get<double>()));
    frame.push_back((*c)["frame"]["mae8"].get<double>());
    specular.push_back((*c)["specular"]["mae8"].get<double>());
  }
  const fs::path charts = dir / "charts";
  const fs::path data = charts / ("." + scene + ".dat"), script = charts / ("." + scene + ".gp");
  const fs::path tmp = charts / ("." + scene + ".tmp.svg"), svg = charts / (scene + ".svg");
  {
    std::ofstream d(data);
    for (std::size_t i = 0; i < cells.size(); ++i)
      d << ms[i] << " " << frame[i] << " " << specular[i] << " \"" << (*cells[i])["technique"].get<std::string>()
        << "\"\n";
    for (const auto& [block, error] : {std::pair{"frame", &frame}, std::pair{"specular", &specular}}) {
      d << "\n\n";  // the next data block: a Pareto front
      for (std::size_t i : pareto(ms, *error)) d << ms[i] << " " << (*error)[i] << "\n";
    }
  }
  {
    std::ofstream g(script);
    g << "set terminal svg size 560,380 font 'sans,10' background '#ffffff'\n"
      << "set output " << shell_quoted(tmp.string()) << "\n"
      << "set title " << shell_quoted(scene + ": error against time") << "\n"
      << "set logscale x\nset xlabel 'median frame ms (log)'\nset ylabel 'mae8 (8-bit values)'\n"
      << "set key top right\nset grid\n"
      << "plot " << shell_quoted(data.string()) << " index 0 using 1:2 with points pt 7 title 'frame', "
      << "'' index 0 using 1:3 with points pt 5 title 'specular', "
      << "'' index 0 using 1:3:4 with labels offset 0.6,0.6 left font ',8' notitle, "
      << "'' index 1 using 1:2 with lines dt 2 title 'frame Pareto front', "
      << "'' index 2 using 1:2 with lines dt 3 title 'specular Pareto front'\n";
  }
  const int status = std::system(("gnuplot " + shell_quoted(script.string()) + " 2>/dev/null").c_str());
  fs::remove(data);
  fs::remove(script);
  std::error_code ec;
  if (status != 0 || !fs::exists(tmp)) throw InputError(svg.string(), "gnuplot failed to draw the chart");
  fs::rename(tmp, svg, ec);
  if (ec) throw InputError(svg.string(), "cannot write: " + ec.message());
}

}  // namespace

ImageRGBA difference_heat_map(const ImageRGBA& a, const ImageRGBA& b, const ImageRGBA* mask) {
  ImageRGBA out(a.width, a.height);
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (mask && mask->pixels[i].x < 0.5f) {
      out.pixels[i] = {0.02f, 0.02f, 0.02f, 1.0f};
      continue;
    }
    int d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(display_to_8bit(a.pixels[i][c]) - display_to_8bit(b.pixels[i][c])));
    // Black → red → yellow → white (sRGB) over 0 .. 64.
    const float t = std::clamp(float(d) / 64.0f, 0.0f, 1.0f);
    const float r = std::clamp(3.0f * t, 0.0f, 1.0f), g = std::clamp(3.0f * t - 1.0f, 0.0f, 1.0f),
                bl = std::clamp(3.0f * t - 2.0f, 0.0f, 1.0f);
    out.pixels[i] = {srgb_to_linear(r), srgb_to_linear(g), srgb_to_linear(bl), 1.0f};
  }
  return out;
}

void write_atlas(const fs::path& dir, const nlohmann::ordered_json& results, bool quiet) {
  std::vector<std::string> techniques, scenes;
  std::map<std::pair<std::string, std::string>, const nlohmann::ordered_json*> by_cell;
  for (const auto& c : results["cells"]) {
    const std::string t = c["technique"], s = c["scene"];
    if (std::find(techniques.begin(), techniques.end(), t) == techniques.end()) techniques.push_back(t);
    if (std::find(scenes.begin(), scenes.end(), s) == scenes.end()) scenes.push_back(s);
    by_cell[{t, s}] = &c;
  }
  const bool charts = have_gnuplot();
  if (charts) {
    std::error_code ec;
    fs::create_directories(dir / "charts", ec);
    for (const std::string& s : scenes) {
      std::vector<const nlohmann::ordered_json*> cells;
      for (const std::string& t : techniques)
        if (by_cell.count({t, s})) cells.push_back(by_cell[{t, s}]);
      chart(dir, s, cells);
    }
  } else if (!quiet) {
    std::fprintf(stderr, "speculum: warning: matrix: gnuplot not found: index.html has no charts "
                         "(Debian package gnuplot-nox)\n");
  }

  std::ostringstream h;
  h << "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n<title>speculum matrix</title>\n"
    << kStyle << "\n" << inspect::page_check_script("atlas-status") << "\n</head><body>\n<h1>speculum matrix</h1>\n"
    << "<p id=\"atlas-status\" data-state=\"pending\">checking images…</p>\n"
    << "<p>" << results["width"].get<int>() << "×" << results["height"].get<int>()
    << "; frame error against <code>reference</code> at " << results["spp_reference"].get<int>()
    << " spp, specular error against <code>specular-reference</code> on specular pixels only. Each cell: "
       "its image, then heat maps of the 8-bit difference to each reference (black 0, white ≥ 64; "
       "grey: not specular). <a href=\"results.json\">results.json</a></p>\n";
  h << "<table><tr><th>technique \\ scene</th>";
  for (const std::string& s : scenes) h << "<th>" << html_escape(s) << "</th>";
  h << "</tr>\n";
  for (const std::string& t : techniques) {
    h << "<tr><th>" << html_escape(t) << "</th>";
    for (const std::string& s : scenes) {
      const auto it = by_cell.find({t, s});
      if (it == by_cell.end()) {
        h << "<td></td>";
        continue;
      }
      const auto& c = *it->second;
      const std::string id = c["id"];
      h << "<td><img src=\"" << html_escape(c["image"].get<std::string>()) << "\" alt=\"" << html_escape(id)
        << "\"><span class=\"maps\"><img src=\"" << html_escape(c["frame_heat_map"].get<std::string>())
        << "\" alt=\"frame difference\" title=\"against reference\"> <img src=\""
        << html_escape(c["specular_heat_map"].get<std::string>())
        << "\" alt=\"specular difference\" title=\"against specular-reference\"></span><br>"
        << fixed(c["ms"].get<double>(), 1) << " ms<br>frame mae8 " << fixed(c["frame"]["mae8"].get<double>(), 2)
        << "<br>specular mae8 " << fixed(c["specular"]["mae8"].get<double>(), 2) << "<br>";
      // The cell's passes, one by one: a link when the run wrote them (--inspect), else the
      // command that writes them.
      if (c.contains("inspect"))
        h << "<a href=\"" << html_escape(c["inspect"].get<std::string>()) << "\">inspect</a>";
      else
        h << "<code title=\"the cell's passes, one by one\">speculum inspect " << html_escape(s) << " -t "
          << html_escape(t) << "</code>";
      h << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n<h2>Error against time</h2>\n";
  if (charts)
    for (const std::string& s : scenes)
      h << "<figure><img src=\"charts/" << html_escape(s) << ".svg\" alt=\"" << html_escape(s)
        << ": error against time\"></figure>\n";
  else
    h << "<p>gnuplot was not found when this page was written: no charts.</p>\n";
  h << "</body></html>\n";
  write_text_file((dir / "index.html").string(), h.str());
}

}  // namespace speculum::matrix
