#pragma once
// The trainee's history (SPEC §10): every flight, from every front end, one row. One interface,
// one file per backend (sqlite_history, postgres_history), one schema (schema.hpp). A history
// failure never costs a flight: the callers say it and fly on.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mixpilot::history {

// How a flight ended; `instructor`: the instructor ended it (SPEC §10), stored as interrupted
// with ended_by 'instructor' (core/history/schema.cpp, migration 5).
enum class Ended { completed, interrupted, lost, instructor };
const char* to_string(Ended e);
std::optional<Ended> ended_from(std::string_view text);

struct FlightRecord {
  std::string trainee, station;            // station: this machine's host name unless set
  std::string scenario, scenario_hash;     // name, SHA-256 hex of the scenario text
  std::string mode, pilot, input_device, input_settings_hash;  // "" where none
  std::int64_t started_unix_ms = 0;
  double duration_s = 0.0;
  Ended ended = Ended::completed;
  bool probe = false;                      // an unassisted probe flight (set by the probe work)
  std::string recording_path, recording_hash;  // "" when not recorded; the hash is unique
  std::string app_version, front_end;      // front_end: window | fly | vehicle | import | ...
  std::vector<std::pair<std::string, double>> metrics;  // every score field of the report
  // A branch (fly from here): flown on from step `parent_step` of the flight whose recording
  // has this hash (that flight's recording_hash); "" and −1 for any other flight.
  std::string parent_recording_hash;
  std::int64_t parent_step = -1;
  bool branch() const { return parent_step >= 0; }
};
// A lesson step's attempt (SPEC §10): the flight flown for step `step` of the lesson `lesson`
// (its name) whose file has the SHA-256 `lesson_hash`, and its verdict.
struct LessonAttempt {
  std::string lesson, lesson_hash;
  int steps = 0;                 // how many steps the lesson has (≥ 1)
  int step = 0;                  // the step flown, 0-based
  std::string step_title;
  double ceiling = 1.0;          // the authority ceiling on λ it was flown with, (0, 1]
  bool passed = false;
  std::string failed_criterion;  // the first criterion that failed ("" when passed)
  std::string detail;            // the verdict in words ("skill 41.2 (at least 70)")
};
// Where a trainee is in a lesson: on step `step` (0-based; = steps once every step is passed),
// with `failed_attempts` failed attempts at it since they reached it.
struct LessonProgress {
  std::string trainee, lesson, lesson_hash;
  int steps = 0, step = 0, failed_attempts = 0;
  std::int64_t updated_unix_ms = 0;
  bool completed() const { return steps > 0 && step >= steps; }
};
struct StoredAttempt : LessonAttempt {
  std::int64_t id = 0, flight_id = 0;
  std::string trainee;
  std::int64_t started_unix_ms = 0;  // the flight's
  std::string recording_path;        // the flight's ("" when not recorded)
  double skill = 0.0;                // the flight's score field `skill` (NaN when it has none)
  bool probe = false;                // the flight was a probe
};

struct StoredFlight : FlightRecord {
  std::int64_t id = 0;
  // The lesson step this flight was an attempt at ("" and −1: none), and its verdict.
  std::string lesson;
  int lesson_step = -1;
  bool lesson_passed = false;
  std::string lesson_failed;  // the criterion that failed ("" when passed or not a lesson's)
  // The rest of the attempt's row (push copies it whole): the lesson's hash, the step's title,
  // the ceiling it was flown with and the verdict in words.
  std::string lesson_hash, lesson_step_title, lesson_detail;
  double lesson_ceiling = 1.0;
  bool attempt() const { return lesson_step >= 0; }
  // The attempt as add_attempt() takes it; its `steps` is step + 1 (a row does not keep how
  // many steps the lesson has: the progress does).
  LessonAttempt as_attempt() const;
};
// Which flights query() returns: all of them where a field is empty / 0. `limit` keeps the
// newest `limit` flights. The answer is oldest first (by start time, then id).
struct Query {
  std::string trainee, scenario;
  std::int64_t since_unix_ms = 0;
  std::int64_t limit = 0;
  // The score fields wanted (empty: all of them, in the report's order; else those of them a
  // flight has, in no set order). A listing that shows one field need not read twenty per
  // flight; a backend may return more than asked.
  std::vector<std::string> metrics;
};

class HistoryStore {
 public:
  virtual ~HistoryStore() = default;
  enum class Added { added, already_known };
  // Adds the flight in one transaction; a flight whose non-empty recording_hash is known is not
  // added again. nullopt with the reason (a refused record: check_record()'s reason).
  [[nodiscard]] virtual std::optional<Added> add(const FlightRecord& f, std::string& error) = 0;
  [[nodiscard]] virtual bool query(const Query& q, std::vector<StoredFlight>& out,
                                   std::string& error) = 0;
  // Every trainee's name, sorted.
  [[nodiscard]] virtual bool trainees(std::vector<std::string>& out, std::string& error) = 0;
  [[nodiscard]] virtual bool knows_recording(const std::string& hash, bool& known,
                                             std::string& error) = 0;

