// mixpilot score: fly recordings again, check them step by step, score them.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight_rig.hpp"
#include "app/slurm.hpp"
#include "app/sweep.hpp"
#include "app/sweep_folder.hpp"
#include "core/base/content_hash.hpp"
#include "core/base/json.hpp"
#include "core/base/report_table.hpp"
#include "core/numerics/version.hpp"
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
    "       mixpilot score DIR [--out OUT] [--jobs N] [--shard i/n] [--merge] [--force]\n"
    "       mixpilot score DIR --slurm [--out OUT] [--partition P] [--tasks N]\n"
    "                          [--cpus-per-task C] [--poll S] [--no-wait]\n"
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
    "A folder (DIR): its recordings (*.mcap directly in it), in sorted name order, are the\n"
    "plan of a folder of results OUT, as `mixpilot sweep` keeps one (docs/sweeps.md): each\n"
    "recording's report goes to OUT/runs/<id>.json (id: its 4-digit index and its name) as it\n"
    "is scored, so a score stopped by ^C or a kill goes on where it stopped when run again;\n"
    "then the reports are merged into OUT/table.csv and OUT/table.json (the array --json\n"
    "writes, with each report's index and id). OUT/plan.json lists the recordings: a\n"
    "folder whose recordings changed since is refused (give another --out).\n"
    "  --out OUT    the results' folder (default: DIR's name followed by -scores, in the\n"
    "               current folder)\n"
    "  --shard i/n  score only the missing recordings of shard i of n: those whose 0-based\n"
    "               index k has k mod n = i - 1; no merge\n"
    "  --merge      score nothing: merge the reports into OUT/table.csv and table.json;\n"
    "               exits 1 naming the recordings still missing\n"
    "  --force      score the selected recordings again even where their report exists\n"
    "\n";
// Then the --slurm options (slurm::kOptionsHelp: its runs are the recordings), then this.
constexpr const char* kScoreUsageEnd =
    "\n"
    "exit status: 0 done (--no-wait: submitted), 1 a recording could not be read or replayed\n"
    "(--slurm: also a task that failed or was cancelled, or Slurm refused the array), 2 usage,\n"
    "3 a replay differs from its recording\n";

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
  bool stopped = false;  // ^C or SIGTERM stopped the replay: no score
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
  while (!interrupted() && rig->step()) {
  }
  if (interrupted() && !rig->mode().finished()) {
    row.stopped = true;
    return row;
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

// The report's labels of a scored recording (score --json, a folder's run files).
Labels row_labels(const ScoreRow& r) {
  Labels labels = {{"file", r.file}, {"mode", r.mode}, {"scenario", r.scenario}};
  if (!r.pilot.empty()) labels.emplace_back("pilot", r.pilot);
  if (r.probe) labels.emplace_back("probe", "true");
  labels.emplace_back("replay", r.difference.empty() ? "exact" : "differs");
  if (!r.ended_early.empty()) labels.emplace_back("interrupted", "true");
  return labels;
}

struct FolderArgs {
  std::string dir, out;
  int jobs = 1;
  std::optional<Shard> shard;
  bool merge = false, force = false, allow_mismatch = false;
  slurm::Options slurm;
};

// A folder's recordings in sorted name order, as the plan of its results' folder.
struct RecordingPlan {
  FolderPlan folder;
  std::vector<std::string> files;  // paths
};

std::optional<RecordingPlan> recording_plan(const std::string& dir, std::string& error) {
  namespace fs = std::filesystem;
  std::vector<std::pair<std::string, std::uintmax_t>> found;  // name, bytes
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    std::error_code fe;
    if (!name.ends_with(".mcap") || !e.is_regular_file(fe)) continue;
    found.emplace_back(name, e.file_size(fe));
  }
  if (ec) {
    error = dir + ": cannot list the folder: " + ec.message();
    return std::nullopt;
  }
  if (found.empty()) {
    error = dir + " holds no recordings (*.mcap)";
    return std::nullopt;
  }
  std::sort(found.begin(), found.end());
  RecordingPlan p;
  p.folder.format = "mixpilot score";
  std::string hashed = "mixpilot score plan 1\n";
  std::string runs;
  for (std::size_t k = 0; k < found.size(); ++k) {
    const auto& [name, bytes] = found[k];
    std::string stem = name.substr(0, name.size() - 5);
    for (char& c : stem)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-' &&
          c != '=' && c != '+')
        c = '_';
    if (stem.size() > 120) stem.resize(120);
    const std::string index = std::to_string(k);
    const std::string id = std::string(index.size() < 4 ? 4 - index.size() : 0, '0') + index + '-' + stem;
    p.folder.ids.push_back(id);
    p.files.push_back((fs::path(dir) / name).string());
    hashed += name + '\n' + std::to_string(bytes) + '\n';
    runs += std::string(k ? "," : "") + "\n    {\"index\": " + std::to_string(k) +
            ", \"id\": " + json_quote(id) + ", \"recording\": " + json_quote(name) +
            ", \"bytes\": " + std::to_string(bytes) + '}';
  }
  p.folder.sha256 = sha256_hex(hashed);
  const fs::path abs = fs::absolute(dir, ec);
  p.folder.json = "{\n  \"format\": \"mixpilot score plan 1\",\n  \"folder\": " +
                  json_quote((ec ? fs::path(dir) : abs).lexically_normal().string()) +
                  ",\n  \"plan_sha256\": " + json_quote(p.folder.sha256) +
                  ",\n  \"version\": " + json_quote(version()) +
                  ",\n  \"runs_total\": " + std::to_string(found.size()) + ",\n  \"runs\": [" +
                  runs + "\n  ]\n}\n";
  return p;
}

