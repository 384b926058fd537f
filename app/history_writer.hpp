#pragma once
// The history's own thread (SPEC §10): it owns the store, opened lazily there, and does all of
// its waiting — a database another process holds locked (up to the store's busy timeout), a
// long recording hashed, a PostgreSQL server far away. Front ends hand it finished flights and
// ask for what the window shows (trainees, a trainee's progress on a scenario); the UI thread
// polls the outcomes and reads the newest snapshot each frame, never waiting on the disk or the
// network. One writer per process: the window's Trainer and `fly --headless` (which waits for
// it at the end) use the same path.
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/history/history.hpp"
#include "ui/progress.hpp"

namespace mixpilot::cli {

class HistoryWriter {
 public:
  // Opens the store on the writer's thread when first needed; a failed open is tried again with
  // the next job (a lock may have gone). nullptr with the reason.
  using Opener = std::function<std::unique_ptr<history::HistoryStore>(std::string& error)>;
  // `location` as open_history() takes it ("" the default SQLite file).
  explicit HistoryWriter(const std::string& location);
  explicit HistoryWriter(Opener open);
  // Writes what is still queued, then joins (a flight closed at exit is still remembered).
  ~HistoryWriter();
  HistoryWriter(const HistoryWriter&) = delete;
  HistoryWriter& operator=(const HistoryWriter&) = delete;

  // A finished flight: `record` is written once `hash_path` (its recording, "" none) is hashed
  // into record.recording_hash. With `attempt`, a lesson step's flight: the flight and its
  // verdict are written together and the trainee's progress moves on (add_attempt).
  void remember(history::FlightRecord record, std::string hash_path,
                std::optional<history::LessonAttempt> attempt = std::nullopt);
  // The snapshot should also show `trainee`'s progress in the lesson (name, hash; "" none).
  void show_lesson(std::string trainee, std::string lesson, std::string lesson_hash);
  // The snapshot should show `trainee`'s progress on `scenario` (and every trainee): loaded now,
  // and again after each flight remembered.
  void show(std::string trainee, std::string scenario);

  // What became of a flight handed over.
  struct Outcome {
    std::string trainee, scenario;
    bool lesson_attempt = false;   // it was a lesson step's attempt
    bool remembered = false;       // its row is in the history (new or already known)
    std::string error;             // why not ("" when remembered)
  };
  // The outcomes since the last poll, appended to `out` (never waits on the disk: the writer
  // holds the lock only to hand them over). True when there were any.
  bool poll(std::vector<Outcome>& out);
  // The newest snapshot (nullptr until the first load). Immutable: a frame keeps it as it is.
  std::shared_ptr<const ui::HistoryView> view() const;
  // Blocks until every job handed over so far is done (fly --headless at its end, tests).
  void wait_idle();

 private:
  struct Job {
    enum class Kind { write, load } kind = Kind::write;
    history::FlightRecord record;
    std::string hash_path;
    std::optional<history::LessonAttempt> attempt;
  };
  void run();
  history::HistoryStore* store(std::string& error);
  void write(Job& job);
  void load();

  Opener open_;
  // The SQLite file a location names ("" PostgreSQL or an Opener): showing the history never
  // creates it (a window opened and closed leaves no history behind); a flight does.
  std::string file_;
  std::unique_ptr<history::HistoryStore> store_;  // the thread's alone

  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<Job> jobs_;
  bool busy_ = false, stopping_ = false;
  std::string trainee_, scenario_;               // what show() asked for
  std::string lesson_trainee_, lesson_, lesson_hash_;  // what show_lesson() asked for
  std::vector<Outcome> outcomes_;
  std::shared_ptr<const ui::HistoryView> view_;
  std::thread thread_;                            // last: started once the rest exists
};

}  // namespace mixpilot::cli
