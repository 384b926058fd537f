#pragma once
// The history's schema, one for both backends (SPEC §10): a schema_version table (one row per
// applied migration), trainees (unique name), flights (the FlightRecord's fields; a recording
// hash is unique, NULL for an unrecorded flight; a branch's parent recording hash and step,
// NULL for any other flight), metrics (flight, position, name, value), and the lessons'
// lesson_progress (trainee, lesson, step) and lesson_attempts (a flight's verdict).
// Forward migrations are an ordered list of SQL texts; the few words the dialects spell
// differently are written as {placeholders} and filled in by dialect().
//
// A backend opens its database thus, all in one transaction that holds the writer's lock (so
// two stations migrating at once run each migration once):
//   1. kCreateVersionTable
//   2. version = SELECT coalesce(max(version), 0) FROM schema_version
//   3. refuse a version newer than kSchemaVersion (newer_schema_message; nothing is written)
//   4. each statement of pending(version, dialect), in order
#include <string>
#include <string_view>
#include <vector>

namespace mixpilot::history {

enum class Dialect { sqlite, postgresql };

// The schema this build writes and reads.
inline constexpr int kSchemaVersion = 5;

inline constexpr const char* kCreateVersionTable =
    "CREATE TABLE IF NOT EXISTS schema_version (version INTEGER NOT NULL PRIMARY KEY, "
    "applied_unix_ms BIGINT NOT NULL)";
inline constexpr const char* kReadVersion = "SELECT coalesce(max(version), 0) FROM schema_version";

// `sql` in `d`: {pk} an auto-increment 64-bit primary key (SQLite INTEGER PRIMARY KEY, an alias
// of the rowid; PostgreSQL BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY), {real} a double.
std::string dialect(std::string_view sql, Dialect d);

// The statements that bring a database at `version` to kSchemaVersion, each migration's record
// in schema_version included (its applied time a bound parameter: the statement's one `?`,
// written `$1` for PostgreSQL). Empty when it is current.
struct Statement {
  std::string sql;
  bool takes_time = false;  // binds the current time (unix ms) as its one parameter
};
std::vector<Statement> pending(int version, Dialect d);

// Why a database at `found` cannot be used by this build ("" when it can): a newer schema is
// refused, never written, so an older mixpilot cannot damage what a newer one wrote.
std::string newer_schema_message(int found, const std::string& where);

}  // namespace mixpilot::history
