#pragma once
// The folder of a plan of independent runs (`mixpilot sweep`, `mixpilot score DIR`;
// docs/sweeps.md), and the pool that flies them:
//
//   DIR/plan.json        the plan: every run's index and id, and plan_sha256, which a second
//                        invocation (a shard, a resumption) must match: a changed plan is
//                        refused rather than mixed with another's results
//   DIR/runs/<id>.json   one per finished run, written whole (a temporary moved into place):
//                        its existence is what "finished" means, so a run that has one is not
//                        flown again (unless --force), and a killed run leaves none
//   DIR/table.csv        the merge: one row per run (docs/sweeps.md, core/base/report_table.hpp)
//   DIR/table.json       the same runs as a JSON array of their run files
//
// The runs of a plan are independent: any subset in any order on any number of threads or
// machines gives the same files (the timing fields aside).
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/base/json.hpp"
#include "core/base/shard.hpp"

namespace mixpilot::cli {

// What a folder's plan is: its plan.json text, its hash and its runs' ids, in plan order.
struct FolderPlan {
  std::string format;  // "mixpilot sweep" or "mixpilot score": a run file's "format" begins so
  std::string json;    // plan.json's text
  std::string sha256;
  std::vector<std::string> ids;
};

class ResultFolder {
 public:
  // Claims `dir` for `plan`: creates it (and runs/) when absent, or checks that it holds this
  // plan. A folder with another plan, or an existing folder that is not a plan's folder (no
  // plan.json and not empty), is refused with the reason and the way out. Several processes
  // may claim one folder at once (the shards of an array job): one writes plan.json, the
  // others find it and check it.
  bool claim(const std::string& dir, const FolderPlan& plan, std::string& error);
  // Opens a folder that must already hold `plan` (a merge); false with the reason.
  bool open_existing(const std::string& dir, const FolderPlan& plan, std::string& error);

  const std::string& dir() const { return dir_; }
  std::string run_path(const std::string& id) const;
  // The run has its file, and the file is this plan's run (its plan_sha256 and id): a file
  // that is not (copied from another folder, edited) counts as unfinished and is replaced.
  bool finished(const std::string& id) const;
  // Removes what killed runs left of themselves: the temporaries of <folder>/<id><ext> of
  // each of `ids` (runs/<id>.json; a run's other outputs, such as its recording).
  void clear_leftovers(const std::vector<std::string>& ids, const std::string& folder,
                       const std::string& ext) const;
  // Writes runs/<id>.json whole; false with the reason.
  bool write_run(const std::string& id, const std::string& json, std::string& error) const;

  // Every run file, in plan order: what a merge reads.
  struct Gathered {
    std::vector<std::string> missing;  // ids without a run file
    std::vector<std::string> bad;      // messages: unreadable, not JSON, another plan's
    std::vector<JsonValue> runs;       // the parsed run files of the rest, in plan order
    std::vector<std::string> texts;    // and their texts
  };
  Gathered gather() const;
  // table.csv (`csv`) and table.json (the gathered run files as one array); false with the
  // reason.
  bool write_tables(const Gathered& g, const std::string& csv, std::string& error) const;

 private:
  bool check_plan(const std::string& text, std::string& error) const;

  std::string dir_;
  FolderPlan plan_;
};

// "… and N more" lists of ids for messages: the first `show` of them.
std::string id_list(const std::vector<std::string>& ids, std::size_t show = 10);

// The runs of `all` (plan indices) a shard holds; every index without a shard.
std::vector<std::size_t> shard_runs(std::size_t total, const std::optional<Shard>& shard);

// One run flown by the pool: its file's text, or why it failed; `said` is a short summary
// for the progress line (a score, a metric).
struct RunOutcome {
  bool ok = false;
  bool interrupted = false;  // stopped by ^C / SIGTERM: not finished, nothing written
  std::string json;
  std::string said;
  std::string error;
};

// Flies `todo` (plan indices) on `jobs` threads with fly(index), writing each finished run's
// file as it ends. Progress on stderr, one line per run: "[done/total] id: said (wall s), ETA".
// `done_before` runs of `total` were finished already. Stops taking runs at ^C or SIGTERM
// (cli::interrupted(); fly() itself stops its flight). Returns the number of runs that failed.
struct PoolResult {
  std::size_t flown = 0, failed = 0;
  bool interrupted = false;
};
PoolResult run_pool(const char* command, const ResultFolder& folder,
                    const std::vector<std::string>& ids, const std::vector<std::size_t>& todo,
                    std::size_t done_before, std::size_t total, int jobs,
                    const std::function<RunOutcome(std::size_t)>& fly);

// The seconds of a wall time as the progress says them: "4.2 s", "3 min 20 s", "1 h 5 min".
std::string duration_text(double seconds);

}  // namespace mixpilot::cli
