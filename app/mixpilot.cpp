// mixpilot command-line entry point: headless flights, batch scoring, model checks.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/numerics/integrator_erk4.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/mi_mode.hpp"
#include "core/modes/mode.hpp"
#include "core/modes/report.hpp"
#include "core/modes/score.hpp"
#include "core/modes/session.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/numerics/version.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"

#ifndef MIXPILOT_SOURCE_DIR
#define MIXPILOT_SOURCE_DIR "."
#endif

namespace {

using namespace mixpilot;

constexpr const char* kUsage =
    "usage: mixpilot <command> [options]\n"
    "\n"
    "commands:\n"
    "  fly     run a session headless as fast as possible and print a summary\n"
    "  score   replay and score recorded sessions\n"
    "  demo    fly scenarios/mi_helix.toml with the emulated novice pilot and print its score\n"
    "  models  open-loop check of each dynamic model\n"
    "\n"
    "Run 'mixpilot <command> --help' for a command's options.\n"
    "  -h, --help      show this help\n"
    "  --version       print the version\n";

constexpr const char* kFlyUsage =
    "usage: mixpilot fly --scenario FILE --pilot PILOT --headless [options]\n"
    "\n"
    "Runs one session of the scenario as fast as possible and prints a short summary.\n"
    "\n"
    "  --scenario FILE    scenario file (TOML, docs/scenario-format.md); optional when PILOT is\n"
    "                     a recording, whose embedded scenario is then used. Its `mode` picks\n"
    "                     what flies: mixed_initiative (with a pilot) or a thesis controller\n"
    "  --pilot PILOT      novice | experienced | reckless | another profile of the scenario |\n"
    "                     RECORDING.mcap (replays its pilot commands); default: the scenario's\n"
    "                     (mixed_initiative only)\n"
    "  --headless         run without a window (required: this build has no GUI yet)\n"
    "  --duration S       fly S seconds instead of the scenario's duration\n"
    "  --record OUT.mcap  record the session (MCAP, ros2 profile; docs/recording-format.md):\n"
    "                     every mode's telemetry, plus the pilot's commands in mixed_initiative\n"
    "  --report OUT.json  write the score (mixed_initiative; fields: README, Scoring) or the\n"
    "                     mode's metrics as JSON\n";

constexpr const char* kScoreUsage =
    "usage: mixpilot score FILE.mcap... [--jobs N] [--json OUT]\n"
    "\n"
    "Flies each recording again through a fresh session of its embedded scenario and checks the\n"
    "replayed states against the recorded ones bit for bit: mixed_initiative recordings replay\n"
    "their pilot commands and are scored (the timing fields come from the recorded solver\n"
    "statistics: they describe that flight); other modes are flown for the recorded number of\n"
    "steps and give their metrics (timing fields from this run). Progress on stderr, a table on\n"
    "stdout.\n"
    "\n"
    "  --jobs N     replay N recordings in parallel (default: the number of cores)\n"
    "  --json OUT   write a JSON array with one object per recording\n";

[[noreturn]] void usage_error(const char* cmd, const std::string& message) {
  std::fprintf(stderr, "mixpilot %s: %s (see 'mixpilot %s --help')\n", cmd, message.c_str(), cmd);
  std::exit(2);
}

// Where a recording's embedded scenario came from: its original file (absolute, as recorded),
// so that paths inside it (reference trajectories) resolve as they did; else a label.
std::string embedded_scenario_source(const RecordingContents& rec, const std::string& path) {
  const auto it = rec.metadata.find("scenario_path");
  if (it != rec.metadata.end() && !it->second.empty() && it->second.front() == '/')
    return it->second;
  return path + " (embedded scenario)";
}

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

bool write_file(const std::string& path, const std::string& text, std::string& error) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f || !(f << text) || !f.flush()) {
      error = path + ": cannot write";
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    error = path + ": cannot rename " + tmp + " into place";
    return false;
  }
  return true;
}

