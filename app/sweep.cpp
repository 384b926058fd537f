// mixpilot sweep: a sweep file's runs flown into a folder of results and merged into a table.
#include "app/sweep.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string_view>
#include <thread>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/slurm.hpp"
#include "core/base/input_file.hpp"
#include "core/base/report_table.hpp"
#include "core/modes/report.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kSweepUsage =
    "usage: mixpilot sweep SWEEP.toml [--out DIR] [--jobs N] [--shard i/n] [--merge] [--force]\n"
    "       mixpilot sweep SWEEP.toml --slurm [--out DIR] [--partition P] [--tasks N]\n"
    "                                 [--cpus-per-task C] [--poll S] [--no-wait]\n"
    "       mixpilot sweep SWEEP.toml --check\n"
    "\n"
    "Flies every run of a sweep file (docs/sweeps.md): a base scenario and what to vary in it,\n"
    "a [grid] of scenario keys (every combination), a list of [[runs]], pilot profiles and\n"
    "seeds. Each run flies headless as `mixpilot fly` would (as fast as possible; not in the\n"
    "history) and writes DIR/runs/<id>.json: its parameters and its report (the fields of\n"
    "fly --report). A run whose file exists is finished and not flown again, so the same\n"
    "command resumes a sweep stopped by ^C, a kill or a crash. Then the runs are merged into\n"
    "DIR/table.csv (one row per run: index, id, the parameters, then every report field, the\n"
    "timing fields last) and DIR/table.json. DIR/plan.json holds the plan; a DIR holding\n"
    "another plan (the sweep file or its scenario changed) is refused.\n"
    "\n"
    "  --out DIR     the results' folder (default: the sweep file's name without .toml, in\n"
    "                the current folder)\n"
    "  --jobs N      fly N runs at once, 1 to 256 (default: the number of cores); the results\n"
    "                do not depend on it\n"
    "  --shard i/n   fly only the missing runs of shard i of n (1 <= i <= n): those whose\n"
    "                0-based index k has k mod n = i - 1; no merge (a Slurm array task, or\n"
    "                one machine of several sharing DIR)\n"
    "  --merge       fly nothing: merge the finished runs into DIR/table.csv and\n"
    "                DIR/table.json; exits 1 naming the runs still missing, if any\n"
    "  --force       fly the selected runs again even where they are finished\n"
    "  --check       read the sweep file, check every run's scenario and print the plan;\n"
    "                nothing is flown or written\n"
    "  -h, --help    show this help\n"
    "\n";
// Then the --slurm options (slurm::kOptionsHelp), then this.
constexpr const char* kSweepUsageEnd =
    "\n"
    "Progress on stderr, one line per finished run ([done/total], its id, its headline\n"
    "metric, its wall time, the time left). ^C (or SIGTERM) stops the runs in flight, which\n"
    "leave nothing; the finished ones are kept.\n"
    "\n"
    "exit status: 0 done (--no-wait: submitted), 1 a bad sweep file, a refused folder, a\n"
    "failed or missing run (--slurm: a task that failed or was cancelled, or Slurm refused the\n"
    "array), 2 usage, 130 interrupted\n";

struct SweepArgs {
  std::string file;
  std::string out;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  bool jobs_given = false;
  std::optional<Shard> shard;
  bool merge = false, force = false, check = false;
  slurm::Options slurm;
};

SweepArgs parse_args(int argc, char** argv) {
  SweepArgs a;
  for (int i = 2; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--out") {
      a.out = option_value("sweep", argc, argv, i);
    } else if (arg == "--jobs") {
      const std::string v = option_value("sweep", argc, argv, i);
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error("sweep", "--jobs expects a whole number from 1 to 256, got '" + v + "'");
      a.jobs = int(n);
      a.jobs_given = true;
    } else if (arg == "--shard") {
      const std::string v = option_value("sweep", argc, argv, i);
      a.shard = parse_shard(v);
      if (!a.shard)
        usage_error("sweep", "--shard expects i/n with whole numbers 1 <= i <= n <= " +
                                 std::to_string(kMaxShards) + ", got '" + v + "'");
    } else if (arg == "--merge") {
      a.merge = true;
    } else if (arg == "--force") {
      a.force = true;
    } else if (arg == "--check") {
      a.check = true;
    } else if (slurm::take_option("sweep", argc, argv, i, a.slurm)) {
    } else if (arg.size() > 1 && arg[0] == '-') {
      usage_error("sweep", "unknown option '" + std::string(arg) + "'");
    } else if (a.file.empty()) {
      a.file = file_argument("sweep", "a sweep file", arg);
    } else {
      usage_error("sweep", "one sweep file at a time (got '" + a.file + "' and '" +
                               std::string(arg) + "')");
    }
  }
  if (a.file.empty()) usage_error("sweep", "which sweep file? (mixpilot sweep SWEEP.toml)");
  if (a.merge && (a.shard || a.force || a.jobs_given))
    usage_error("sweep", std::string(a.shard ? "--shard" : a.force ? "--force" : "--jobs") +
                             " flies runs; --merge only gathers the finished ones");
  if (a.check && (a.merge || a.shard || a.force || a.jobs_given || !a.out.empty() ||
                  a.slurm.on || !a.slurm.given.empty()))
    usage_error("sweep", "--check only reads the sweep file: no other option goes with it");
  slurm::check_options("sweep", a.slurm, a.shard.has_value(), a.merge, a.force, a.jobs_given);
  return a;
}

