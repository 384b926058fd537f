#include "core/history/schema.hpp"

namespace mixpilot::history {

namespace {

// Migration i (from 0) brings the schema from version i to i + 1. Never edit a released one:
// add the next.
const std::vector<std::vector<const char*>>& migrations() {
  static const std::vector<std::vector<const char*>> m = {
      // 1: trainees, flights, metrics.
      {
          "CREATE TABLE trainees (id {pk}, name TEXT NOT NULL UNIQUE)",
          "CREATE TABLE flights ("
          " id {pk},"
          " trainee_id BIGINT NOT NULL REFERENCES trainees (id),"
          " station TEXT NOT NULL,"
          " scenario TEXT NOT NULL,"
          " scenario_hash TEXT NOT NULL,"
          " mode TEXT NOT NULL,"
          " pilot TEXT NOT NULL,"
          " input_device TEXT NOT NULL,"
          " input_settings_hash TEXT NOT NULL,"
          " started_unix_ms BIGINT NOT NULL,"
          " duration_s {real} NOT NULL,"
          " ended TEXT NOT NULL CHECK (ended IN ('completed', 'interrupted', 'lost')),"
          " probe INTEGER NOT NULL CHECK (probe IN (0, 1)),"
          " recording_path TEXT,"
          " recording_hash TEXT UNIQUE,"  // NULL for an unrecorded flight: many may be NULL
          " app_version TEXT NOT NULL,"
          " front_end TEXT NOT NULL)",
          "CREATE INDEX flights_by_start ON flights (started_unix_ms, id)",
          "CREATE INDEX flights_by_trainee ON flights (trainee_id, started_unix_ms)",
          "CREATE INDEX flights_by_scenario ON flights (scenario, started_unix_ms)",
          // value NULL: not a finite number (JSON's null in the reports).
          "CREATE TABLE metrics ("
          " flight_id BIGINT NOT NULL REFERENCES flights (id) ON DELETE CASCADE,"
          " position INTEGER NOT NULL,"
          " name TEXT NOT NULL,"
          " value {real},"
          " PRIMARY KEY (flight_id, position),"
          " UNIQUE (flight_id, name))",
      },
      // 2: one score field of every flight (a listing's skill) read from an index alone, in
      // one pass, instead of found among each flight's twenty.
      {
          "CREATE INDEX metrics_by_name ON metrics (name, flight_id, value)",
      },
      // 3: fly from here (SPEC §10): a branch names its parent flight by that flight's
      // recording hash and the step it was taken over at (NULL for any other flight); the
      // branches of a flight are found through the index.
      {
          "ALTER TABLE flights ADD COLUMN parent_recording_hash TEXT",
          "ALTER TABLE flights ADD COLUMN parent_step BIGINT CHECK (parent_step >= 0)",
          "CREATE INDEX flights_by_parent ON flights (parent_recording_hash, parent_step)",
      },
      // 4: lessons (SPEC §10). A lesson is its name and the SHA-256 of its file (a changed file
      // is another lesson). lesson_progress: the step each trainee is on (0-based; = steps once
      // every step is passed) and the failed attempts at it since they reached it.
      // lesson_attempts: each attempt, one flight's row, with its verdict (failed_criterion
      // NULL when passed). A flight is at most one attempt.
      {
          "CREATE TABLE lesson_progress ("
          " trainee_id BIGINT NOT NULL REFERENCES trainees (id),"
          " lesson TEXT NOT NULL,"
          " lesson_hash TEXT NOT NULL,"
          " steps INTEGER NOT NULL CHECK (steps >= 1),"
          " step INTEGER NOT NULL CHECK (step >= 0 AND step <= steps),"
          " failed_attempts INTEGER NOT NULL CHECK (failed_attempts >= 0),"
          " updated_unix_ms BIGINT NOT NULL,"
          " PRIMARY KEY (trainee_id, lesson, lesson_hash))",
          "CREATE TABLE lesson_attempts ("
          " id {pk},"
          " flight_id BIGINT NOT NULL UNIQUE REFERENCES flights (id) ON DELETE CASCADE,"
          " trainee_id BIGINT NOT NULL REFERENCES trainees (id),"
          " lesson TEXT NOT NULL,"
          " lesson_hash TEXT NOT NULL,"
          " step INTEGER NOT NULL CHECK (step >= 0),"
          " step_title TEXT NOT NULL,"
          " ceiling {real} NOT NULL CHECK (ceiling > 0 AND ceiling <= 1),"
          " passed INTEGER NOT NULL CHECK (passed IN (0, 1)),"
          " failed_criterion TEXT,"
          " detail TEXT NOT NULL,"
          " CHECK ((passed = 1) = (failed_criterion IS NULL)))",
          "CREATE INDEX lesson_attempts_by_lesson ON lesson_attempts (trainee_id, lesson, "
          "lesson_hash, step, id)",
      },
      // 5: who ended a flight stopped before its end, when it was not the trainee: 'instructor'
      // (SPEC §10; its `ended` stays 'interrupted', which older readers understand), else NULL.
      {
          "ALTER TABLE flights ADD COLUMN ended_by TEXT CHECK (ended_by IN ('instructor'))",
      },
  };
  return m;
}

void replace_all(std::string& s, std::string_view what, std::string_view with) {
  for (std::size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + with.size()))
    s.replace(at, what.size(), with);
}

}  // namespace

std::string dialect(std::string_view sql, Dialect d) {
  std::string s(sql);
  replace_all(s, "{pk}", d == Dialect::sqlite ? "INTEGER PRIMARY KEY"
                                              : "BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY");
  replace_all(s, "{real}", d == Dialect::sqlite ? "REAL" : "DOUBLE PRECISION");
  return s;
}

std::vector<Statement> pending(int version, Dialect d) {
  std::vector<Statement> out;
  const auto& m = migrations();
  static_assert(kSchemaVersion >= 1);
  for (int v = version; v < int(m.size()) && v < kSchemaVersion; ++v) {
    for (const char* sql : m[std::size_t(v)]) out.push_back({dialect(sql, d), false});
    out.push_back({"INSERT INTO schema_version (version, applied_unix_ms) VALUES (" +
                       std::to_string(v + 1) + (d == Dialect::sqlite ? ", ?)" : ", $1)"),
                   true});
  }
  return out;
}

std::string newer_schema_message(int found, const std::string& where) {
  if (found <= kSchemaVersion) return {};
  return where + ": the history was written by a newer mixpilot (schema version " +
         std::to_string(found) + "; this one knows up to " + std::to_string(kSchemaVersion) +
         "): it is left untouched; update mixpilot to use it";
}

}  // namespace mixpilot::history
