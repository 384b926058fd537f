#include "app/slurm.hpp"

#include <sys/file.h>
#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "app/child_process.hpp"
#include "app/cli.hpp"

namespace mixpilot::cli::slurm {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

std::string_view trim(std::string_view s) {
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> out;
  while (!text.empty()) {
    const std::size_t nl = text.find('\n');
    const std::string_view line = trim(text.substr(0, nl));
    if (!line.empty()) out.push_back(line);
    if (nl == std::string_view::npos) break;
    text.remove_prefix(nl + 1);
  }
  return out;
}

// `line` cut at the first `count - 1` '|' (the last field keeps any further '|').
std::vector<std::string_view> fields(std::string_view line, std::size_t count) {
  std::vector<std::string_view> out;
  while (out.size() + 1 < count) {
    const std::size_t bar = line.find('|');
    if (bar == std::string_view::npos) break;
    out.push_back(line.substr(0, bar));
    line.remove_prefix(bar + 1);
  }
  out.push_back(line);
  return out;
}

bool parse_int(std::string_view s, int& v) {
  if (s.empty() || s.size() > 9) return false;
  v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  return true;
}

std::string quote_shell(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// A value of an #SBATCH line: in double quotes (sbatch's reader takes a value with spaces so).
std::string quote_directive(const std::string& s) { return "\"" + s + "\""; }

// Slurm's file name patterns read '%': a literal one is written "%%".
std::string escape_pattern(const std::string& s) {
  std::string out;
  for (char c : s) out += c == '%' ? std::string("%%") : std::string(1, c);
  return out;
}

std::string plural(std::size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

// The last `lines` lines of a file, indented, or "".
std::string tail_of(const fs::path& file, std::size_t lines) {
  std::ifstream in(file);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (last.size() > lines) last.pop_front();
  }
  std::string out;
  for (const auto& l : last) out += "\n    | " + l;
  return out;
}

// An array this folder submitted, as DIR/slurm/jobs remembers it.
struct Submitted {
  std::string job;
  int tasks = 0;            // n
  std::vector<int> shards;  // the indices submitted
  std::string name;
};

constexpr const char* kJobsHeader =
    "# The Slurm job arrays mixpilot submitted for this folder: job id, shards (n), the array's\n"
    "# indices, job name. `mixpilot ... --slurm` reads it to find an array still queued.\n";

std::vector<Submitted> read_jobs(const fs::path& file) {
  std::vector<Submitted> out;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    Submitted s;
    std::string spec;
    if (!(f >> s.job >> s.tasks >> spec >> s.name) || !parse_indices(spec, s.shards)) continue;
    out.push_back(std::move(s));
  }
  return out;
}

// The folder's lock, held while it looks for a queued array and submits (two commands started
// at once for one folder submit one array; the second waits for it).
class FolderLock {
 public:
  explicit FolderLock(const fs::path& file) {
    fd_ = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd_ < 0) return;
    if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
      std::fprintf(stderr, "slurm: another mixpilot is submitting for this folder; waiting for it\n");
      while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
      }
    }
  }
  ~FolderLock() { release(); }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  void release() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_ = -1;
};

// A task followed: its shard (the array index), what Slurm last said and what we make of it.
struct Task {
  int shard = 0;
  std::string job;
  TaskState state = TaskState::pending;
  std::string word = "SUBMITTED";  // Slurm's state word, or ours for a task gone from its view
  std::string detail;              // why pending, or the exit code
  bool seen = false;               // squeue or sacct has named it
};

struct Tools {
  std::string sbatch, squeue, sacct;
};

std::string path_env() {
  const char* p = std::getenv("PATH");
  return p ? p : "";
}

// Runs a Slurm client; false with a message naming it when it could not run or failed.
bool run_tool(const std::string& program, const std::vector<std::string>& args, ProgramRun& run,
              std::string& error) {
  std::string start_error;
  if (!run_program(program, args, 120, run, start_error)) {
    error = start_error;
    return false;
  }
  if (run.timed_out) {
    error = program + " did not answer within 120 s";
    return false;
  }
  if (!run.exit.ok()) {
    std::string said = std::string(trim(run.err.empty() ? run.out : run.err));
    error = fs::path(program).filename().string() + " failed (" + to_string(run.exit) + ")" +
            (said.empty() ? std::string() : ": " + said);
    return false;
  }
  return true;
}