// The exit status the merged reports call for: 1 a recording that could not be scored, 3 a
// replay that differs (unless allowed), else 0.
int reports_status(const std::vector<JsonValue>& runs, bool allow_mismatch) {
  bool failed = false, differs = false;
  for (const JsonValue& run : runs) {
    const JsonValue* report = run.get("report");
    if (!report) continue;
    if (report->get("error")) failed = true;
    if (const std::string* replay = report->string_at("replay"); replay && *replay == "differs")
      differs = true;
  }
  if (failed) return kExitError;
  return differs && !allow_mismatch ? kExitReplayMismatch : kExitOk;
}

int merge_scores(const RecordingPlan& plan, const ResultFolder& folder, bool allow_mismatch) {
  const ResultFolder::Gathered g = folder.gather();
  for (const std::string& b : g.bad) std::fprintf(stderr, "mixpilot score: %s\n", b.c_str());
  if (!g.missing.empty()) {
    std::fprintf(stderr,
                 "mixpilot score: %zu of %zu recordings have no report yet, no table written: "
                 "%s\n",
                 g.missing.size(), plan.files.size(), id_list(g.missing).c_str());
    return kExitError;
  }
  if (!g.bad.empty()) return kExitError;
  std::vector<JsonValue> reports(g.runs.size());
  std::vector<ReportRow> rows(g.runs.size());
  for (std::size_t i = 0; i < g.runs.size(); ++i) {
    rows[i].keys = {{"index", std::to_string(i)}, {"id", plan.folder.ids[i]}};
    reports[i] = *g.runs[i].get("report");
    if (const JsonValue* wall = g.runs[i].number_at("wall_s"))
      reports[i].members.push_back({"wall_s", *wall});
    rows[i].report = &reports[i];
  }
  std::string error;
  if (!folder.write_tables(g, report_table_csv(rows), error)) {
    std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
    return kExitError;
  }
  std::printf("  table %s/table.csv (%zu recordings; also table.json)\n", folder.dir().c_str(),
              rows.size());
  return reports_status(g.runs, allow_mismatch);
}

