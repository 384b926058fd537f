// `mixpilot figures`: the thesis's figures (SPEC §11) as PNG and CSV, with an index.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/figures.hpp"
#include "core/base/output_file.hpp"
#include "core/numerics/version.hpp"
#include "core/scenario/data_files.hpp"

namespace mixpilot::cli {
namespace {

constexpr const char* kUsageHead =
    "usage: mixpilot figures --out DIR [--only ID[,ID...]] [--force] [--jobs N] [--width PX]\n"
    "\n"
    "Renders the thesis's figures (SPEC 11) from flights of the shipped scenarios, flown headless\n"
    "as `mixpilot fly --headless` flies them (variants by setting scenario keys: the round trip,\n"
    "the predictor, the constraint form, the pilot). Each figure is written as DIR/fig_<id>.png,\n"
    "drawn offscreen through EGL by the app's plot code at print resolution (1800 px across:\n"
    "300 dpi over 15 cm), its data as DIR/fig_<id>.csv (a header of names with units), and\n"
    "DIR/index.md lists them with what each shows. Which flight is flying goes to stderr; all\n"
    "of them (36 flights) take about half a minute on two cores.\n"
    "\n"
    "figures:\n";

constexpr const char* kUsageTail =
    "\n"
    "options:\n"
    "  --out DIR     the folder to write into (made when missing)\n"
    "  --only IDS    only these figures: ids separated by commas (--only 5.6, --only 7.5,7.9);\n"
    "                may be repeated. index.md then lists these\n"
    "  --force       replace existing outputs (without it, an output that exists is an error\n"
    "                before anything flies)\n"
    "  --jobs N      flights flown at once (default: the number of cores); the flights whose RTI\n"
    "                times a figure plots (Fig. 7.9) fly alone afterwards\n"
    "  --width PX    the images' width, 600 to 7200 (default 1800); heights, text and lines\n"
    "                in proportion (1200 suits a screen or a web page)\n"
    "  -h, --help    show this help\n"
    "\n"
    "environment: MIXPILOT_DATA_DIR, the folder holding scenarios/ (see 'mixpilot --help')\n"
    "\n"
    "exit status: 0 done, 1 a flight, the rendering or a write failed, 2 usage, 130 interrupted\n";

std::string usage() {
  std::string u = kUsageHead;
  for (const FigureDef& d : figure_defs()) {
    char line[160];
    std::snprintf(line, sizeof line, "  %-5s %s\n", d.id, d.title);
    u += line;
  }
  return u + kUsageTail;
}

std::string index_md(const std::vector<BuiltFigure>& figures) {
  std::string md =
      "# The thesis's figures, from mixpilot's flights\n\n"
      "Rendered by `mixpilot figures` (" +
      std::string(version()) +
      ") from flights of the shipped scenarios, flown headless as `mixpilot fly --headless` "
      "flies them (SPEC §11). Each figure's data is beside it as CSV, its header naming each "
      "column with its unit.\n";
  for (const BuiltFigure& b : figures) {
    const std::string file = b.def->file;
    md += "\n## Fig. " + std::string(b.def->id) + " \u2014 " + b.def->title + "\n\n" + b.def->shows +
          "\n\n![Fig. " + b.def->id + ": " + b.def->title + "](" + file + ".png)\n\nData: [" + file +
          ".csv](" + file + ".csv) (" + std::to_string(b.table.rows.size()) + " rows)\n";
  }
  return md;
}

}  // namespace

int figures_command(int argc, char** argv) {
  std::string out;
  std::vector<const FigureDef*> chosen;
  bool force = false;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  int width = kFigureWidth;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(usage().c_str(), stdout);
      return kExitOk;
    } else if (a == "--out") {
      out = option_value("figures", argc, argv, i);
    } else if (a == "--only") {
      const std::string v = option_value("figures", argc, argv, i);
      std::size_t start = 0;
      while (start <= v.size()) {
        const std::size_t comma = std::min(v.find(',', start), v.size());
        const std::string id = v.substr(start, comma - start);
        if (id.empty()) usage_error("figures", "--only: an empty id in '" + v + "' (ids separated by commas: 7.5,7.9)");
        const FigureDef* d = find_figure(id);
        if (!d)
          usage_error("figures", "--only: no figure '" + id + "' (the figures: " + figure_ids() + ")");
        if (std::find(chosen.begin(), chosen.end(), d) == chosen.end()) chosen.push_back(d);
        start = comma + 1;
      }
    } else if (a == "--force") {
      force = true;
    } else if (a == "--jobs") {
      const std::string v = option_value("figures", argc, argv, i);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error("figures", "--jobs expects a whole number from 1 to 256, got '" + v + "'");
      jobs = int(n);
    } else if (a == "--width") {
      const std::string v = option_value("figures", argc, argv, i);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 600 || n > 7200)
        usage_error("figures", "--width expects a whole number of pixels from 600 to 7200, got '" + v + "'");
      width = int(n);
    } else if (a.size() > 1 && a[0] == '-') {
      usage_error("figures", "unknown option '" + std::string(a) + "'");
    } else {
      usage_error("figures", "unexpected argument '" + std::string(a) + "' (the folder is --out DIR)");
    }
  }
  if (out.empty()) usage_error("figures", "--out DIR is required");
  if (chosen.empty())
    for (const FigureDef& d : figure_defs()) chosen.push_back(&d);
  // In the thesis's order, whatever order --only gave (they point into figure_defs()).
  std::sort(chosen.begin(), chosen.end());

  std::string why;
  const std::string data = data_dir(&why);
  if (data.empty()) {
    std::fprintf(stderr, "mixpilot figures: %s\n", why.c_str());
    return kExitError;
  }
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
    std::fprintf(stderr, "mixpilot figures: --out %s: not a folder\n", out.c_str());
    return kExitError;
  }
  fs::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "mixpilot figures: --out %s: cannot make the folder: %s\n", out.c_str(),
                 ec.message().c_str());
    return kExitError;
  }
  // Every output is checked before anything flies: minutes of flights never end in a refusal.
  const auto path = [&](const std::string& name) { return (fs::path(out) / name).string(); };
  std::vector<std::string> outputs;
  for (const FigureDef* d : chosen) {
    outputs.push_back(path(std::string(d->file) + ".png"));
    outputs.push_back(path(std::string(d->file) + ".csv"));
  }
  outputs.push_back(path("index.md"));
  for (const std::string& p : outputs) {
    std::string error;
    if (!check_output_path(p, force, error)) {
      std::fprintf(stderr, "mixpilot figures: %s%s\n", error.c_str(),
                   force ? "" : " (--force replaces the outputs)");
      return kExitError;
    }
  }

  catch_interrupts();
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<BuiltFigure> figures;
  std::string error;
  if (!build_figures(chosen, FigureLength::thesis, jobs, data, figures, error, stderr)) {
    std::fprintf(stderr, "mixpilot figures: %s\n", error.c_str());
    return interrupted() ? kExitInterrupted : kExitError;
  }
  const auto t1 = std::chrono::steady_clock::now();
  int status = kExitOk;
  for (const BuiltFigure& b : figures) {
    if (interrupted()) return kExitInterrupted;
    const std::string png_path = path(std::string(b.def->file) + ".png");
    // The figure's own proportions and print scale, at `width` pixels across.
    const double zoom = double(width) / double(b.def->width);
    const int height = int(std::lround(zoom * b.def->height));
    std::fprintf(stderr, "mixpilot figures: rendering Fig. %s (%dx%d)\n", b.def->id, width, height);
    std::string png;
    if (!render_figure_png(b.figure, width, height, float(zoom) * kFigureScale, png, error) ||
        !write_file(png_path, png, force, error) ||
        !write_file(path(std::string(b.def->file) + ".csv"), b.table.csv(), force, error)) {
      std::fprintf(stderr, "mixpilot figures: Fig. %s: %s\n", b.def->id, error.c_str());
      status = kExitError;
      continue;
    }
    std::printf("  Fig. %-4s %s, %s.csv\n", b.def->id, png_path.c_str(), b.def->file);
  }
  if (!write_file(path("index.md"), index_md(figures), force, error)) {
    std::fprintf(stderr, "mixpilot figures: %s\n", error.c_str());
    status = kExitError;
  } else {
    std::printf("  index    %s\n", path("index.md").c_str());
  }
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("mixpilot figures: %zu figures in %s: flights %.1f s, rendering %.1f s\n",
              figures.size(), out.c_str(), std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count());
  return status;
}

}  // namespace mixpilot::cli