// squeue's rows for `jobs` (comma-separated ids); an empty list when the controller no longer
// knows any of them. False with `error` when squeue failed otherwise.
bool query_squeue(const Tools& t, const std::string& jobs, std::vector<TaskRecord>& rows,
                  std::string& error) {
  rows.clear();
  ProgramRun run;
  if (!run_tool(t.squeue,
                {"--noheader", "--array", "--states=all", "--jobs=" + jobs,
                 "--format=%F|%K|%T|%r|%j"},
                run, error)) {
    // Jobs purged from the controller's memory (MinJobAge): "Invalid job id specified".
    if (run.err.find("Invalid job id") != std::string::npos) {
      error.clear();
      return true;
    }
    return false;
  }
  return parse_squeue(run.out, rows, error);
}

// sacct's rows for `jobs`, or nullopt when sacct is missing or cannot answer (no accounting on
// this cluster: then it is not asked again).
std::optional<std::vector<TaskRecord>> query_sacct(Tools& t, const std::string& jobs) {
  if (t.sacct.empty()) return std::nullopt;
  ProgramRun run;
  std::string error;
  if (!run_tool(t.sacct,
                {"--noheader", "--parsable2", "--allocations", "--jobs=" + jobs,
                 "--format=JobID,State,ExitCode"},
                run, error)) {
    t.sacct.clear();
    return std::nullopt;
  }
  return parse_sacct(run.out);
}