int score_folder(const FolderArgs& a) {
  namespace fs = std::filesystem;
  std::string error;
  const std::optional<RecordingPlan> plan = recording_plan(a.dir, error);
  if (!plan) {
    std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
    return kExitError;
  }
  std::string out = a.out;
  if (out.empty()) {
    std::error_code ec;
    fs::path abs = fs::absolute(a.dir, ec).lexically_normal();
    if (!abs.has_filename()) abs = abs.parent_path();
    out = abs.filename().string() + "-scores";
  }
  ResultFolder folder;
  if (a.merge) {
    if (!folder.open_existing(out, plan->folder, error)) {
      std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
      return kExitError;
    }
    std::printf("mixpilot score: %s: %zu recordings, results in %s\n", a.dir.c_str(),
                plan->files.size(), out.c_str());
    return merge_scores(*plan, folder, a.allow_mismatch);
  }
  // The results never go among the recordings they score.
  std::error_code ec;
  if (fs::exists(out, ec) && fs::equivalent(out, a.dir, ec))
    usage_error("score", "--out " + out + " is the folder of the recordings: the results go "
                         "to a folder of their own");
  if (!folder.claim(out, plan->folder, error)) {
    std::fprintf(stderr, "mixpilot score: %s\n", error.c_str());
    return kExitError;
  }
  if (a.slurm.on) {
    // The array's tasks score the shards (`--shard i/n` into this folder); here, the merge.
    slurm::ArrayRequest r;
    r.kind = "score";
    r.dir = fs::absolute(out, ec).lexically_normal();
    r.task = {slurm::self_executable(), "score", fs::absolute(a.dir, ec).lexically_normal().string(),
              "--out", r.dir.string()};
    if (a.allow_mismatch) r.task.push_back("--allow-mismatch");
    r.unit = "recordings";
    r.total = plan->files.size();
    r.missing = [&plan, &folder] {
      std::vector<std::size_t> missing;
      for (std::size_t k = 0; k < plan->folder.ids.size(); ++k)
        if (!folder.finished(plan->folder.ids[k])) missing.push_back(k);
      return missing;
    };
    std::printf("mixpilot score: %s: %zu recordings, results in %s, on Slurm\n", a.dir.c_str(),
                plan->files.size(), out.c_str());
    std::fflush(stdout);
    const bool allow_mismatch = a.allow_mismatch;
    return slurm::run_command("score", a.slurm, std::move(r), [&plan, &folder, allow_mismatch] {
      return merge_scores(*plan, folder, allow_mismatch);
    });
  }
  const std::vector<std::size_t> selected = shard_runs(plan->files.size(), a.shard);
  std::vector<std::size_t> todo;
  std::vector<std::string> todo_ids;
  for (const std::size_t k : selected)
    if (a.force || !folder.finished(plan->folder.ids[k])) {
      todo.push_back(k);
      todo_ids.push_back(plan->folder.ids[k]);
    }
  folder.clear_leftovers(todo_ids, out + "/runs", ".json");
  const std::size_t done_before = selected.size() - todo.size();
  std::printf("mixpilot score: %s: %zu recordings%s, results in %s, %zu scored, %zu to score\n",
              a.dir.c_str(), plan->files.size(),
              a.shard ? (" (shard " + std::to_string(a.shard->index) + "/" +
                         std::to_string(a.shard->count) + ": " + std::to_string(selected.size()) + ")")
                            .c_str()
                      : "",
              out.c_str(), done_before, todo.size());
  std::fflush(stdout);
  catch_interrupts();
  std::atomic<int> failures{0}, mismatches{0};
  const PoolResult r = run_pool(
      "score", folder, plan->folder.ids, todo, done_before, selected.size(), a.jobs,
      [&](std::size_t k) {
        RunOutcome o;
        const auto t0 = std::chrono::steady_clock::now();
        const ScoreRow row = score_recording(plan->files[k]);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (row.stopped) {
          o.interrupted = true;
          return o;
        }
        std::string report;
        if (!row.ok) {
          // A recording that cannot be scored is a result too: said in its report.
          report = to_json({{"file", row.file}, {"error", row.error}}, {}, 4);
          o.said = "error: " + row.error;
          ++failures;
        } else {
          report = to_json(row_labels(row), row.metrics, 4);
          o.said = metrics_headline(row.metrics) +
                   (row.difference.empty() ? "" : ", the replay DIFFERS from the recording");
          if (!row.difference.empty()) ++mismatches;
        }
        report.replace(report.size() - 2, 2, "\n  }");
        char wall_text[32];
        std::snprintf(wall_text, sizeof wall_text, "%.3f", wall);
        o.json = "{\n  \"format\": \"mixpilot score run 1\",\n  \"plan_sha256\": " +
                 json_quote(plan->folder.sha256) + ",\n  \"index\": " + std::to_string(k) +
                 ",\n  \"id\": " + json_quote(plan->folder.ids[k]) + ",\n  \"recording\": " +
                 json_quote(fs::path(plan->files[k]).filename().string()) +
                 ",\n  \"wall_s\": " + wall_text + ",\n  \"report\": " + report + "\n}\n";
        o.ok = true;
        return o;
      });
  if (r.interrupted) {
    std::printf("  interrupted: the reports written are kept; the same command scores the rest\n");
    return kExitInterrupted;
  }
  int status = failures > 0 || r.failed > 0 ? kExitError
               : mismatches > 0 && !a.allow_mismatch ? kExitReplayMismatch
                                                     : kExitOk;
  if (a.shard) return status;
  const int merged = merge_scores(*plan, folder, a.allow_mismatch);
  return status != kExitOk ? status : merged;
}

}  // namespace

