#pragma once
// The thesis's figures from flights of the shipped scenarios (SPEC §11, `mixpilot figures`).
// Each figure names the flights it is drawn from (a shipped scenario, maybe with keys set: the
// round trip, the predictor, the constraint form, the pilot), which fly headless through the
// flight assembly (app/flight_rig.hpp) as `fly --headless` flies them; from their telemetry
// and metrics it builds its data (a table, written as CSV) and its chart (ui/plot.hpp), which
// renders offscreen at print resolution.
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/modes/mode.hpp"
#include "core/scenario/scenario_keys.hpp"
#include "ui/plot.hpp"

namespace mixpilot::cli {

// One flight a figure is drawn from.
struct FigureFlight {
  std::string scenario;            // a shipped scenario: the data folder's scenarios/<scenario>
  std::vector<ScenarioKey> keys;   // the variant flown ({}: as shipped)
  std::string pilot;               // mixed initiative: the pilot profile ("" otherwise)
  std::optional<double> duration;  // [s] shorter than the scenario's (a test's variant)
  // Its computing times are data (RTI time): it flies alone, after the others, so no other
  // flight of the run competes for the cores while it is timed.
  bool timed = false;
  // The flight's identity: two figures naming the same flight share one.
  std::string key() const;
  // "tracking_smooth_step (plant.rtt = 0.012, controller.compensation = false)".
  std::string describe() const;
};

// A flight flown: what its figures read.
struct FlownFlight {
  FigureFlight flight;
  std::vector<Telemetry> steps;  // every step's telemetry, in order
  Metrics metrics;
  ModeView view;
  double dt = 0.0;        // [s] control period
  double duration = 0.0;  // [s] planned length
  bool lost = false;      // the vehicle was lost (the run ended early)
  double lost_at = -1.0;  // [s]
  double wall_s = 0.0;    // [s] how long it took to fly
  std::string error;      // why it did not fly ("" when it did)

  // The metric `name`, NaN when the mode has none.
  double metric(std::string_view name) const;
};

// A figure's data: a header of names with units ("t [s]"), rows of cells. Written as CSV.
struct FigureTable {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;

  void add(std::vector<std::string> cells) { rows.push_back(std::move(cells)); }
  std::string csv() const;
  // The column named `name` (with its unit), -1 when there is none.
  int column(std::string_view name) const;
  // Column `name`'s numbers (NaN where a cell is not one), in the rows whose column `where`
  // holds `is` (every row when `where` is empty).
  std::vector<double> numbers(std::string_view name, std::string_view where = {},
                              std::string_view is = {}) const;
};

// A number as a CSV cell: the shortest text that reads back to it ("nan" for NaN).
std::string cell(double v);

// Which flights a figure flies: the thesis's (what `mixpilot figures` renders), or shorter ones
// with the same behaviour, for tests.
enum class FigureLength { thesis, shortened };

struct FigureDef {
  const char* id;     // the thesis's number: "5.6"
  const char* file;   // DIR/<file>.png and .csv: "fig_5_6"
  const char* title;  // "Tracking error against the round-trip time"
  const char* shows;  // what it shows, for DIR/index.md
  int width, height;  // [px] of the PNG at print size (width = kFigureWidth)
  std::vector<FigureFlight> (*flights)(FigureLength length);
  // The figure and its data from its flights, given in the order flights() named them.
  void (*build)(const std::vector<const FlownFlight*>& flights, ui::Figure& figure,
                FigureTable& table);
};

// Every figure, in the thesis's order.
const std::vector<FigureDef>& figure_defs();
// The figure numbered `id`, or nullptr.
const FigureDef* find_figure(std::string_view id);
// "4.4, 5.3, 5.4, ...": the valid ids, for messages.
std::string figure_ids();

// Flies `flight` headless through the flight assembly, as `fly --headless` does (no
// recording, no history), stopping early when interrupted.
FlownFlight fly_figure_flight(const FigureFlight& flight, const std::string& data_dir);

struct BuiltFigure {
  const FigureDef* def = nullptr;
  ui::Figure figure;
  FigureTable table;
};

// Flies what `defs` need, each distinct flight once (on `jobs` threads; the timed ones alone
// afterwards, in order), then builds each figure. Progress (which flight is flying, how long
// each took) goes to `progress` when it is not null. False with the reason when a flight could
// not fly or the run was interrupted.
[[nodiscard]] bool build_figures(const std::vector<const FigureDef*>& defs, FigureLength length,
                                 int jobs, const std::string& data_dir,
                                 std::vector<BuiltFigure>& out, std::string& error,
                                 std::FILE* progress = nullptr);

// The print size: every figure is kFigureWidth pixels across (FigureDef::width), 300 dpi over
// a 15 cm column, and its text and lines drawn at the UI's display scale kFigureScale
// (15 px × 2.2 is 8 pt text there).
inline constexpr int kFigureWidth = 1800;
inline constexpr float kFigureScale = 2.2f;

// A figure rendered offscreen (EGL) at width × height and `scale`, as PNG bytes; false with
// the reason (no EGL).
[[nodiscard]] bool render_figure_png(const ui::Figure& figure, int width, int height, float scale,
                                     std::string& png, std::string& error);

}  // namespace mixpilot::cli