struct FlyOptions {
  std::string scenario_path;
  std::string pilot;
  bool headless = false;
  std::optional<double> duration;
  std::string record;
  std::string report;
};

// The flight of FlyOptions, set up: the scenario from --scenario or the recording given as
// --pilot, and the mode it names.
struct Flight {
  std::string scenario_text;
  std::string scenario_source;  // for messages and relative paths
  std::string scenario_file;    // the scenario's file, absolute (recorded as scenario_path)
  std::unique_ptr<Mode> mode;
  std::string pilot;  // mixed initiative: the pilot source's name
};

std::optional<Flight> prepare_flight(const FlyOptions& o, std::string& error) {
  Flight f;
  std::optional<RecordingContents> recording;
  if (ends_with(o.pilot, ".mcap")) {
    recording = read_recording(o.pilot, error);
    if (!recording) return std::nullopt;
  }
  if (!o.scenario_path.empty()) {
    if (!read_text_file(o.scenario_path, f.scenario_text, error)) return std::nullopt;
    f.scenario_source = o.scenario_path;
    f.scenario_file = std::filesystem::absolute(o.scenario_path).lexically_normal().string();
  } else if (recording) {
    f.scenario_text = recording->metadata["scenario"];
    f.scenario_source = embedded_scenario_source(*recording, o.pilot);
    f.scenario_file = recording->metadata["scenario_path"];
  } else {
    usage_error("fly", "--scenario FILE is required");
  }
  const auto kind_name = scenario_mode(f.scenario_text, f.scenario_source, error);
  if (!kind_name) return std::nullopt;
  if (*kind_name != "mixed_initiative" && !o.pilot.empty())
    usage_error("fly", "--pilot is for mixed_initiative scenarios, " + f.scenario_source +
                           " is " + *kind_name);
  ModeRequest request;
  request.duration = o.duration;
  if (recording) {
    request.pilot_source = std::make_unique<ReplayPilot>(recording->pilot, "replay:" + o.pilot);
  } else {
    request.pilot_name = o.pilot;
  }
  f.mode = make_mode(f.scenario_text, f.scenario_source, std::move(request), error);
  if (!f.mode) return std::nullopt;
  if (const auto* mi = dynamic_cast<const MiMode*>(f.mode.get())) f.pilot = mi->pilot().name();
  return f;
}

SessionInfo session_info(const Flight& f) {
  SessionInfo info;
  info.mode = to_string(f.mode->kind());
  info.scenario = f.scenario_text;
  info.scenario_path = f.scenario_file;
  info.pilot = f.pilot;
  if (const auto* mi = dynamic_cast<const MiMode*>(f.mode.get()))
    info.seed = mi->scenario().plant.seed;
  return info;
}

Labels report_labels(const Flight& f) {
  Labels labels = {{"mode", to_string(f.mode->kind())}, {"scenario", f.mode->scenario_name()}};
  if (!f.pilot.empty()) labels.emplace_back("pilot", f.pilot);
  return labels;
}

int run_fly(const FlyOptions& o) {
  std::string error;
  std::optional<Flight> flight = prepare_flight(o, error);
  if (!flight) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    return 1;
  }
  Mode& mode = *flight->mode;
  Session session(mode);
  RecordingSink recorder;
  if (!o.record.empty()) {
    if (!recorder.open(o.record, mode, session_info(*flight), error)) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
    session.add_sink(&recorder);
  }

  const auto t0 = std::chrono::steady_clock::now();
  session.run();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  int status = 0;
  if (!o.record.empty() && !recorder.close(error)) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    status = 1;
  }
  std::fputs(mode.summary().c_str(), stdout);
  const double flown = double(mode.steps_done()) * mode.dt();
  std::printf("  %.1f s flown in %.2f s of wall time (%.0fx real time)\n", flown, wall,
              flown / std::max(wall, 1e-9));
  if (!o.report.empty()) {
    const std::string json = to_json(report_labels(*flight), mode.metrics()) + "\n";
    if (!write_file(o.report, json, error)) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      status = 1;
    }
  }
  if (!o.record.empty() && status == 0) std::printf("  recorded %s\n", o.record.c_str());
  if (!o.report.empty() && status == 0) std::printf("  report %s\n", o.report.c_str());
  return status;
}