int score_command(int argc, char** argv) {
  std::vector<std::string> files;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  std::string json_path, out;
  std::optional<Shard> shard;
  bool allow_mismatch = false, force = false, merge = false, jobs_given = false;
  slurm::Options slurm;
  for (int i = 2; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kScoreUsage, stdout);
      std::fputs(slurm::kOptionsHelp, stdout);
      std::fputs(kScoreUsageEnd, stdout);
      return kExitOk;
    } else if (a == "--jobs") {
      const std::string v = option_value("score", argc, argv, i);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error("score", "--jobs expects a whole number from 1 to 256, got '" + v + "'");
      jobs = int(n);
      jobs_given = true;
    } else if (a == "--out") {
      out = option_value("score", argc, argv, i);
    } else if (a == "--shard") {
      const std::string v = option_value("score", argc, argv, i);
      shard = parse_shard(v);
      if (!shard)
        usage_error("score", "--shard expects i/n with whole numbers 1 <= i <= n <= " +
                                 std::to_string(kMaxShards) + ", got '" + v + "'");
    } else if (a == "--merge") {
      merge = true;
    } else if (a == "--json") {
      json_path = option_value("score", argc, argv, i);
    } else if (a == "--allow-mismatch") {
      allow_mismatch = true;
    } else if (a == "--force") {
      force = true;
    } else if (slurm::take_option("score", argc, argv, i, slurm)) {
    } else if (a.size() > 1 && a[0] == '-') {
      usage_error("score", "unknown option '" + std::string(a) + "'");
    } else {
      files.push_back(file_argument("score", "a recording", a));
    }
  }
  if (files.empty()) usage_error("score", "no recordings given");
  std::error_code dir_ec;
  const bool folder = files.size() == 1 && std::filesystem::is_directory(files[0], dir_ec);
  if (!folder) {
    for (const std::string& f : files)
      if (std::filesystem::is_directory(f, dir_ec))
        usage_error("score", "'" + f + "' is a folder: score a folder alone (mixpilot score DIR), "
                             "or recordings (FILE.mcap...)");
    if (!out.empty() || shard || merge || slurm.on || !slurm.given.empty())
      usage_error("score", std::string(!out.empty() ? "--out"
                                       : shard      ? "--shard"
                                       : merge      ? "--merge"
                                       : slurm.on   ? "--slurm"
                                                    : slurm.given.front()) +
                               " goes with a folder of recordings (mixpilot score DIR)");
  } else {
    if (!json_path.empty())
      usage_error("score", "--json is for recordings given one by one; a folder's reports are "
                           "merged into OUT/table.json");
    if (merge && (shard || force || jobs_given))
      usage_error("score", std::string(shard ? "--shard" : force ? "--force" : "--jobs") +
                               " scores recordings; --merge only gathers the reports");
    slurm::check_options("score", slurm, shard.has_value(), merge, force, jobs_given);
    FolderArgs fa;
    fa.dir = files[0];
    fa.out = out;
    fa.jobs = jobs;
    fa.shard = shard;
    fa.merge = merge;
    fa.force = force;
    fa.allow_mismatch = allow_mismatch;
    fa.slurm = slurm;
    return score_folder(fa);
  }
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
    json += to_json(row_labels(r), r.metrics);
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