// Sleeps `seconds`, in slices, returning false at once on ^C.
bool pause_for(double seconds) {
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  while (Clock::now() < until) {
    if (interrupted()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return !interrupted();
}

std::string log_path(const fs::path& dir, const std::string& job, int shard,
                     const char* ext) {
  return (dir / "slurm" / (job + "_" + std::to_string(shard) + ext)).string();
}

}  // namespace

bool parse_indices(std::string_view text, std::vector<int>& out) {
  out.clear();
  text = trim(text);
  if (!text.empty() && text.front() == '[') text.remove_prefix(1);
  if (!text.empty() && text.back() == ']') text.remove_suffix(1);
  if (const std::size_t pct = text.find('%'); pct != std::string_view::npos) {
    int throttle = 0;
    if (!parse_int(text.substr(pct + 1), throttle)) return false;
    text = text.substr(0, pct);
  }
  if (text.empty()) return false;
  std::set<int> all;
  while (true) {
    const std::size_t comma = text.find(',');
    std::string_view item = text.substr(0, comma);
    int step = 1;
    if (const std::size_t colon = item.find(':'); colon != std::string_view::npos) {
      if (!parse_int(item.substr(colon + 1), step) || step < 1) return false;
      item = item.substr(0, colon);
    }
    int first = 0, last = 0;
    if (const std::size_t dash = item.find('-'); dash != std::string_view::npos) {
      if (!parse_int(item.substr(0, dash), first) || !parse_int(item.substr(dash + 1), last) ||
          last < first || last - first > 10'000'000)
        return false;
    } else {
      if (!parse_int(item, first)) return false;
      last = first;
    }
    for (int i = first; i <= last; i += step) all.insert(i);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  out.assign(all.begin(), all.end());
  return true;
}

std::string array_spec(const std::vector<int>& indices) {
  std::string out;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    if (!out.empty()) out += ',';
    out += std::to_string(indices[i]);
    if (j > i) out += "-" + std::to_string(indices[j]);
    i = j + 1;
  }
  return out;
}

bool parse_squeue(std::string_view text, std::vector<TaskRecord>& rows, std::string& error) {
  rows.clear();
  for (const std::string_view line : lines_of(text)) {
    const auto f = fields(line, 5);
    TaskRecord r;
    if (f.size() != 5 || trim(f[0]).empty() || trim(f[2]).empty()) {
      error = "squeue answered a line not of the form JOB|TASKS|STATE|REASON|NAME: '" +
              std::string(line) + "'";
      return false;
    }
    // A job that is no array ("N/A") is none of ours.
    if (!parse_indices(f[1], r.tasks)) continue;
    r.job = std::string(trim(f[0]));
    r.state = std::string(trim(f[2]));
    r.detail = std::string(trim(f[3]));
    if (r.detail == "None") r.detail.clear();  // squeue's word for no reason
    r.name = std::string(trim(f[4]));
    rows.push_back(std::move(r));
  }
  return true;
}

std::vector<TaskRecord> parse_sacct(std::string_view text) {
  std::vector<TaskRecord> out;
  for (const std::string_view line : lines_of(text)) {
    const auto f = fields(line, 3);
    if (f.size() != 3) continue;
    const std::string_view id = trim(f[0]);
    const std::size_t us = id.find('_');
    if (us == std::string_view::npos || id.find('.') != std::string_view::npos) continue;
    TaskRecord r;
    if (!parse_indices(id.substr(us + 1), r.tasks)) continue;
    r.job = std::string(id.substr(0, us));
    const std::string_view state = trim(f[1]);
    r.state = std::string(state.substr(0, state.find(' ')));
    r.detail = std::string(trim(f[2]));
    out.push_back(std::move(r));
  }
  return out;
}

TaskState classify(std::string_view state) {
  state = state.substr(0, state.find(' '));
  if (state == "COMPLETED") return TaskState::done;
  for (const char* w : {"FAILED", "CANCELLED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY",
                        "PREEMPTED", "BOOT_FAIL", "DEADLINE", "REVOKED"})
    if (state == w) return TaskState::failed;
  for (const char* w : {"PENDING", "REQUEUED", "REQUEUE_HOLD", "REQUEUE_FED", "RESV_DEL_HOLD",
                        "SPECIAL_EXIT"})
    if (state == w) return TaskState::pending;
  return TaskState::running;
}

std::string job_name(const ArrayRequest& r) {
  std::string folder = r.dir.filename().string();
  if (folder.empty()) folder = r.dir.parent_path().filename().string();
  std::string clean;
  for (char c : folder)
    clean += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')
                 ? c
                 : '_';
  return ("mixpilot-" + r.kind + "-" + clean).substr(0, 64);
}

std::string unscriptable_path(const fs::path& dir) {
  const std::string s = dir.string();
  if (s.find('"') != std::string::npos) return "its path holds a double quote";
  if (s.find('\\') != std::string::npos) return "its path holds a backslash";
  if (s.find_first_of("\n\r") != std::string::npos) return "its path holds a line break";
  return "";
}

std::string job_script(const ArrayRequest& r, const std::vector<int>& shards,
                       const std::string& name) {
  const std::string dir = r.dir.string();
  const std::string logs = escape_pattern((r.dir / "slurm").string());
  std::ostringstream s;
  s << "#!/bin/sh\n"
    << "# mixpilot " << r.kind << " on Slurm, written by mixpilot: array task i flies shard i of "
    << r.tasks << " of\n# " << dir << "\n# and writes its results there as each finishes.\n"
    << "#SBATCH --job-name=" << name << "\n"
    << "#SBATCH --array=" << array_spec(shards) << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << r.cpus_per_task << "\n";
  if (!r.partition.empty()) s << "#SBATCH --partition=" << r.partition << "\n";
  s << "#SBATCH --chdir=" << quote_directive(dir) << "\n"
    << "#SBATCH --output=" << quote_directive(logs + "/%A_%a.out") << "\n"
    << "#SBATCH --error=" << quote_directive(logs + "/%A_%a.err") << "\n"
    << "exec";
  for (const std::string& a : r.task) s << ' ' << quote_shell(a);
  s << " --shard \"$SLURM_ARRAY_TASK_ID/" << r.tasks << "\" --jobs \"${SLURM_CPUS_PER_TASK:-"
    << r.cpus_per_task << "}\"\n";
  return s.str();
}

ArrayOutcome run_array(const ArrayRequest& r) {
  ArrayOutcome outcome;
  const auto fail = [&outcome](std::string message) {
    outcome.end = ArrayEnd::error;
    outcome.message = std::move(message);
    return outcome;
  };
  Tools tools;
  tools.sbatch = find_program("sbatch", path_env());
  tools.squeue = find_program("squeue", path_env());
  tools.sacct = find_program("sacct", path_env());
  if (tools.sbatch.empty() || tools.squeue.empty())
    return fail(std::string(tools.sbatch.empty() ? "sbatch" : "squeue") +
                " is not in PATH: --slurm submits with Slurm's sbatch and follows with squeue "
                "(run it on the cluster's login node; Debian: slurm-client)");
  if (r.task.empty() || r.task[0].empty())
    return fail("cannot tell this program's own path (/proc/self/exe), which the job script runs");
  if (const std::string why = unscriptable_path(r.dir); !why.empty())
    return fail(r.dir.string() + " cannot be written into a Slurm job script: " + why);

  const fs::path slurm_dir = r.dir / "slurm";
  std::error_code ec;
  fs::create_directories(slurm_dir, ec);
  if (ec) return fail("cannot create " + slurm_dir.string() + ": " + ec.message());
  const fs::path jobs_file = slurm_dir / "jobs";
  const std::string name = job_name(r);
  const int n = r.tasks;
  const auto shards_missing = [&r, n] {
    std::set<int> s;
    for (std::size_t k : r.missing()) s.insert(static_cast<int>(k % std::size_t(n)) + 1);
    return std::vector<int>(s.begin(), s.end());
  };

  // The tasks to follow: those of arrays this folder submitted that are still in the queue,
  // else those of a new array of the shards with work missing.
  std::vector<Task> tasks;
  std::vector<std::string> job_ids;
  Clock::time_point submitted_at{};
  {
    FolderLock lock(slurm_dir / "lock");
    const std::vector<Submitted> before = read_jobs(jobs_file);
    if (!before.empty()) {
      std::string ids;
      for (const auto& s : before) ids += (ids.empty() ? "" : ",") + s.job;
      std::vector<TaskRecord> rows;
      std::string error;
      if (!query_squeue(tools, ids, rows, error))
        return fail("cannot tell whether an array of " + r.dir.string() +
                    " is still queued: " + error);
      for (const auto& s : before) {
        std::vector<Task> active;
        for (const TaskRecord& row : rows) {
          if (row.job != s.job || row.name != s.name) continue;
          for (int shard : row.tasks) {
            if (std::find(s.shards.begin(), s.shards.end(), shard) == s.shards.end()) continue;
            const TaskState st = classify(row.state);
            if (st == TaskState::pending || st == TaskState::running)
              active.push_back({shard, s.job, st, row.state, row.detail, true});
          }
        }
        if (active.empty()) continue;
        // Follow the whole array: its finished tasks too, for the final word on each (they
        // start as if running, so that squeue, sacct or the folder settles them).
        for (int shard : s.shards) {
          const auto it = std::find_if(active.begin(), active.end(),
                                       [shard](const Task& t) { return t.shard == shard; });
          tasks.push_back(it != active.end() ? *it : Task{shard, s.job, TaskState::running,
                                                          "ENDED", "", false});
        }
        job_ids.push_back(s.job);
      }
      if (!job_ids.empty()) {
        std::size_t pending = 0, running = 0;
        for (const Task& t : tasks) {
          pending += t.seen && t.state == TaskState::pending;
          running += t.seen && t.state == TaskState::running;
        }
        std::string ids_said;
        for (const auto& j : job_ids) ids_said += (ids_said.empty() ? "" : ", ") + j;
        std::fprintf(stderr,
                     "slurm: array job %s of %s is still in the queue (%zu pending, %zu running): "
                     "not submitting again%s\n",
                     ids_said.c_str(), r.dir.string().c_str(), pending, running,
                     r.wait ? "; following it" : "");
      }
    }

    if (job_ids.empty()) {
      const std::vector<int> shards = shards_missing();
      if (shards.empty()) {
        std::fprintf(stderr, "slurm: all %zu %s of %s are there: nothing to submit\n", r.total,
                     r.unit.c_str(), r.dir.string().c_str());
        outcome.end = ArrayEnd::complete;
        return outcome;
      }
      const std::string script =
          (slurm_dir / (r.kind + "-" + std::to_string(before.size() + 1) + ".sh")).string();
      std::string error;
      if (!write_file(script, job_script(r, shards, name), true, error))
        return fail("cannot write the job script: " + error);
      ProgramRun run;
      if (!run_tool(tools.sbatch, {"--parsable", script}, run, error))
        return fail("sbatch refused the array (its script: " + script + "): " + error);
      // "12345" or "12345;cluster".
      const std::string out(trim(run.out));
      const std::string job = out.substr(0, out.find(';'));
      int id = 0;
      if (!parse_int(job, id))
        return fail("sbatch answered '" + out + "', not a job id (its script: " + script + ")");
      std::string record;
      {
        std::ifstream in(jobs_file);
        std::stringstream ss;
        ss << in.rdbuf();
        record = ss.str();
      }
      if (record.empty()) record = kJobsHeader;
      record += job + " " + std::to_string(n) + " " + array_spec(shards) + " " + name + "\n";
      if (!write_file(jobs_file.string(), record, true, error))
        return fail("submitted array job " + job + " but cannot remember it: " + error +
                    " (scancel " + job + " before running this again)");
      const std::string where = r.partition.empty() ? "" : " on partition " + r.partition;
      std::fprintf(stderr, "slurm: submitted array job %s: %s (of %d) of %s, %s each%s; logs in %s\n",
                   job.c_str(), plural(shards.size(), "task", "tasks").c_str(), n,
                   r.dir.string().c_str(), plural(std::size_t(r.cpus_per_task), "CPU", "CPUs").c_str(),
                   where.c_str(), slurm_dir.string().c_str());
      for (int shard : shards) tasks.push_back({shard, job, TaskState::pending, "SUBMITTED", "", false});
      job_ids.push_back(job);
      submitted_at = Clock::now();
    }
  }
  outcome.job = job_ids.back();
  if (!r.wait) {
    outcome.end = ArrayEnd::submitted;
    return outcome;
  }

  // Follow the tasks until none is pending or running.
  std::string ids;
  for (const auto& j : job_ids) ids += (ids.empty() ? "" : ",") + j;
  std::string said;
  int squeue_failures = 0;
  for (bool first = true;; first = false) {
    if (!first && !pause_for(r.poll_seconds)) {
      std::fprintf(stderr,
                   "slurm: stopped following; array job %s keeps running (scancel %s stops it). "
                   "Run the same command again to follow it and merge.\n",
                   outcome.job.c_str(), outcome.job.c_str());
      outcome.end = ArrayEnd::interrupted;
      return outcome;
    }
    std::vector<TaskRecord> rows;
    std::string error;
    if (!query_squeue(tools, ids, rows, error)) {
      if (++squeue_failures >= 10)
        return fail("squeue failed 10 times in a row: " + error);
      std::fprintf(stderr, "slurm: %s; asking again\n", error.c_str());
      continue;
    }
    squeue_failures = 0;
    const std::vector<std::size_t> missing = r.missing();
    std::set<int> shards_left;
    for (std::size_t k : missing) shards_left.insert(static_cast<int>(k % std::size_t(n)) + 1);

    std::vector<Task*> unknown;
    for (Task& t : tasks) {
      bool found = false;
      for (const TaskRecord& row : rows)
        if (row.job == t.job && std::find(row.tasks.begin(), row.tasks.end(), t.shard) != row.tasks.end()) {
          t.state = classify(row.state);
          t.word = row.state;
          t.detail = row.detail;
          t.seen = found = true;
        }
      if (!found && (t.state == TaskState::pending || t.state == TaskState::running))
        unknown.push_back(&t);
    }
    if (!unknown.empty()) {
      // Gone from the controller's view (cancelled while pending, or forgotten): sacct, where
      // the cluster keeps accounts; else the folder says whether its work is there.
      const auto acct = query_sacct(tools, ids);
      for (Task* t : unknown) {
        bool found = false;
        if (acct)
          for (const TaskRecord& row : *acct)
            if (row.job == t->job &&
                std::find(row.tasks.begin(), row.tasks.end(), t->shard) != row.tasks.end()) {
              t->state = classify(row.state);
              t->word = row.state;
              t->detail = "exit " + row.detail;
              t->seen = found = true;
            }
        if (found) continue;
        // Just submitted and not listed yet: still pending.
        if (!t->seen && submitted_at != Clock::time_point{} &&
            Clock::now() - submitted_at < std::chrono::seconds(60))
          continue;
        const bool done = shards_left.count(t->shard) == 0;
        t->state = done ? TaskState::done : TaskState::failed;
        t->word = done ? "ENDED" : "GONE";
        t->detail = done ? "" : "left the queue unfinished; the cluster keeps no record of why";
      }
    }

    std::size_t pending = 0, running = 0, done = 0, failed = 0;
    std::map<std::string, std::size_t> reasons;
    for (const Task& t : tasks) {
      switch (t.state) {
        case TaskState::pending:
          ++pending;
          if (!t.detail.empty()) ++reasons[t.detail];
          break;
        case TaskState::running: ++running; break;
        case TaskState::done: ++done; break;
        case TaskState::failed: ++failed; break;
      }
    }
    std::string why;
    for (const auto& [reason, count] : reasons) why += (why.empty() ? "" : ", ") + reason;
    const std::string line =
        "slurm: job " + outcome.job + ": " + std::to_string(pending) + " pending" +
        (why.empty() ? "" : " (" + why + ")") + ", " + std::to_string(running) + " running, " +
        std::to_string(done) + " done, " + std::to_string(failed) + " failed; " +
        std::to_string(r.total - std::min(r.total, missing.size())) + " of " +
        std::to_string(r.total) + " " + r.unit;
    if (line != said) {
      std::fprintf(stderr, "%s\n", line.c_str());
      said = line;
    }
    if (pending + running > 0) continue;

    // The array has ended: what each task that did not finish its shard left behind.
    for (const Task& t : tasks) {
      const bool work_missing = shards_left.count(t.shard) != 0;
      if (t.state == TaskState::done && !work_missing) continue;
      const std::string err = log_path(r.dir, t.job, t.shard, ".err");
      std::string what = t.state == TaskState::done
                             ? "completed, yet its " + r.unit + " are not in " + r.dir.string() +
                                   " (is that folder on a filesystem every node shares?)"
                             : t.word + (t.detail.empty() ? "" : " (" + t.detail + ")");
      std::fprintf(stderr, "slurm: task %d (shard %d of %d) of job %s: %s; its log: %s%s\n",
                   t.shard, t.shard, n, t.job.c_str(), what.c_str(), err.c_str(),
                   tail_of(err, 5).c_str());
    }
    if (missing.empty()) {
      outcome.end = ArrayEnd::complete;
      return outcome;
    }
    std::fprintf(stderr,
                 "slurm: %zu of %zu %s missing (shards %s); run the same command again to "
                 "submit those shards again\n",
                 missing.size(), r.total, r.unit.c_str(),
                 array_spec(std::vector<int>(shards_left.begin(), shards_left.end())).c_str());
    outcome.end = ArrayEnd::incomplete;
    return outcome;
  }
}

int default_tasks(std::size_t total) {
  return static_cast<int>(std::clamp<std::size_t>(total, 1, kDefaultMaxTasks));
}

const char* const kOptionsHelp =
    "  --slurm       fly the runs on a Slurm cluster (docs/slurm.md): the folder (on a\n"
    "                filesystem every node shares) gets a job script, submitted with sbatch as\n"
    "                an array of one task per shard, each task running --shard i/n; followed\n"
    "                with squeue until it ends, then merged. Run the same command again to\n"
    "                follow an array still queued, or to submit only the shards whose runs\n"
    "                are missing (a task that failed or was cancelled)\n"
    "  --partition P the Slurm partition (default: the cluster's default)\n"
    "  --tasks N     shards, one array task each (default: one per run, at most 100)\n"
    "  --cpus-per-task C  CPUs of each task, which flies C runs at once (default 1)\n"
    "  --poll S      ask squeue every S seconds (default 10)\n"
    "  --no-wait     submit and return; the same command later follows the array and merges\n";

bool take_option(const char* command, int argc, char** argv, int& i, Options& o) {
  const std::string_view arg = argv[i];
  const auto whole = [&](const std::string& v, long lo, long hi) {
    char* end = nullptr;
    const long n = std::strtol(v.c_str(), &end, 10);
    if (end == v.c_str() || *end != '\0' || n < lo || n > hi)
      usage_error(command, std::string(arg) + " expects a whole number from " + std::to_string(lo) +
                               " to " + std::to_string(hi) + ", got '" + v + "'");
    return static_cast<int>(n);
  };
  if (arg == "--slurm") {
    o.on = true;
    return true;
  }
  if (arg == "--partition") {
    o.partition = option_value(command, argc, argv, i);
    if (o.partition.find_first_of(" \t\n\"'\\") != std::string::npos)
      usage_error(command, "--partition expects a partition's name, got '" + o.partition + "'");
  } else if (arg == "--tasks") {
    o.tasks = whole(option_value(command, argc, argv, i), 1, 100000);
  } else if (arg == "--cpus-per-task") {
    o.cpus_per_task = whole(option_value(command, argc, argv, i), 1, 256);
  } else if (arg == "--poll") {
    const std::string v = option_value(command, argc, argv, i);
    const auto s = parse_seconds(v, 3600);
    if (!s) usage_error(command, "--poll expects seconds, more than 0 and at most 3600, got '" + v + "'");
    o.poll_seconds = *s;
  } else if (arg == "--no-wait") {
    o.wait = false;
  } else {
    return false;
  }
  o.given.emplace_back(arg);
  return true;
}

void check_options(const char* command, const Options& o, bool shard, bool merge, bool force,
                   bool jobs) {
  if (!o.on) {
    if (!o.given.empty()) usage_error(command, o.given.front() + " goes with --slurm");
    return;
  }
  if (shard) usage_error(command, "--slurm gives each array task its --shard itself");
  if (merge) usage_error(command, "--slurm merges when its array ends; --merge is without it");
  if (force)
    usage_error(command,
                "--slurm flies only what is missing from the folder; to fly everything again, "
                "give another --out");
  if (jobs) usage_error(command, "with --slurm, each task's parallel runs are --cpus-per-task");
}

std::string self_executable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

int run_command(const char* command, const Options& o, ArrayRequest r,
                const std::function<int()>& merge) {
  r.tasks = o.tasks > 0 ? o.tasks : default_tasks(r.total);
  r.cpus_per_task = o.cpus_per_task;
  r.partition = o.partition;
  r.poll_seconds = o.poll_seconds;
  r.wait = o.wait;
  catch_interrupts();
  const ArrayOutcome outcome = run_array(r);
  switch (outcome.end) {
    case ArrayEnd::complete:
      return merge();
    case ArrayEnd::submitted:
      std::fprintf(stderr,
                   "slurm: not following it (--no-wait); run the same command again to follow "
                   "array job %s and merge\n",
                   outcome.job.c_str());
      return kExitOk;
    case ArrayEnd::interrupted:
      return kExitInterrupted;
    case ArrayEnd::incomplete:
      return kExitError;
    case ArrayEnd::error:
      break;
  }
  std::fprintf(stderr, "mixpilot %s: %s\n", command, outcome.message.c_str());
  return kExitError;
}

}  // namespace mixpilot::cli::slurm
