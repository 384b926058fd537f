// mixpilot score: fly recordings again, check them step by step, score them.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight_rig.hpp"
#include "core/recording/replay.hpp"
#include "core/modes/report.hpp"
#include "core/base/input_file.hpp"
#include "core/modes/session.hpp"
#include "core/base/output_file.hpp"
#include "core/recording/recording.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kScoreUsage =
    "usage: mixpilot score FILE.mcap... [--jobs N] [--json OUT]\n"
    "\n"
    "Flies each recording again through a fresh session of its embedded scenario and checks the\n"
    "replayed states against the recorded ones bit for bit: mixed_initiative recordings replay\n"
    "their pilot commands and are scored (the timing fields come from the recorded solver\n"
    "statistics: they describe that flight); other modes are flown for the recorded number of\n"
    "steps and give their metrics (timing fields from this run). A probe flight (fly --assist\n"
    "off) is replayed as one and marked \"probe\": \"true\". Progress on stderr, a table on\n"
    "stdout. Each progress line says how fast the replay ran: the flight's length over the CPU\n"
    "time of the thread that replayed it (\"30.0 s in 0.29 s CPU: 103x real time\"; wall time\n"
    "too), which on a machine shared with other work is the figure that stays put.\n"
    "\n"
    "  --jobs N     replay N recordings in parallel (default: the number of cores)\n"
    "  --json OUT   write a JSON array with one object per recording\n"
    "  --allow-mismatch  exit 0 even when a replay differs from its recording\n"
    "  --force      overwrite an existing --json file\n"
    "\n"
    "exit status: 0 done, 1 a recording could not be read or replayed, 2 usage, 3 a replay\n"
    "differs from its recording\n";

struct ScoreRow {
  std::string file;
  std::string mode;
  std::string pilot;
  std::string scenario;
  bool probe = false;  // a probe flight (assistance off), replayed as one
  Metrics metrics;
  bool ok = false;
  std::string difference;  // what differed first; empty: every step replayed bit for bit
  std::string error;
  // The flight stopped before its planned end: "interrupted at t = 3.0 s of 30.0 s" ("" if not).
  std::string ended_early;
  // How fast it was replayed: the steps flown [s of flight], the replaying thread's CPU time and
  // the wall time it took [s] (assembling the flight and reading the recording included).
  double flown_s = 0.0;
  double cpu_s = 0.0;
  double wall_s = 0.0;
};

// CPU time of the calling thread [s].
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// " (30.0 s in 0.29 s CPU, 0.31 s wall: 103x real time)" for the progress line.
std::string speed_words(const ScoreRow& row) {
  if (!(row.flown_s > 0.0) || !(row.cpu_s > 0.0)) return "";
  char buf[128];
  std::snprintf(buf, sizeof buf, " (%.1f s in %.2f s CPU, %.2f s wall: %.0fx real time)",
                row.flown_s, row.cpu_s, row.wall_s, row.flown_s / row.cpu_s);
  return buf;
}

// A metric of the row by name (0 when the mode has none).
double metric_of(const ScoreRow& row, std::string_view name) {
  for (const auto& [key, value] : row.metrics)
    if (key == name) return value;
  return 0.0;
}

ScoreRow score_recording(const std::string& path) {
  ScoreRow row;
  row.file = path;
  const double cpu0 = thread_cpu_s();
  const auto wall0 = std::chrono::steady_clock::now();
  FlyOptions o;
  o.pilot = path;
  o.replay = true;
  o.command = "score";
  std::string error;
  int status = kExitOk;
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error, status);
  if (!rig) {
    row.error = error;
    return row;
  }
  rig->start();
  while (rig->step()) {
  }
  const RecordingContents& rec = *rig->flight().recording;
  const auto pilot_meta = rec.metadata.find("pilot");
  // Printed in the table: as the recording says it, made printable.
  row.pilot = pilot_meta != rec.metadata.end() ? escape_controls(pilot_meta->second) : "";
  const Mode& mode = rig->mode();
  row.mode = to_string(mode.kind());
  row.scenario = mode.scenario_name();
  row.probe = mode.identity().probe;
  row.metrics = rig->metrics();
  row.difference = rig->replay_difference();
  row.ended_early = recording_ended_early(rec, mode);
  row.flown_s = double(mode.steps_done()) * mode.dt();
  row.cpu_s = thread_cpu_s() - cpu0;
  row.wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  row.ok = true;
  return row;
}

}  // namespace