int fly_command(int argc, char** argv) {
  FlyOptions o;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage_error("fly", std::string(a) + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kFlyUsage, stdout);
      return 0;
    } else if (a == "--scenario") {
      o.scenario_path = value();
    } else if (a == "--pilot") {
      o.pilot = value();
    } else if (a == "--headless") {
      o.headless = true;
    } else if (a == "--duration") {
      const std::string v = value();
      char* end = nullptr;
      const double d = std::strtod(v.c_str(), &end);
      if (end == v.c_str() || *end != '\0' || !(d > 0.0) || !std::isfinite(d))
        usage_error("fly", "--duration expects a positive number of seconds, got '" + v + "'");
      o.duration = d;
    } else if (a == "--record") {
      o.record = value();
    } else if (a == "--report") {
      o.report = value();
    } else {
      usage_error("fly", "unknown option '" + std::string(a) + "'");
    }
  }
  if (!o.headless) usage_error("fly", "this build has no GUI yet: pass --headless");
  return run_fly(o);
}

struct ScoreRow {
  std::string file;
  std::string mode;
  std::string pilot;
  std::string scenario;
  Metrics metrics;
  Score score;  // mixed initiative
  bool ok = false;
  bool matches = false;  // replayed states equal the recorded ones bit for bit
  std::string error;
};

// Compares each replayed state with the recorded one as the session goes.
struct StateCompare final : TelemetrySink {
  const std::vector<VehicleStateMsg>* states = nullptr;
  bool matches = true;
  void on_sample(const Telemetry& s) override {
    const auto k = std::size_t(s.step);
    if (k >= states->size() || (*states)[k].x.size() != std::size_t(s.x.size()) ||
        !std::equal(s.x.data(), s.x.data() + s.x.size(), (*states)[k].x.begin()))
      matches = false;
  }
};

// A fresh flight of the recording's embedded scenario: mixed initiative replays the recorded
// pilot commands (and is as long as they are), other modes fly on their own for as many
// steps as were recorded.
std::unique_ptr<Mode> replay_mode(const RecordingContents& rec, const std::string& path,
                                  const std::string& text, std::string& error) {
  const std::string source = embedded_scenario_source(rec, path);
  const auto kind = scenario_mode(text, source, error);
  if (!kind) return nullptr;
  ModeRequest request;
  if (*kind == "mixed_initiative") {
    const auto scenario = parse_scenario(text, source, error);
    if (!scenario) return nullptr;
    request.duration = double(rec.pilot.size()) * scenario->controller.dt;
    request.pilot_source = std::make_unique<ReplayPilot>(rec.pilot, "replay:" + path);
    return make_mode(text, source, std::move(request), error);
  }
  auto mode = make_mode(text, source, ModeRequest{}, error);
  if (mode && std::int64_t(rec.states.size()) < mode->steps_total())  // an interrupted run
    mode = make_mode(text, source, ModeRequest{double(rec.states.size()) * mode->dt(), {}, {}},
                     error);
  return mode;
}