std::string metric_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", v);
  return buf;
}

// The CSV text of a parameter's value.
std::string cell_of(const ScenarioValue& v) { return v.text(); }

}  // namespace

FolderPlan folder_plan(const SweepPlan& plan) {
  FolderPlan f;
  f.format = "mixpilot sweep";
  f.json = sweep_plan_json(plan, version());
  f.sha256 = plan.sha256;
  for (const SweepRun& r : plan.runs) f.ids.push_back(r.id);
  return f;
}

FlyOptions sweep_fly_options(const SweepPlan& plan, const SweepRun& run) {
  FlyOptions o;
  o.command = "sweep";
  o.scenario_path = plan.scenario_file;
  o.scenario_text = run.scenario_text;
  o.headless = true;
  o.history = "off";  // research flights, not a trainee's: `history import` adds recordings
  o.duration = run.duration;
  if (run.assist == Assistance::off) o.assist = Assistance::off;
  o.bounds = run.bounds;
  return o;
}

std::string metrics_headline(const Metrics& m) {
  const auto get = [&](std::string_view name) -> std::optional<double> {
    for (const auto& [k, v] : m)
      if (k == name) return v;
    return std::nullopt;
  };
  std::string out;
  for (const char* name : {"skill", "tracking_rms_m", "swingup_time_s", "min_margin_m"})
    if (const auto v = get(name)) {
      out = std::string(name) + " " + metric_text(*v);
      break;
    }
  if (const auto lost = get("lost"); lost && *lost != 0.0)
    out += std::string(out.empty() ? "" : ", ") + "LOST";
  return out.empty() ? "done" : out;
}

