#pragma once
// Work divided into shards (a sweep's runs, a folder's recordings to score: SPEC §11) flown on a
// Slurm cluster as a job array: task i of the array runs `mixpilot ... --shard i/n` on some
// node, which writes each result into the output folder as it finishes, so that folder must be
// on a filesystem the login node and every compute node share. The array's script, its tasks'
// logs and the ids of the arrays submitted for the folder are kept in DIR/slurm/.
//
// run_array() submits the shards that still have work missing (sbatch --parsable), then follows
// the array with squeue (and sacct, for tasks the controller has forgotten) until no task is
// pending or running, reporting on stderr; the caller merges. Run again for the same folder, it
// first looks for an array it submitted before that is still queued or running, and waits for
// that one instead of submitting twice; once none is, it submits only the shards with work
// missing (a task that failed or was cancelled). What a task did is judged by the output folder
// as much as by Slurm: a task that left the queue with its work missing failed.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot::cli::slurm {

// What an array task is doing, as Slurm's state words say.
enum class TaskState { pending, running, done, failed };

// One row of squeue's or sacct's answer about array tasks: one task, or several still pending
// as one record ("12_[4-6]").
struct TaskRecord {
  std::string job;         // the array's job id
  std::vector<int> tasks;  // the array indices the row covers
  std::string state;       // Slurm's word: PENDING, RUNNING, COMPLETED, CANCELLED, ...
  std::string detail;      // why pending (squeue's reason), or the exit code (sacct)
  std::string name;        // the job's name (squeue)
};

// The lines of `squeue --noheader --array --states=all --format=%F|%K|%T|%r|%j`. False with
// `error` naming the line that is not of that form.
[[nodiscard]] bool parse_squeue(std::string_view text, std::vector<TaskRecord>& rows,
                                std::string& error);
// The lines of `sacct --noheader --parsable2 --allocations --format=JobID,State,ExitCode`:
// "12_3|COMPLETED|0:0", "12_[4-6]|PENDING|0:0", "12_2|CANCELLED by 1000|0:15". Lines of other
// jobs (no array index) are left out.
std::vector<TaskRecord> parse_sacct(std::string_view text);
// Slurm's state word (its first word: "CANCELLED by 0") as ours: COMPLETED is done; FAILED,
// CANCELLED, TIMEOUT, NODE_FAIL, OUT_OF_MEMORY, PREEMPTED, BOOT_FAIL, DEADLINE and REVOKED
// failed; PENDING and the held or requeued states pending; anything else (RUNNING,
// COMPLETING, CONFIGURING, SUSPENDED, a word this version does not know) running: still in
// the queue.
TaskState classify(std::string_view state);
// Array indices: "1-3,5,7-9" (a step "1-9:2" and a throttle "%4" allowed, brackets ignored) as
// the sorted distinct list. False when it is not of that form.
[[nodiscard]] bool parse_indices(std::string_view text, std::vector<int>& out);
// The shortest --array value for sorted distinct indices: {1, 2, 3, 5} -> "1-3,5".
std::string array_spec(const std::vector<int>& indices);

// What to run on the cluster.
struct ArrayRequest {
  std::string kind;               // "sweep" or "score": the command, in names and messages
  std::filesystem::path dir;      // the output folder, absolute, on the shared filesystem
  std::vector<std::string> task;  // one task's command (an absolute executable first), to which
                                  // "--shard $SLURM_ARRAY_TASK_ID/n --jobs <cpus>" is added
  int tasks = 1;                  // n: the work is cut into this many shards
  int cpus_per_task = 1;          // each task's --jobs
  std::string partition;          // "" : the cluster's default partition
  double poll_seconds = 10;       // how often squeue is asked
  bool wait = true;               // false: submit, say so and return
  std::string unit = "runs";      // what the work consists of, for the progress line
  std::size_t total = 0;          // how many of them in all
  // The plan indices (0-based) of the work still missing from `dir`: index k belongs to shard
  // k % n + 1, as `--shard i/n` divides it.
  std::function<std::vector<std::size_t>()> missing;
};

enum class ArrayEnd {
  complete,      // every shard's work is in the folder: merge
  incomplete,    // tasks failed or were cancelled: their work is missing (they were named)
  submitted,     // wait = false: the array is in the queue
  interrupted,   // ^C while waiting (the array keeps running)
  error,         // nothing could be submitted or followed (sbatch or squeue missing, refused)
};

struct ArrayOutcome {
  ArrayEnd end = ArrayEnd::error;
  std::string job;      // the array followed or submitted last ("" when none)
  std::string message;  // ArrayEnd::error: why
};

// The job script for `shards` (sorted, distinct, 1-based) of `r` under the job name `name`.
std::string job_script(const ArrayRequest& r, const std::vector<int>& shards,
                       const std::string& name);
// The job name of `r`'s arrays: "mixpilot-<kind>-<the folder's name>", in characters any
// shell and Slurm take as they are.
std::string job_name(const ArrayRequest& r);
// Why `dir` cannot be written into a job script ("" when it can): a double quote, a backslash
// or a line break in its path.
std::string unscriptable_path(const std::filesystem::path& dir);

// Submits and follows `r`'s array as described above, reporting on stderr.
ArrayOutcome run_array(const ArrayRequest& r);

// ---- The command line of `sweep ... --slurm` and `score DIR ... --slurm` ----

// The default number of shards: one per run (a one-CPU task is what a scheduler backfills
// soonest, and a lost task loses one run), at most this many (well under Slurm's default
// MaxArraySize of 1001 and the per-user job limits sites set).
inline constexpr int kDefaultMaxTasks = 100;
int default_tasks(std::size_t total);

struct Options {
  bool on = false;          // --slurm
  std::string partition;    // --partition P
  int tasks = 0;            // --tasks N (0: default_tasks)
  int cpus_per_task = 1;    // --cpus-per-task C
  double poll_seconds = 10; // --poll S
  bool wait = true;         // --no-wait clears it
  std::vector<std::string> given;  // the options above given, but --slurm (for usage errors)
};

// The options' lines of `--help`.
extern const char* const kOptionsHelp;

// Takes argv[i] when it is one of the options above (moving i past its value; a bad value is
// a usage error of `command`): true, or false when it is none of them.
bool take_option(const char* command, int argc, char** argv, int& i, Options& o);
// Usage errors: an option above without --slurm; --slurm with --shard, --merge, --force or
// --jobs, which it decides itself.
void check_options(const char* command, const Options& o, bool shard, bool merge, bool force,
                   bool jobs);

// This executable's absolute path (what the job script runs on the nodes).
std::string self_executable();

// Fills `r` from `o` (tasks, CPUs, partition, polling, waiting), runs the array and, once every
// shard's work is in the folder, `merge()`: the command's exit status (0 merged, or submitted
// with --no-wait; 1 tasks failed or an error, said on stderr; 130 interrupted).
int run_command(const char* command, const Options& o, ArrayRequest r,
                const std::function<int()>& merge);

}  // namespace mixpilot::cli::slurm