ScoreRow score_recording(const std::string& path) {
  ScoreRow row;
  row.file = path;
  std::string error;
  const auto rec = read_recording(path, error);
  if (!rec) {
    row.error = error;
    return row;
  }
  const auto meta = rec->metadata.find("scenario");
  if (meta == rec->metadata.end()) {
    row.error = path + ": no embedded scenario in the 'mixpilot' metadata record";
    return row;
  }
  std::unique_ptr<Mode> mode = replay_mode(*rec, path, meta->second, error);
  if (!mode) {
    row.error = error;
    return row;
  }
  const auto pilot_meta = rec->metadata.find("pilot");
  row.pilot = pilot_meta != rec->metadata.end() ? pilot_meta->second : "";
  row.mode = to_string(mode->kind());
  row.scenario = mode->scenario_name();
  Session session(*mode);
  StateCompare compare;
  compare.states = &rec->states;
  session.add_sink(&compare);
  session.run();
  row.metrics = mode->metrics();
  if (const auto* mi = dynamic_cast<const MiMode*>(mode.get())) {
    // The timing fields describe the recorded flight, not this replay.
    row.score = mi->score();
    std::vector<double> recorded_us;
    recorded_us.reserve(rec->solver.size());
    for (const auto& m : rec->solver) recorded_us.push_back(m.total_us);
    set_timing(row.score, std::move(recorded_us), mode->dt());
    row.metrics = to_metrics(row.score);
  }
  row.matches = compare.matches && rec->states.size() == std::size_t(mode->steps_done());
  row.ok = true;
  return row;
}

int score_command(int argc, char** argv) {
  std::vector<std::string> files;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  std::string json_path;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kScoreUsage, stdout);
      return 0;
    } else if (a == "--jobs") {
      if (i + 1 >= argc) usage_error("score", "--jobs needs a value");
      const std::string v = argv[++i];
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error("score", "--jobs expects a whole number from 1 to 256, got '" + v + "'");
      jobs = int(n);
    } else if (a == "--json") {
      if (i + 1 >= argc) usage_error("score", "--json needs a value");
      json_path = argv[++i];
    } else if (a.size() > 1 && a[0] == '-') {
      usage_error("score", "unknown option '" + std::string(a) + "'");
    } else {
      files.emplace_back(a);
    }
  }
  if (files.empty()) usage_error("score", "no recordings given");

  std::vector<ScoreRow> rows(files.size());
  std::atomic<std::size_t> next{0};
  std::atomic<std::size_t> done{0};
  std::mutex io;
  const auto worker = [&] {
    for (std::size_t i = next++; i < files.size(); i = next++) {
      rows[i] = score_recording(files[i]);
      const std::size_t d = ++done;
      const std::lock_guard<std::mutex> lock(io);
      if (rows[i].ok && rows[i].mode == "mixed_initiative") {
        std::fprintf(stderr, "[%zu/%zu] %s: skill %.1f\n", d, files.size(), files[i].c_str(),
                     rows[i].score.skill);
      } else if (rows[i].ok) {
        std::fprintf(stderr, "[%zu/%zu] %s: %s\n", d, files.size(), files[i].c_str(),
                     rows[i].mode.c_str());
      } else {
        std::fprintf(stderr, "[%zu/%zu] %s\n", d, files.size(), rows[i].error.c_str());
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < std::min<int>(jobs, int(files.size())); ++j) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  std::printf("%-32s %-12s %8s %7s %7s %8s %5s %6s %7s %s\n", "recording", "pilot", "time_s",
              "lambda", "min_l", "maxdev_m", "coll", "fallb", "skill", "replay");
  int failures = 0;
  std::string json = "[\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const ScoreRow& r = rows[i];
    if (!r.ok) {
      ++failures;
      std::printf("%-32s error: %s\n", r.file.c_str(), r.error.c_str());
      continue;
    }
    const Score& s = r.score;
    const char* replay = r.matches ? "exact" : "DIFFERS from recording";
    if (r.mode == "mixed_initiative") {
      std::printf("%-32s %-12s %8.1f %7.3f %7.3f %8.3f %5d %6lld %7.1f %s\n", r.file.c_str(),
                  r.pilot.c_str(), s.duration_s, s.mean_lambda, s.min_lambda, s.max_deviation_m,
                  s.collisions, static_cast<long long>(s.fallbacks), s.skill, replay);
    } else {  // the other modes' metrics are in the JSON
      std::printf("%-32s %-12.12s %8s %7s %7s %8s %5s %6s %7s %s\n", r.file.c_str(),
                  r.mode.c_str(), "-", "-", "-", "-", "-", "-", "-", replay);
    }
    if (json.size() > 2) json += ",\n";
    Labels labels = {{"file", r.file}, {"mode", r.mode}, {"scenario", r.scenario}};
    if (!r.pilot.empty()) labels.emplace_back("pilot", r.pilot);
    labels.emplace_back("replay", r.matches ? "exact" : "differs");
    json += to_json(labels, r.metrics);
  }
  json += "\n]\n";
  if (!json_path.empty()) {
    std::string error;
    if (!write_file(json_path, json, error)) {
      std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
      return 1;
    }
  }
  return failures > 0 ? 1 : 0;
}

