#include "app/ghost.hpp"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>

#include "app/progress.hpp"
#include "core/base/content_hash.hpp"
#include "core/base/input_file.hpp"
#include "core/history/history.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot::cli {

std::optional<GhostTarget> ghost_target(const Flight& f, std::string& error) {
  const Mode& mode = *f.mode;
  if (mode.kind() != ModeKind::mixed_initiative) {
    error = "a ghost flies along a pilot's flight (mixed_initiative); " + mode.scenario_name() +
            " is " + to_string(mode.kind()) + ", flown by the thesis's controller";
    return std::nullopt;
  }
  GhostTarget t;
  t.scenario_name = mode.scenario_name();
  t.scenario_hash = sha256_hex(f.scenario_text);
  t.mode = mode.kind();
  t.dt = mode.dt();
  t.reference = mode.view().reference_at;
  if (!t.reference) {
    error = mode.scenario_name() + " has no reference to compare a ghost along";
    return std::nullopt;
  }
  return t;
}

std::shared_ptr<const ui::Ghost> load_ghost(const std::string& path, const GhostTarget& target,
                                            std::string label, std::string& error) {
  const std::optional<RecordingContents> rec = read_recording(path, error);
  if (!rec) return nullptr;
  const std::string* text = embedded_scenario(*rec, path, error);
  if (!text) return nullptr;
  const std::string flown = escape_controls(target.scenario_name);
  const auto meta = rec->metadata.find("mode");
  const std::string mode = meta == rec->metadata.end() ? "" : escape_controls(meta->second);
  if (mode != to_string(target.mode)) {
    error = path + ": a recording of a " + (mode.empty() ? "flight of no known mode" : mode) +
            " flight, not of " + flown + " (" + to_string(target.mode) +
            "): a ghost is a flight of the scenario flown";
    return nullptr;
  }
  if (const std::string hash = sha256_hex(*text); hash != target.scenario_hash) {
    std::string ignored;
    const std::optional<Scenario> sc =
        parse_scenario(*text, embedded_scenario_source(*rec, path), ignored);
    if (sc && sc->name != target.scenario_name)
      error = path + ": a recording of scenario '" + escape_controls(sc->name) + "', not of '" +
              flown + "': a ghost is a flight of the scenario flown";
    else
      error = path + ": a recording of another version of scenario '" + flown +
              "' (its text differs from the one flown: SHA-256 " + hash.substr(0, 12) +
              "..., not " + target.scenario_hash.substr(0, 12) +
              "...): a ghost is a flight of the scenario flown";
    return nullptr;
  }
  const double dt = double(rec->control_period_ns) * 1e-9;
  if (std::abs(dt - target.dt) > 1e-12) {
    error = path + ": recorded every " + std::to_string(dt) + " s, the flight steps every " +
            std::to_string(target.dt) + " s";
    return nullptr;
  }
  const std::vector<VehicleStateMsg>& states = rec->states;
  if (states.empty()) {
    error = path + ": no vehicle states recorded (/vehicle/state): nothing to fly along";
    return nullptr;
  }
  const std::size_t nx = states.front().x.size();
  const std::uint64_t first = states.front().step, last = states.back().step;
  for (std::size_t i = 0; i < states.size(); ++i) {
    if (states[i].x.size() != nx || nx < 3 ||
        (i > 0 && states[i].step <= states[i - 1].step)) {
      error = path + ": its vehicle states are not one state per step in order (at message " +
              std::to_string(i) + " of /vehicle/state)";
      return nullptr;
    }
  }
  // Steps a real-time recording dropped hold the state before them; a recording that lost more
  // steps than it kept is no flight to race.
  if (last - first >= 2 * std::uint64_t(states.size())) {
    error = path + ": it holds " + std::to_string(states.size()) + " of the steps " +
            std::to_string(first) + " to " + std::to_string(last) + ": too few to fly along";
    return nullptr;
  }
  auto g = std::make_shared<ui::Ghost>();
  g->path = path;
  g->label = label.empty() ? std::filesystem::path(path).filename().string() : std::move(label);
  g->scenario_hash = target.scenario_hash;
  g->dt = target.dt;
  g->first_step = std::int64_t(first);
  const auto k = Eigen::Index(last - first + 1);
  g->states.resize(Eigen::Index(nx), k);
  std::size_t next = 0;
  for (Eigen::Index j = 0; j < k; ++j) {
    if (next < states.size() && states[next].step == first + std::uint64_t(j)) {
      g->states.col(j) = Eigen::Map<const Eigen::VectorXd>(states[next].x.data(), Eigen::Index(nx));
      ++next;
    } else {
      g->states.col(j) = g->states.col(j - 1);  // dropped (the first step never is)
    }
  }
  g->progress.resize(std::size_t(k));
  for (Eigen::Index j = 0; j < k; ++j) {
    const double t = double(g->first_step + j) * g->dt;
    const std::optional<double> tau =
        reference_progress(target.reference, g->states.col(j).head<3>(), t);
    g->progress[std::size_t(j)] = tau ? *tau : std::numeric_limits<double>::quiet_NaN();
  }
  return g;
}

std::string ghost_label(const ui::ProgressFlight& f, bool best) {
  char text[96];
  std::snprintf(text, sizeof text, "%sattempt %d, skill %.1f%s", best ? "your best: " : "",
                f.attempt, f.skill, f.probe ? " (probe)" : "");
  return text;
}

std::optional<ui::ProgressFlight> best_ghost_flight(const std::string& location,
                                                    const std::string& trainee_name,
                                                    const GhostTarget& target, std::string& why) {
  std::string trainee = trainee_name.empty() ? history::login_name() : trainee_name;
  if (trainee.empty()) trainee = "unnamed";  // as a flight of an account without a name is kept
  const std::unique_ptr<history::HistoryStore> store = history::open_history(location, why);
  if (!store) return std::nullopt;
  history::Query q;
  q.trainee = trainee;
  q.scenario = target.scenario_name;
  std::vector<history::StoredFlight> rows;
  if (!store->query(q, rows, why)) return std::nullopt;
  const ui::ProgressView v = progress_view(rows, trainee, target.scenario_name);
  const int best = best_recorded(v, target.scenario_hash);
  if (best < 0) {
    why = escape_controls(trainee) + " has no flight of " + escape_controls(target.scenario_name) +
          " in the history (" + store->where() +
          ") with its recording on this disk: fly it recorded first";
    return std::nullopt;
  }
  return v.flights[std::size_t(best)];
}

GhostChoice GhostChoice::of(const std::string& option) {
  if (option.empty() || option == "best") return {Kind::best, ""};
  if (option == "off") return {Kind::off, ""};
  return {Kind::file, option};
}

GhostLoader::GhostLoader(std::string path, GhostTarget target, std::string label)
    : path_(std::move(path)),
      label_(std::move(label)),
      target_(std::move(target)),
      worker_([this] {
        ghost_ = load_ghost(path_, target_, label_, error_);
        done_.store(true, std::memory_order_release);
      }) {}

GhostLoader::~GhostLoader() {
  if (worker_.joinable()) worker_.join();
}

}  // namespace mixpilot::cli
