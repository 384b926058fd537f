// mixpilot command-line entry point: headless flights, batch scoring, model checks.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/numerics/integrator_erk4.hpp"
#include "core/modes/mode.hpp"
#include "core/control/pilot_emulated.hpp"
#include "core/recording/recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/modes/score.hpp"
#include "core/modes/session.hpp"
#include "core/recording/session_recording.hpp"
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
    "  --record OUT.mcap  record the session (MCAP, ros2 profile; docs/recording-format.md;\n"
    "                     mixed_initiative only)\n"
    "  --report OUT.json  write the score (mixed_initiative; fields: README, Scoring) or the\n"
    "                     mode's metrics as JSON\n";

constexpr const char* kScoreUsage =
    "usage: mixpilot score FILE.mcap... [--jobs N] [--json OUT]\n"
    "\n"
    "Replays each recording's pilot commands through a fresh session of its embedded scenario\n"
    "and scores it: progress on stderr, a table on stdout. The timing fields come from the\n"
    "recorded solver statistics (they describe that flight); every other field is recomputed\n"
    "and a replay whose states differ from the recorded ones is flagged.\n"
    "\n"
    "  --jobs N     replay N recordings in parallel (default: the number of cores)\n"
    "  --json OUT   write a JSON array with one object per recording\n";