// Open-loop simulation of `seconds` of the model from x0 under constant u with ERK4 at dt.
template <class M>
typename M::State simulate(const M& model, typename M::State x, const typename M::Input& u,
                           double dt, double seconds) {
  const IntegratorErk4<M> erk4(model);
  const int steps = static_cast<int>(std::lround(seconds / dt));
  for (int k = 0; k < steps; ++k) {
    typename M::State xn;
    erk4.step(x, u, dt, xn);
    x = xn;
  }
  return x;
}

int models_command() {
  std::printf("%s: headless model check (open loop, ERK4)\n\n", version());
  std::printf("%-12s %-44s %s\n", "model", "experiment", "result");
  {
    const models::Pendubot pb;
    const models::Pendubot::State x0(-std::acos(-1.0) + 1.2, 0.8, 0.0, 0.0);
    const auto x = simulate(pb, x0, models::Pendubot::Input::Zero().eval(), 1e-3, 10.0);
    std::printf("%-12s %-44s energy drift %.1e (relative)\n", "pendubot",
                "free swing from rest, u = 0, 10 s @ 1 ms",
                std::abs(pb.energy(x) - pb.energy(x0)) / pb.energy(x0));
  }
  {
    const models::Crazyflie cf;
    const auto x0 = cf.hover_state({0.0, 0.0, 0.4});
    const auto x = simulate(cf, x0, cf.hover_input(), 0.015, 10.0);
    std::printf("%-12s %-44s drift %.1e m, |q| - 1 = %.0e\n", "crazyflie",
                "hover at 15.78 krpm, 10 s @ 15 ms", (x - x0).head<3>().norm(),
                x.segment<4>(3).norm() - 1.0);
  }
  {
    const models::MikroKopter mk;
    const auto x0 = mk.hover_state({0.0, 0.0, 1.0});
    const auto x = simulate(mk, x0, mk.hover_input(), 0.015, 10.0);
    std::printf("%-12s %-44s drift %.1e m, rotors at %.4f\n", "mikrokopter",
                "hover torque 0.0756 N m, 10 s @ 15 ms", (x - x0).head<3>().norm(), x(12));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const std::string_view cmd = argv[1];
  if (cmd == "-h" || cmd == "--help" || cmd == "help") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (cmd == "--version") {
    std::printf("%s\n", version());
    return 0;
  }
  if (cmd == "fly") return fly_command(argc, argv);
  if (cmd == "score") return score_command(argc, argv);
  if (cmd == "demo" || cmd == "models") {
    if (argc > 2) {
      if (std::strcmp(argv[2], "--help") == 0 || std::strcmp(argv[2], "-h") == 0) {
        std::fputs(kUsage, stdout);
        return 0;
      }
      std::fprintf(stderr, "mixpilot %s: unexpected argument '%s'\n", argv[1], argv[2]);
      return 2;
    }
    if (cmd == "models") return models_command();
    FlyOptions o;
    o.scenario_path = MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml";
    o.pilot = "novice";
    o.headless = true;
    return run_fly(o);
  }
  std::fprintf(stderr, "mixpilot: unknown command '%s' (see 'mixpilot --help')\n", argv[1]);
  return 2;
}