int score_command(int argc, char** argv) {
  std::vector<std::string> files;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  std::string json_path;
  bool allow_mismatch = false, force = false;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kScoreUsage, stdout);
      return kExitOk;
    } else if (a == "--jobs") {
      const std::string v = option_value("score", argc, argv, i);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error("score", "--jobs expects a whole number from 1 to 256, got '" + v + "'");
      jobs = int(n);
    } else if (a == "--json") {
      json_path = option_value("score", argc, argv, i);
    } else if (a == "--allow-mismatch") {
      allow_mismatch = true;
    } else if (a == "--force") {
      force = true;
    } else if (a.size() > 1 && a[0] == '-') {
      usage_error("score", "unknown option '" + std::string(a) + "'");
    } else {
      files.push_back(file_argument("score", "a recording", a));
    }
  }
  if (files.empty()) usage_error("score", "no recordings given");
  if (!json_path.empty()) {
    std::vector<std::pair<std::string, std::string>> inputs;
    for (const std::string& f : files) inputs.emplace_back("the recording", f);
    check_not_an_input("score", "--json", json_path, inputs);
  }
  if (!json_path.empty()) {
    std::string error;
    if (!check_output_path(json_path, force, error)) {
      std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
      return kExitError;
    }
  }

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
        std::fprintf(stderr, "[%zu/%zu] %s: skill %.1f%s\n", d, files.size(), files[i].c_str(),
                     metric_of(rows[i], "skill"), speed_words(rows[i]).c_str());
      } else if (rows[i].ok) {
        std::fprintf(stderr, "[%zu/%zu] %s: %s%s\n", d, files.size(), files[i].c_str(),
                     rows[i].mode.c_str(), speed_words(rows[i]).c_str());
      } else {
        std::fprintf(stderr, "[%zu/%zu] %s\n", d, files.size(), rows[i].error.c_str());
      }
    }
  };
  std::vector<std::thread> pool;
  for (int j = 0; j < std::min<int>(jobs, int(files.size())); ++j) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  std::printf("%-32s %-12s %8s %7s %7s %6s %8s %5s %6s %7s %s\n", "recording", "pilot", "time_s",
              "lambda", "min_l", "D", "maxdev_m", "coll", "fallb", "skill", "replay");
  int failures = 0, mismatches = 0;
  std::string json = "[\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const ScoreRow& r = rows[i];
    if (!r.ok) {
      ++failures;
      std::printf("%-32s error: %s\n", r.file.c_str(), r.error.c_str());
      continue;
    }
    const auto m = [&r](std::string_view name) { return metric_of(r, name); };
    const bool exact = r.difference.empty();
    std::string replay = exact ? "exact" : "DIFFERS from recording";
    if (!r.ended_early.empty()) replay += " (" + r.ended_early + ")";
    if (r.probe) replay += " (probe: assistance off)";
    if (!exact) {
      ++mismatches;
      std::fprintf(stderr, "%s: the replay differs from the recording: %s\n", r.file.c_str(),
                   r.difference.c_str());
    }
    if (r.mode == "mixed_initiative") {
      std::printf("%-32s %-12s %8.1f %7.3f %7.3f %6.3f %8.3f %5d %6lld %7.1f %s\n",
                  r.file.c_str(), r.pilot.c_str(), m("duration_s"), m("mean_lambda"),
                  m("min_lambda"), m("assistance_dependence"), m("max_deviation_m"),
                  int(m("collisions")), static_cast<long long>(m("fallbacks")), m("skill"),
                  replay.c_str());
    } else {  // the other modes' metrics are in the JSON
      std::printf("%-32s %-12.12s %8s %7s %7s %6s %8s %5s %6s %7s %s\n", r.file.c_str(),
                  r.mode.c_str(), "-", "-", "-", "-", "-", "-", "-", "-", replay.c_str());
    }
    if (json.size() > 2) json += ",\n";
    Labels labels = {{"file", r.file}, {"mode", r.mode}, {"scenario", r.scenario}};
    if (!r.pilot.empty()) labels.emplace_back("pilot", r.pilot);
    if (r.probe) labels.emplace_back("probe", "true");
    labels.emplace_back("replay", exact ? "exact" : "differs");
    if (!r.ended_early.empty()) labels.emplace_back("interrupted", "true");
    json += to_json(labels, r.metrics);
  }
  json += "\n]\n";
  if (!json_path.empty()) {
    std::string error;
    if (!write_file(json_path, json, force, error)) {
      std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
      return kExitError;
    }
  }
  if (failures > 0) return kExitError;
  return mismatches > 0 && !allow_mismatch ? kExitReplayMismatch : kExitOk;
}

}  // namespace mixpilot::cli