RunOutcome fly_sweep_run(const SweepPlan& plan, const SweepRun& run, const std::string& dir) {
  RunOutcome out;
  const FlyOptions o = sweep_fly_options(plan, run);
  std::string error;
  int status = kExitOk;
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error, status);
  if (!rig) {
    for (const std::string& line : explain_run_error(plan, run, error))
      out.error += (out.error.empty() ? "" : "\n") + line;
    return out;
  }
  std::string recording;
  if (plan.record) {
    recording = dir + "/recordings/" + run.id + ".mcap";
    // A recording of this id is a run that never finished (its file would exist): replaced.
    if (!rig->record(recording, "", {}, /*overwrite=*/true, error)) {
      out.error = error;
      return out;
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  rig->start();
  while (!interrupted() && rig->step()) {
  }
  const bool stopped = interrupted() && !rig->mode().finished();
  const FlightRig::Closed closed = rig->close(stopped);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (stopped) {
    std::error_code ec;
    if (!recording.empty()) fs::remove(recording, ec);  // an unfinished run leaves nothing
    out.interrupted = true;
    return out;
  }
  if (!closed.error.empty()) {
    out.error = closed.error;
    return out;
  }
  const Metrics metrics = rig->metrics();
  std::string report = to_json(rig->labels(false), metrics, 4);
  report.replace(report.size() - 2, 2, "\n  }");  // the closing brace at the member's indent
  std::string params = "{";
  for (std::size_t i = 0; i < run.parameters.size(); ++i)
    params += (i ? ", " : "") + json_quote(run.parameters[i].key) + ": " +
              run.parameters[i].value.json();
  params += '}';
  char wall_text[32];
  std::snprintf(wall_text, sizeof wall_text, "%.3f", wall);
  out.json = "{\n  \"format\": \"mixpilot sweep run 1\",\n  \"sweep\": " + json_quote(plan.name) +
             ",\n  \"plan_sha256\": " + json_quote(plan.sha256) +
             ",\n  \"index\": " + std::to_string(run.index) + ",\n  \"id\": " + json_quote(run.id) +
             ",\n  \"parameters\": " + params + ",\n  \"wall_s\": " + wall_text +
             (recording.empty() ? std::string()
                                : ",\n  \"recording\": " + json_quote("recordings/" + run.id + ".mcap")) +
             ",\n  \"report\": " + report + "\n}\n";
  out.said = metrics_headline(metrics);
  out.ok = true;
  return out;
}

namespace {

// Every run's scenario and options checked as its flight will be set up, before anything is
// flown: a sweep that cannot fly one of its runs flies none.
bool check_runs(const SweepPlan& plan, std::string& error) {
  // Each complaint once, with the runs it concerns (a bad value of an axis spoils every run
  // that flies it).
  std::vector<std::pair<std::string, std::vector<std::string>>> problems;
  for (const SweepRun& run : plan.runs) {
    std::string why;
    int status = kExitOk;
    if (FlightRig::assemble(sweep_fly_options(plan, run), why, status)) continue;
    for (const std::string& line : explain_run_error(plan, run, why)) {
      auto it = std::find_if(problems.begin(), problems.end(),
                             [&](const auto& p) { return p.first == line; });
      if (it == problems.end()) it = problems.insert(problems.end(), {line, {}});
      it->second.push_back(run.id);
    }
  }
  error.clear();
  for (std::size_t i = 0; i < problems.size() && i < 20; ++i) {
    const auto& [line, runs] = problems[i];
    error += (error.empty() ? "" : "\n") + line + (runs.size() == 1 ? " (run " : " (runs ") +
             id_list(runs, 3) + ")";
  }
  if (problems.size() > 20)
    error += "\n... and " + std::to_string(problems.size() - 20) + " more problems";
  return problems.empty();
}

// DIR/table.csv and table.json from every run's file; exit status (1 with the missing runs).
int merge(const SweepPlan& plan, const ResultFolder& folder) {
  const ResultFolder::Gathered g = folder.gather();
  for (const std::string& b : g.bad) std::fprintf(stderr, "mixpilot sweep: %s\n", b.c_str());
  if (!g.missing.empty()) {
    std::fprintf(stderr,
                 "mixpilot sweep: %zu of %zu runs are missing, no table written: %s\n"
                 "(fly them: mixpilot sweep %s --out %s, or the shards that hold them)\n",
                 g.missing.size(), plan.runs.size(), id_list(g.missing).c_str(),
                 plan.file.c_str(), folder.dir().c_str());
    return kExitError;
  }
  if (!g.bad.empty()) return kExitError;
  std::vector<JsonValue> reports(g.runs.size());
  std::vector<ReportRow> rows(g.runs.size());
  for (std::size_t i = 0; i < g.runs.size(); ++i) {
    const JsonValue& run = g.runs[i];
    const SweepRun& r = plan.runs[i];  // every run is there, in plan order
    rows[i].keys = {{"index", std::to_string(r.index)}, {"id", r.id}};
    for (const std::string& c : plan.columns) {
      std::string text;
      for (const SweepSetting& s : r.parameters)
        if (s.key == c) text = cell_of(s.value);
      rows[i].keys.emplace_back(c, text);
    }
    reports[i] = *run.get("report");
    if (const JsonValue* wall = run.number_at("wall_s")) reports[i].members.push_back({"wall_s", *wall});
    rows[i].report = &reports[i];
  }
  std::string error;
  if (!folder.write_tables(g, report_table_csv(rows), error)) {
    std::fprintf(stderr, "mixpilot sweep: %s\n", error.c_str());
    return kExitError;
  }
  std::printf("  table %s/table.csv (%zu runs; also table.json)\n", folder.dir().c_str(), rows.size());
  return kExitOk;
}

}  // namespace

int sweep_command(int argc, char** argv) {
  for (int i = 2; i < argc; ++i)
    if (std::string_view(argv[i]) == "-h" || std::string_view(argv[i]) == "--help") {
      std::fputs(kSweepUsage, stdout);
      std::fputs(slurm::kOptionsHelp, stdout);
      std::fputs(kSweepUsageEnd, stdout);
      return kExitOk;
    }
  const SweepArgs a = parse_args(argc, argv);
  std::string error;
  const std::optional<SweepPlan> plan = load_sweep(a.file, error);
  if (!plan) {
    std::fprintf(stderr, "%s\n", escape_controls(error, true).c_str());
    return kExitError;
  }
  const std::string dir = a.out.empty() ? plan->name : a.out;
  const FolderPlan fplan = folder_plan(*plan);

  if (a.merge) {
    ResultFolder folder;
    if (!folder.open_existing(dir, fplan, error)) {
      std::fprintf(stderr, "mixpilot sweep: %s\n", error.c_str());
      return kExitError;
    }
    std::printf("mixpilot sweep: %s: %zu runs in %s\n", plan->name.c_str(), plan->runs.size(),
                dir.c_str());
    return merge(*plan, folder);
  }
  if (!check_runs(*plan, error)) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return kExitError;
  }
  for (const std::string& note : plan->notes)
    std::fprintf(stderr, "mixpilot sweep: note: %s\n", note.c_str());
  if (a.check) {
    std::printf("mixpilot sweep: %s: %zu runs of %s%s\n", plan->name.c_str(), plan->runs.size(),
                plan->scenario_file.c_str(),
                plan->duration ? (", " + metric_text(*plan->duration) + " s each").c_str() : "");
    for (const SweepSetting& s : plan->fixed)
      std::printf("  set %s = %s\n", s.key.c_str(), s.value.toml().c_str());
    for (const SweepRun& r : plan->runs) std::printf("  %s\n", r.id.c_str());
    std::printf("  plan_sha256 %s\n", plan->sha256.c_str());
    return kExitOk;
  }

  ResultFolder folder;
  if (!folder.claim(dir, fplan, error)) {
    std::fprintf(stderr, "mixpilot sweep: %s\n", error.c_str());
    return kExitError;
  }
  if (plan->record) {
    std::error_code ec;
    fs::create_directories(dir + "/recordings", ec);
    if (ec) {
      std::fprintf(stderr, "mixpilot sweep: %s/recordings: cannot create the folder: %s\n",
                   dir.c_str(), ec.message().c_str());
      return kExitError;
    }
  }
  if (a.slurm.on) {
    // The array's tasks fly the shards (`--shard i/n` into this folder); here, the merge.
    slurm::ArrayRequest r;
    r.kind = "sweep";
    std::error_code ec;
    r.dir = fs::absolute(dir, ec).lexically_normal();
    r.task = {slurm::self_executable(), "sweep", fs::absolute(a.file, ec).lexically_normal().string(),
              "--out", r.dir.string()};
    r.total = plan->runs.size();
    r.missing = [&plan, &folder] {
      std::vector<std::size_t> missing;
      for (std::size_t k = 0; k < plan->runs.size(); ++k)
        if (!folder.finished(plan->runs[k].id)) missing.push_back(k);
      return missing;
    };
    std::printf("mixpilot sweep: %s: %zu runs in %s, on Slurm\n", plan->name.c_str(),
                plan->runs.size(), dir.c_str());
    std::fflush(stdout);
    return slurm::run_command("sweep", a.slurm, std::move(r),
                              [&plan, &folder] { return merge(*plan, folder); });
  }
  const std::vector<std::size_t> selected = shard_runs(plan->runs.size(), a.shard);
  std::vector<std::size_t> todo;
  std::vector<std::string> todo_ids;
  for (const std::size_t k : selected)
    if (a.force || !folder.finished(plan->runs[k].id)) {
      todo.push_back(k);
      todo_ids.push_back(plan->runs[k].id);
    }
  folder.clear_leftovers(todo_ids, dir + "/runs", ".json");
  if (plan->record) folder.clear_leftovers(todo_ids, dir + "/recordings", ".mcap");
  const std::size_t done_before = selected.size() - todo.size();
  const std::string scope =
      a.shard ? "shard " + std::to_string(a.shard->index) + "/" + std::to_string(a.shard->count) +
                    ": " + std::to_string(selected.size()) + " of " +
                    std::to_string(plan->runs.size()) + " runs"
              : std::to_string(plan->runs.size()) + " runs";
  const int jobs = std::min<int>(a.jobs, int(std::max<std::size_t>(1, todo.size())));
  std::printf("mixpilot sweep: %s: %s in %s, %zu finished, %zu to fly%s\n", plan->name.c_str(),
              scope.c_str(), dir.c_str(), done_before, todo.size(),
              todo.empty() ? "" : (" on " + std::to_string(jobs) + (jobs == 1 ? " job" : " jobs")).c_str());
  std::fflush(stdout);

  catch_interrupts();
  const auto t0 = std::chrono::steady_clock::now();
  const PoolResult r = run_pool("sweep", folder, fplan.ids, todo, done_before, selected.size(),
                                a.jobs, [&](std::size_t k) {
                                  return fly_sweep_run(*plan, plan->runs[k], dir);
                                });
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!todo.empty())
    std::printf("  %zu run%s flown in %s%s\n", r.flown - r.failed, r.flown - r.failed == 1 ? "" : "s",
                duration_text(wall).c_str(),
                r.failed ? (", " + std::to_string(r.failed) + " failed").c_str() : "");
  if (r.interrupted) {
    std::printf("  interrupted: the runs finished are kept; the same command flies the rest\n");
    return kExitInterrupted;
  }
  if (a.shard) return r.failed > 0 ? kExitError : kExitOk;
  const int merged = merge(*plan, folder);
  return r.failed > 0 ? kExitError : merged;
}

}  // namespace mixpilot::cli
