// The flights of the thesis's figures (app/figures.hpp): flown through the flight assembly,
// scheduled on threads, and the figures' tables and rendering.
#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "app/cli.hpp"
#include "app/figures.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "ui/theme.hpp"

#include <stb/stb_image_write.h>  // implemented in Debian's libstb, which ImGui links

namespace mixpilot::cli {

std::string FigureFlight::key() const {
  std::string k = scenario + "|" + pilot + "|";
  for (const ScenarioKey& s : keys) k += s.key + "=" + s.value + ";";
  if (duration) k += "|" + cell(*duration);
  return k;
}

std::string FigureFlight::describe() const {
  std::string d = scenario.substr(0, scenario.rfind(".toml"));
  std::string extra = describe_keys(keys);
  if (!pilot.empty()) extra = "pilot " + pilot + (extra.empty() ? "" : ", " + extra);
  if (duration) extra += (extra.empty() ? "" : ", ") + cell(*duration) + " s";
  return extra.empty() ? d : d + " (" + extra + ")";
}

double FlownFlight::metric(std::string_view name) const {
  for (const auto& [k, v] : metrics)
    if (k == name) return v;
  return std::numeric_limits<double>::quiet_NaN();
}

std::string cell(double v) {
  if (std::isnan(v)) return "nan";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string FigureTable::csv() const {
  const auto row = [](const std::vector<std::string>& cells) {
    std::string line;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      const std::string& c = cells[i];
      if (i > 0) line += ',';
      if (c.find_first_of(",\"\n") == std::string::npos) {
        line += c;
      } else {  // RFC 4180 quoting
        line += '"';
        for (const char ch : c) line += ch == '"' ? std::string("\"\"") : std::string(1, ch);
        line += '"';
      }
    }
    return line + "\n";
  };
  std::string out = row(header);
  for (const auto& r : rows) out += row(r);
  return out;
}

int FigureTable::column(std::string_view name) const {
  for (std::size_t i = 0; i < header.size(); ++i)
    if (header[i] == name) return int(i);
  return -1;
}

std::vector<double> FigureTable::numbers(std::string_view name, std::string_view where,
                                         std::string_view is) const {
  std::vector<double> out;
  const int c = column(name), w = where.empty() ? -1 : column(where);
  if (c < 0 || (!where.empty() && w < 0)) return out;
  for (const auto& r : rows) {
    if (w >= 0 && (std::size_t(w) >= r.size() || r[std::size_t(w)] != is)) continue;
    const std::string& s = std::size_t(c) < r.size() ? r[std::size_t(c)] : std::string();
    char* end = nullptr;
    const double v = std::strtod(s.c_str(), &end);
    out.push_back(end != s.c_str() && *end == '\0' ? v : std::numeric_limits<double>::quiet_NaN());
  }
  return out;
}

namespace {

// Keeps every step's telemetry (on the stepping thread: this is no real-time flight).
class KeepSteps final : public TelemetrySink {
 public:
  explicit KeepSteps(std::vector<Telemetry>& steps) : steps_(&steps) {}
  void on_sample(const Telemetry& s) override { steps_->push_back(s); }