  // Lessons (SPEC §10). add_attempt(): a lesson step's flight (as add()) and its verdict in one
  // transaction, and the trainee's progress moved on: a pass to the next step (its failed
  // attempts 0), a failure one more failed attempt at this step. The attempt must be at the
  // step the trainee is on (else it is refused with the reason, nothing written: another
  // station moved them on); a known recording adds nothing (already_known).
  [[nodiscard]] virtual std::optional<Added> add_attempt(const FlightRecord& f,
                                                         const LessonAttempt& a,
                                                         std::string& error) = 0;
  // Every lesson `trainee` has attempted ("": every trainee's), by trainee, lesson, hash.
  [[nodiscard]] virtual bool lesson_progress(const std::string& trainee,
                                             std::vector<LessonProgress>& out,
                                             std::string& error) = 0;
  // The attempts of `trainee` at the lesson (name and hash), oldest first.
  [[nodiscard]] virtual bool lesson_attempts(const std::string& trainee, const std::string& lesson,
                                             const std::string& lesson_hash,
                                             std::vector<StoredAttempt>& out,
                                             std::string& error) = 0;
  // The trainee starts the lesson over (step 0, no failed attempt, updated now: the row stays,
  // so a push carries the reset); the attempts stay.
  [[nodiscard]] virtual bool reset_lesson(const std::string& trainee, const std::string& lesson,
                                          const std::string& lesson_hash, std::string& error) = 0;

  // For push (core/history/push.hpp), which copies every table of the schema:
  // copy_flight(): a flight read from another store, with its metrics and, for a lesson
  // attempt, the attempt's row as it is (the progress is merged apart), in one transaction. A
  // flight is the same one here when a recorded flight's recording hash is, or an unrecorded
  // flight's trainee, station and start time (to the millisecond) are; such a flight is not
  // added again, but gains its attempt's row when it lacks it (a store pushed to by a mixpilot
  // that did not copy attempts).
  struct Copied {
    bool flight = false;   // the flight was added
    bool attempt = false;  // its attempt's row was added
  };
  [[nodiscard]] virtual std::optional<Copied> copy_flight(const StoredFlight& f,
                                                          std::string& error) = 0;
  // merge_progress(): the trainee's place in a lesson as `p` says, when this store has none or
  // an older one (by updated_unix_ms: the newest wins, so the same row twice writes nothing).
  // true when written.
  [[nodiscard]] virtual std::optional<bool> merge_progress(const LessonProgress& p,
                                                           std::string& error) = 0;
  virtual std::string where() const = 0;  // for messages: the file, or the server WITHOUT credentials
};

// "" → the default SQLite file $XDG_DATA_HOME/mixpilot/history.sqlite (~/.local/share/...), a
// path or sqlite:PATH → SQLite; postgresql://… or postgres://… → PostgreSQL (open_postgres()).
// nullptr with the reason, which names the location (never a password).
std::unique_ptr<HistoryStore> open_history(const std::string& location, std::string& error);
// The default SQLite file; "" with `why` when the user has no home folder.
std::string default_history_path(std::string* why = nullptr);
// The files an SQLite history at `location` (as open_history takes it) consists of: the
// database and its -wal, -shm and -journal companions. None for PostgreSQL, "off" or no home.
std::vector<std::string> sqlite_files(const std::string& location);

// Names are shown in terminals, tables, HTML and stored in PostgreSQL, which accepts only UTF-8:
// a trainee's name is 1 to kMaxNameChars characters of valid UTF-8 without control characters.
inline constexpr std::size_t kMaxNameChars = 200;
// "" when `name` is acceptable as a trainee's name, else why not.
std::string check_trainee(std::string_view name);
// "" when the record can be stored (the trainee's name as above; every text valid UTF-8 and at
// most kMaxTextBytes; metric names as a trainee's), else why not. Both backends call it.
inline constexpr std::size_t kMaxTextBytes = 4096;
std::string check_record(const FlightRecord& f);
// "" when the attempt can be stored (its texts as check_record's, 0 ≤ step < steps, the ceiling
// in (0, 1], a failed criterion exactly when it failed), else why not.
std::string check_attempt(const LessonAttempt& a);
// "" when the progress row can be stored (the trainee's name as above, the lesson's texts,
// 1 ≤ steps, 0 ≤ step ≤ steps, failed attempts ≥ 0), else why not.
std::string check_progress(const LessonProgress& p);
// The progress after `a`, from `before` (the trainee's progress at that lesson, step 0 when
// none): passed → the next step, failed → one more failed attempt. "" in `why` when `a` is at
// the step `before` is on, else why it is refused.
LessonProgress progress_after(const LessonProgress& before, const LessonAttempt& a,
                              std::string& why);

// This machine's host name ("" when it has none).
std::string host_name();
// Who flies when nobody said: the account's login name ("" when it has none).
std::string login_name();

}  // namespace mixpilot::history
