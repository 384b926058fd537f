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
// with ended_by 'instructor' (core/history/schema.cpp, migration 4).
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
struct StoredFlight : FlightRecord {
  std::int64_t id = 0;
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

// This machine's host name ("" when it has none).
std::string host_name();
// Who flies when nobody said: the account's login name ("" when it has none).
std::string login_name();

}  // namespace mixpilot::history