 private:
  std::vector<Telemetry>* steps_;
};

}  // namespace

FlownFlight fly_figure_flight(const FigureFlight& flight, const std::string& data_dir) {
  FlownFlight out;
  out.flight = flight;
  FlyOptions o;
  o.scenario_path = data_dir + "/scenarios/" + flight.scenario;
  if (!flight.keys.empty()) {
    // The variant: the shipped file with its keys set, flown as that text.
    std::string text;
    std::optional<std::string> variant;
    if (read_text_file(o.scenario_path, text, out.error))
      variant = set_scenario_keys(text, o.scenario_path, flight.keys, out.error);
    if (!variant) {
      out.error = flight.describe() + ": " + out.error;
      return out;
    }
    o.scenario_text = std::move(*variant);
  }
  o.pilot = flight.pilot;
  o.headless = true;
  o.duration = flight.duration;
  o.history = "off";
  o.command = "figures";
  int status = kExitOk;
  const auto t0 = std::chrono::steady_clock::now();
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, out.error, status);
  if (!rig) {
    out.error = flight.describe() + ": " + out.error;
    return out;
  }
  out.steps.reserve(std::size_t(rig->mode().steps_total()));
  KeepSteps keep(out.steps);
  rig->watch(keep);
  rig->start();
  while (!interrupted() && rig->step()) {
  }
  const bool stopped = interrupted() && !rig->mode().finished();
  (void)rig->close(stopped);
  if (stopped) out.error = flight.describe() + ": interrupted";
  const Mode& mode = rig->mode();
  out.metrics = rig->metrics();
  out.view = mode.view();
  out.dt = mode.dt();
  out.duration = double(mode.steps_total()) * mode.dt();
  out.lost = mode.lost();
  out.lost_at = mode.lost_at();
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

bool build_figures(const std::vector<const FigureDef*>& defs, FigureLength length, int jobs,
                   const std::string& data_dir, std::vector<BuiltFigure>& out, std::string& error,
                   std::FILE* progress) {
  // Each distinct flight once, in the order the figures name them.
  std::vector<FigureFlight> flights;
  std::map<std::string, std::size_t> index;
  std::vector<std::vector<std::size_t>> uses(defs.size());
  for (std::size_t d = 0; d < defs.size(); ++d) {
    for (const FigureFlight& f : defs[d]->flights(length)) {
      const auto [it, added] = index.emplace(f.key(), flights.size());
      if (added) {
        flights.push_back(f);
      } else {
        flights[it->second].timed |= f.timed;
      }
      uses[d].push_back(it->second);
    }
  }
  std::vector<FlownFlight> flown(flights.size());
  std::mutex io;
  std::atomic<std::size_t> done{0};
  const std::size_t total = flights.size();
  const auto fly = [&](std::size_t i) {
    if (progress) {
      const std::lock_guard<std::mutex> lock(io);
      std::fprintf(progress, "mixpilot figures: flying %s%s\n", flights[i].describe().c_str(),
                   flights[i].timed ? " (alone: its RTI times are data)" : "");
    }
    flown[i] = fly_figure_flight(flights[i], data_dir);
    const std::size_t d = ++done;
    if (progress) {
      const std::lock_guard<std::mutex> lock(io);
      const FlownFlight& f = flown[i];
      if (f.error.empty())
        std::fprintf(progress, "mixpilot figures: [%zu/%zu] %s: %.1f s flown in %.1f s%s\n", d,
                     total, flights[i].describe().c_str(), double(f.steps.size()) * f.dt, f.wall_s,
                     f.lost ? " (vehicle lost)" : "");
    }
  };
  // The untimed flights on `jobs` threads, each taking the next; then the timed ones alone.
  std::vector<std::size_t> parallel, alone;
  for (std::size_t i = 0; i < flights.size(); ++i) (flights[i].timed ? alone : parallel).push_back(i);
  std::atomic<std::size_t> next{0};
  const auto worker = [&] {
    for (std::size_t k = next++; k < parallel.size() && !interrupted(); k = next++) fly(parallel[k]);
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < std::min<int>(std::max(jobs, 1), int(parallel.size())); ++j)
    pool.emplace_back(worker);
  for (std::thread& t : pool) t.join();
  for (const std::size_t i : alone) {
    if (interrupted()) break;
    fly(i);
  }
  if (interrupted()) {
    error = "interrupted";
    return false;
  }
  for (const FlownFlight& f : flown) {
    if (!f.error.empty()) {
      error = f.error;
      return false;
    }
  }
  out.clear();
  for (std::size_t d = 0; d < defs.size(); ++d) {
    std::vector<const FlownFlight*> mine;
    for (const std::size_t i : uses[d]) mine.push_back(&flown[i]);
    BuiltFigure b;
    b.def = defs[d];
    defs[d]->build(mine, b.figure, b.table);
    out.push_back(std::move(b));
  }
  return true;
}

bool render_figure_png(const ui::Figure& figure, int width, int height, float scale,
                       std::string& png, std::string& error) {
  Offscreen screen;
  if (!screen.open(width, height, error, scale)) return false;
  (void)ui::add_heading_font(scale, 1.3f);
  // Two frames: ImGui settles a new window's layout in its first.
  for (int f = 0; f < 2; ++f) screen.frame([&] { ui::draw_figure(figure); });
  // The page is opaque: RGB, a quarter smaller than the RGBA of a screenshot.
  const std::vector<std::uint8_t> rgba = screen.pixels();
  std::vector<std::uint8_t> rgb(std::size_t(width) * std::size_t(height) * 3);
  for (std::size_t i = 0, n = std::size_t(width) * std::size_t(height); i < n; ++i)
    std::copy_n(rgba.data() + 4 * i, 3, rgb.data() + 3 * i);
  png.clear();
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
      },
      &png, width, height, 3, rgb.data(), width * 3);
  if (png.empty()) {
    error = "the PNG could not be encoded";
    return false;
  }
  return true;
}

}  // namespace mixpilot::cli