[[noreturn]] void usage_error(const char* cmd, const std::string& message) {
  std::fprintf(stderr, "mixpilot %s: %s (see 'mixpilot %s --help')\n", cmd, message.c_str(), cmd);
  std::exit(2);
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

// A pilot source by name: a profile of the scenario, "reckless", or a recording to replay.
std::unique_ptr<PilotSource> make_pilot(const Scenario& scenario, const std::string& name,
                                        const std::optional<RecordingContents>& recording,
                                        std::string& error) {
  const models::MikroKopter model;
  if (recording) {
    return std::make_unique<ReplayPilot>(recording->pilot, "replay:" + name);
  }
  if (name == "reckless") {
    const auto it = scenario.pilots.find("reckless");
    const double tilt = it != scenario.pilots.end() ? it->second.max_tilt : PilotProfile{}.max_tilt;
    return std::make_unique<RecklessPilot>(model, scenario.arena, tilt);
  }
  const auto it = scenario.pilots.find(name);
  if (it == scenario.pilots.end()) {
    error = "unknown pilot '" + name + "': the scenario defines";
    for (const auto& [profile, _] : scenario.pilots) error += " " + profile;
    error += ", plus reckless and RECORDING.mcap";
    return nullptr;
  }
  auto pilot = std::make_unique<EmulatedPilot>();
  PilotProfile profile = it->second;
  profile.name = name;
  if (!pilot->setup(model, profile, scenario.reference, scenario.controller.dt)) {
    error = "pilot profile '" + name + "' does not form a valid OCP";
    return nullptr;
  }
  return pilot;
}

struct FlyOptions {
  std::string scenario_path;
  std::string pilot;
  bool headless = false;
  std::optional<double> duration;
  std::string record;
  std::string report;
};

void print_summary(const Scenario& sc, const std::string& pilot, const Score& s, double wall,
                   bool lost) {
  std::printf("mixpilot fly: %s, pilot %s\n", sc.name.c_str(), pilot.c_str());
  std::printf("  flew %.1f s in %.2f s (%.0fx real time); RTI median %.0f us, p99 %.0f us, "
              "%d deadline misses, %lld fallbacks\n",
              s.duration_s, wall, s.duration_s / std::max(wall, 1e-9), s.rti_median_us,
              s.rti_p99_us, s.deadline_misses, static_cast<long long>(s.fallbacks));
  std::printf("  lambda mean %.3f (min %.3f); deviation max %.3f m, rms %.3f m; in ball %.1f%%; "
              "progress %.1f%%\n",
              s.mean_lambda, s.min_lambda, s.max_deviation_m, s.rms_deviation_m,
              100.0 * s.time_in_ball, 100.0 * s.progress);
  std::printf("  collisions %d; min clearance %.3f m; override %.4f rad rms; skill %.1f / 100\n",
              s.collisions, s.min_clearance_m, s.override_rms, s.skill);
  if (lost) std::printf("  the vehicle was lost: the plant state stopped being finite\n");
}

// Modes other than mixed_initiative fly on their own (core/modes/mode.hpp).
int run_mode(const std::string& mode, const FlyOptions& o) {
  const ModeRunner runner = find_mode_runner(mode);
  if (!runner) {
    std::string known = "mixed_initiative";
    for (const auto& m : mode_runner_names()) known += ", " + m;
    std::fprintf(stderr, "mixpilot fly: %s: mode \"%s\" has no runner (known: %s)\n",
                 o.scenario_path.c_str(), mode.c_str(), known.c_str());
    return 1;
  }
  if (!o.pilot.empty()) usage_error("fly", "--pilot is for mixed_initiative scenarios");
  if (!o.record.empty()) usage_error("fly", "--record is for mixed_initiative scenarios");
  ModeOptions options;
  options.duration = o.duration;
  const ModeResult r = runner(o.scenario_path, options);
  if (!r.ok) {
    std::fprintf(stderr, "mixpilot fly: %s\n", r.error.c_str());
    return 1;
  }
  std::fputs(r.summary.c_str(), stdout);
  if (!r.summary.empty() && r.summary.back() != '\n') std::fputc('\n', stdout);
  if (!o.report.empty()) {
    std::string json = "{\n  \"mode\": \"" + mode + "\"";
    char buf[160];
    for (const auto& [name, value] : r.metrics) {
      std::snprintf(buf, sizeof buf, ",\n  \"%s\": %.17g", name.c_str(), value);
      json += buf;
    }
    json += "\n}\n";
    std::string error;
    if (!write_file(o.report, json, error)) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
    std::printf("  report %s\n", o.report.c_str());
  }
  return 0;
}

int run_fly(const FlyOptions& o) {
  std::string error;
  if (!o.scenario_path.empty()) {
    std::string text;
    if (!read_text_file(o.scenario_path, text, error)) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
    const auto mode = scenario_mode(text, o.scenario_path, error);
    if (!mode) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
    if (*mode != "mixed_initiative") return run_mode(*mode, o);
  }
  std::optional<RecordingContents> recording;
  if (ends_with(o.pilot, ".mcap")) {
    recording = read_recording(o.pilot, error);
    if (!recording) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
  }
  std::optional<Scenario> scenario;
  if (!o.scenario_path.empty()) {
    scenario = load_scenario(o.scenario_path, error);
  } else if (recording) {
    scenario = parse_scenario(recording->metadata["scenario"],
                              o.pilot + " (embedded scenario)", error);
  } else {
    usage_error("fly", "--scenario FILE is required");
  }
  if (!scenario) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    return 1;
  }
  if (o.duration) scenario->duration = *o.duration;
  const std::string pilot_name = o.pilot.empty() ? scenario->default_pilot : o.pilot;
  auto pilot = make_pilot(*scenario, pilot_name, recording, error);
  if (!pilot) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    return 1;
  }

  Session session;
  if (!session.setup(*scenario, *pilot, error)) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    return 1;
  }
  ScoreAccumulator score(*scenario);
  session.add_sink(&score);
  RecordingSink recorder;
  if (!o.record.empty()) {
    if (!recorder.open(o.record, *scenario, pilot->name(), error)) {
      std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
      return 1;
    }
    session.add_sink(&recorder);
  }

  const auto t0 = std::chrono::steady_clock::now();
  session.run();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const Score s = score.finish();

  int status = 0;
  if (!o.record.empty() && !recorder.close(error)) {
    std::fprintf(stderr, "mixpilot fly: %s\n", error.c_str());
    status = 1;
  }
  print_summary(*scenario, pilot->name(), s, wall, session.lost());
  if (!o.report.empty()) {
    const std::string json =
        to_json(s, {{"scenario", scenario->name}, {"pilot", pilot->name()}}) + "\n";
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
  std::string pilot;
  std::string scenario;
  Score score;
  bool ok = false;
  bool matches = false;  // replayed states equal the recorded ones bit for bit
  std::string error;
};

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
  auto scenario = parse_scenario(meta->second, path + " (embedded scenario)", error);
  if (!scenario) {
    row.error = error;
    return row;
  }
  scenario->duration = double(rec->pilot.size()) * scenario->controller.dt;
  const auto pilot_meta = rec->metadata.find("pilot");
  row.pilot = pilot_meta != rec->metadata.end() ? pilot_meta->second : "?";
  row.scenario = scenario->name;
  ReplayPilot pilot(rec->pilot, "replay:" + path);
  Session session;
  if (!session.setup(*scenario, pilot, error)) {
    row.error = path + ": " + error;
    return row;
  }
  ScoreAccumulator acc(*scenario);
  session.add_sink(&acc);
  // Compare each replayed state with the recorded one as the session goes.
  struct Compare final : TelemetrySink {
    const std::vector<VehicleStateMsg>* states;
    bool matches = true;
    void on_sample(const TelemetrySample& s) override {
      const auto k = std::size_t(s.step);
      if (k >= states->size() || (*states)[k].x.size() != std::size_t(s.x.size()) ||
          !std::equal(s.x.data(), s.x.data() + s.x.size(), (*states)[k].x.begin()))
        matches = false;
    }
  } compare;
  compare.states = &rec->states;
  session.add_sink(&compare);
  session.run();
  row.score = acc.finish();
  std::vector<double> recorded_us;
  recorded_us.reserve(rec->solver.size());
  for (const auto& m : rec->solver) recorded_us.push_back(m.total_us);
  set_timing(row.score, std::move(recorded_us), scenario->controller.dt);
  row.matches = compare.matches && rec->states.size() == std::size_t(session.steps_done());
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
      if (rows[i].ok) {
        std::fprintf(stderr, "[%zu/%zu] %s: skill %.1f\n", d, files.size(), files[i].c_str(),
                     rows[i].score.skill);
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
    std::printf("%-32s %-12s %8.1f %7.3f %7.3f %8.3f %5d %6lld %7.1f %s\n", r.file.c_str(),
                r.pilot.c_str(), s.duration_s, s.mean_lambda, s.min_lambda, s.max_deviation_m,
                s.collisions, static_cast<long long>(s.fallbacks), s.skill,
                r.matches ? "exact" : "DIFFERS from recording");
    if (json.size() > 2) json += ",\n";
    json += to_json(s, {{"file", r.file},
                        {"scenario", r.scenario},
                        {"pilot", r.pilot},
                        {"replay", r.matches ? "exact" : "differs"}});
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
