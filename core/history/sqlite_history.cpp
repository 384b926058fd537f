#include "core/history/sqlite_history.hpp"

#include <sqlite3.h>
#include <sys/stat.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <unordered_map>

#include "core/history/schema.hpp"

namespace mixpilot::history {

namespace {

namespace fs = std::filesystem;

std::int64_t now_unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Makes the missing folders of `dir`, each mode 700 (a person's flights are theirs).
bool make_folders(const fs::path& dir, std::string& error) {
  if (dir.empty()) return true;
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return true;
  if (!make_folders(dir.parent_path(), error)) return false;
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    error = "cannot make the folder " + dir.string() + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

// One prepared statement, finalized when it goes.
class Stmt {
 public:
  Stmt() = default;
  Stmt(Stmt&& o) noexcept : s_(std::exchange(o.s_, nullptr)) {}
  Stmt& operator=(Stmt&& o) noexcept {
    std::swap(s_, o.s_);
    return *this;
  }
  ~Stmt() { sqlite3_finalize(s_); }
  sqlite3_stmt* get() const { return s_; }
  sqlite3_stmt** out() { return &s_; }

 private:
  sqlite3_stmt* s_ = nullptr;
};

class SqliteHistory final : public HistoryStore {
 public:
  SqliteHistory(std::string path, sqlite3* db) : path_(std::move(path)), db_(db) {}
  ~SqliteHistory() override { sqlite3_close_v2(db_); }

  [[nodiscard]] bool init(const SqliteSettings& s, std::string& error);
  std::optional<Added> add(const FlightRecord& f, std::string& error) override;
  bool query(const Query& q, std::vector<StoredFlight>& out, std::string& error) override;
  bool trainees(std::vector<std::string>& out, std::string& error) override;
  bool knows_recording(const std::string& hash, bool& known, std::string& error) override;
  std::optional<Added> add_attempt(const FlightRecord& f, const LessonAttempt& a,
                                   std::string& error) override;
  bool lesson_progress(const std::string& trainee, std::vector<LessonProgress>& out,
                       std::string& error) override;
  bool lesson_attempts(const std::string& trainee, const std::string& lesson,
                       const std::string& lesson_hash, std::vector<StoredAttempt>& out,
                       std::string& error) override;
  bool reset_lesson(const std::string& trainee, const std::string& lesson,
                    const std::string& lesson_hash, std::string& error) override;
  std::optional<Copied> copy_flight(const StoredFlight& f, std::string& error) override;
  std::optional<bool> merge_progress(const LessonProgress& p, std::string& error) override;
  std::string where() const override { return path_; }

 private:
  // Inside a write transaction: the flight's rows (trainee, flight, metrics). The new flight's
  // id and its trainee's; 0 when its recording is known (nothing written); nullopt with the
  // error (the caller rolls back).
  struct Inserted {
    std::int64_t flight_id = 0, trainee_id = 0;
  };
  std::optional<Inserted> insert_flight(const FlightRecord& f, std::string& error);
  // Inside a transaction: the flight here that is `f` (copy_flight's match), or a zero id.
  std::optional<Inserted> find_flight(const FlightRecord& f, std::string& error);
  // Inside a transaction: the attempt's row of the flight `in`, unless it has one; whether
  // it was added.
  std::optional<bool> insert_attempt(const Inserted& in, const LessonAttempt& a,
                                     std::string& error);
  // "FILE: what failed: SQLite's message", with the usual causes said in words.
  std::string fail(const char* what) const;
  bool exec(const char* sql, std::string& error, const char* what);
  bool prepare(Stmt& s, const char* sql, std::string& error);
  // Ends a transaction that failed on the way (the error is already said).
  void rollback() { sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr); }

  std::string path_;
  sqlite3* db_;
};

std::string SqliteHistory::fail(const char* what) const {
  const int code = sqlite3_extended_errcode(db_) & 0xFF;
  std::string m = path_ + ": " + what + ": " + sqlite3_errmsg(db_);
  switch (code) {
    case SQLITE_NOTADB:
    case SQLITE_CORRUPT:
      m += " (the file is damaged or not a mixpilot history; move it aside to start a new one)";
      break;
    case SQLITE_READONLY:
    case SQLITE_CANTOPEN:
    case SQLITE_PERM:
      m += " (the file or its folder cannot be written)";
      break;
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      m += " (another program holds the database locked)";
      break;
    case SQLITE_FULL:
      m += " (the disk is full)";
      break;
    default:
      break;
  }
  return m;
}

bool SqliteHistory::exec(const char* sql, std::string& error, const char* what) {
  if (sqlite3_exec(db_, sql, nullptr, nullptr, nullptr) == SQLITE_OK) return true;
  error = fail(what);
  return false;
}

bool SqliteHistory::prepare(Stmt& s, const char* sql, std::string& error) {
  if (sqlite3_prepare_v2(db_, sql, -1, s.out(), nullptr) == SQLITE_OK) return true;
  error = fail("preparing a statement");
  return false;
}

bool SqliteHistory::init(const SqliteSettings& s, std::string& error) {
  sqlite3_extended_result_codes(db_, 1);
  sqlite3_busy_timeout(db_, s.busy_timeout_ms);
  if (!exec("PRAGMA foreign_keys = ON", error, "cannot switch foreign keys on")) return false;
  // WAL: readers (a `history` listing) never wait for a writer (a flight closing). Switching a
  // new file to WAL needs its exclusive lock, and SQLite answers SQLITE_BUSY at once, without the
  // busy handler, when another process opening the same new file holds a lock it must wait for:
  // retried here for as long as the busy timeout.
  {
    Stmt wal;
    if (!prepare(wal, "PRAGMA journal_mode = WAL", error)) return false;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(s.busy_timeout_ms);
    int rc = sqlite3_step(wal.get());
    while ((rc & 0xFF) == SQLITE_BUSY && std::chrono::steady_clock::now() < deadline) {
      sqlite3_reset(wal.get());
      sqlite3_sleep(5);
      rc = sqlite3_step(wal.get());
    }
    if (rc != SQLITE_ROW) {
      error = fail("cannot open");
      return false;
    }
  }
  // The schema: read and migrated under the writer's lock, so two processes opening a new file
  // at once migrate it once.
  if (!exec("BEGIN IMMEDIATE", error, "cannot lock the history to check its schema")) return false;
  if (!exec(kCreateVersionTable, error, "cannot create the schema")) return rollback(), false;
  int version = 0;
  {
    Stmt v;
    if (!prepare(v, kReadVersion, error)) return rollback(), false;
    if (sqlite3_step(v.get()) != SQLITE_ROW) {
      error = fail("cannot read the schema version");
      return rollback(), false;
    }
    version = sqlite3_column_int(v.get(), 0);
  }
  if (std::string why = newer_schema_message(version, path_); !why.empty()) {
    error = why;
    return rollback(), false;
  }
  for (const Statement& st : pending(version, Dialect::sqlite)) {
    Stmt m;
    if (!prepare(m, st.sql.c_str(), error)) return rollback(), false;
    if (st.takes_time) sqlite3_bind_int64(m.get(), 1, now_unix_ms());
    if (sqlite3_step(m.get()) != SQLITE_DONE) {
      error = fail("cannot migrate the schema");
      return rollback(), false;
    }
  }
  if (!exec("COMMIT", error, "cannot write the schema")) return rollback(), false;
  return true;
}

// Binds `text` as the parameter `i`; an empty text as NULL when `null_if_empty`.
void bind_text(sqlite3_stmt* s, int i, const std::string& text, bool null_if_empty = false) {
  if (null_if_empty && text.empty())
    sqlite3_bind_null(s, i);
  else
    sqlite3_bind_text(s, i, text.data(), int(text.size()), SQLITE_TRANSIENT);
}

std::string column_text(sqlite3_stmt* s, int i) {
  const auto* p = reinterpret_cast<const char*>(sqlite3_column_text(s, i));
  return p ? std::string(p, std::size_t(sqlite3_column_bytes(s, i))) : std::string();
}

std::optional<SqliteHistory::Inserted> SqliteHistory::insert_flight(const FlightRecord& f,
                                                                  std::string& error) {
  if (!f.recording_hash.empty()) {
    Stmt k;
    if (!prepare(k, "SELECT 1 FROM flights WHERE recording_hash = ?", error)) return std::nullopt;
    bind_text(k.get(), 1, f.recording_hash);
    const int rc = sqlite3_step(k.get());
    if (rc == SQLITE_ROW) return Inserted{};  // nothing was written
    if (rc != SQLITE_DONE) {
      error = fail("cannot look the recording up");
      return std::nullopt;
    }
  }
  Inserted out;
  {
    Stmt t;
    if (!prepare(t, "INSERT INTO trainees (name) VALUES (?) ON CONFLICT (name) DO NOTHING", error))
      return std::nullopt;
    bind_text(t.get(), 1, f.trainee);
    if (sqlite3_step(t.get()) != SQLITE_DONE) {
      error = fail("cannot add the trainee");
      return std::nullopt;
    }
    Stmt id;
    if (!prepare(id, "SELECT id FROM trainees WHERE name = ?", error)) return std::nullopt;
    bind_text(id.get(), 1, f.trainee);
    if (sqlite3_step(id.get()) != SQLITE_ROW) {
      error = fail("cannot find the trainee");
      return std::nullopt;
    }
    out.trainee_id = sqlite3_column_int64(id.get(), 0);
  }
  {
    Stmt s;
    if (!prepare(s,
                 "INSERT INTO flights (trainee_id, station, scenario, scenario_hash, mode, pilot, "
                 "input_device, input_settings_hash, started_unix_ms, duration_s, ended, probe, "
                 "recording_path, recording_hash, app_version, front_end, parent_recording_hash, "
                 "parent_step, ended_by) "
                 "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) RETURNING id",
                 error))
      return std::nullopt;
    sqlite3_stmt* p = s.get();
    sqlite3_bind_int64(p, 1, out.trainee_id);
    bind_text(p, 2, f.station);
    bind_text(p, 3, f.scenario);
    bind_text(p, 4, f.scenario_hash);
    bind_text(p, 5, f.mode);
    bind_text(p, 6, f.pilot);
    bind_text(p, 7, f.input_device);
    bind_text(p, 8, f.input_settings_hash);
    sqlite3_bind_int64(p, 9, f.started_unix_ms);
    sqlite3_bind_double(p, 10, f.duration_s);
    // The instructor's end is stored as interrupted, with who ended it (schema migration 5).
    const bool by_instructor = f.ended == Ended::instructor;
    bind_text(p, 11, to_string(by_instructor ? Ended::interrupted : f.ended));
    sqlite3_bind_int(p, 12, f.probe ? 1 : 0);
    bind_text(p, 13, f.recording_path, true);
    bind_text(p, 14, f.recording_hash, true);
    bind_text(p, 15, f.app_version);
    bind_text(p, 16, f.front_end);
    bind_text(p, 17, f.parent_recording_hash, true);
    if (f.branch())
      sqlite3_bind_int64(p, 18, f.parent_step);
    else
      sqlite3_bind_null(p, 18);
    bind_text(p, 19, by_instructor ? "instructor" : "", true);
    if (sqlite3_step(p) != SQLITE_ROW) {
      error = fail("cannot add the flight");
      return std::nullopt;
    }
    out.flight_id = sqlite3_column_int64(p, 0);
  }
  {
    Stmt m;
    if (!prepare(m, "INSERT INTO metrics (flight_id, position, name, value) VALUES (?, ?, ?, ?)",
                 error))
      return std::nullopt;
    for (std::size_t i = 0; i < f.metrics.size(); ++i) {
      sqlite3_reset(m.get());
      sqlite3_bind_int64(m.get(), 1, out.flight_id);
      sqlite3_bind_int64(m.get(), 2, std::int64_t(i));
      bind_text(m.get(), 3, f.metrics[i].first);
      // Not a finite number: NULL (as the reports' JSON null).
      if (std::isfinite(f.metrics[i].second))
        sqlite3_bind_double(m.get(), 4, f.metrics[i].second);
      else
        sqlite3_bind_null(m.get(), 4);
      if (sqlite3_step(m.get()) != SQLITE_DONE) {
        error = fail("cannot add the flight's metrics");
        return std::nullopt;
      }
    }
  }
  return out;
}

std::optional<HistoryStore::Added> SqliteHistory::add(const FlightRecord& f, std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = path_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  if (!exec("BEGIN IMMEDIATE", error, "cannot lock the history to add a flight"))
    return std::nullopt;
  const std::optional<Inserted> in = insert_flight(f, error);
  if (!in) return rollback(), std::nullopt;
  if (in->flight_id == 0) {
    rollback();  // nothing was written
    return Added::already_known;
  }
  if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK) {
    error = fail("cannot commit the flight");
    rollback();
    return std::nullopt;
  }
  return Added::added;
}

std::optional<HistoryStore::Added> SqliteHistory::add_attempt(const FlightRecord& f,
                                                              const LessonAttempt& a,
                                                              std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = path_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  if (std::string why = check_attempt(a); !why.empty()) {
    error = path_ + ": the lesson attempt is not stored: " + why;
    return std::nullopt;
  }
  if (!exec("BEGIN IMMEDIATE", error, "cannot lock the history to add a lesson attempt"))
    return std::nullopt;
  const auto failed = [&](const char* what) {
    error = fail(what);
    rollback();
    return std::nullopt;
  };
  const std::optional<Inserted> in = insert_flight(f, error);
  if (!in) return rollback(), std::nullopt;
  if (in->flight_id == 0) {
    rollback();
    return Added::already_known;
  }
  LessonProgress before;
  before.step = 0;
  {
    Stmt p;
    if (!prepare(p,
                 "SELECT steps, step, failed_attempts FROM lesson_progress WHERE trainee_id = ? "
                 "AND lesson = ? AND lesson_hash = ?",
                 error))
      return rollback(), std::nullopt;
    sqlite3_bind_int64(p.get(), 1, in->trainee_id);
    bind_text(p.get(), 2, a.lesson);
    bind_text(p.get(), 3, a.lesson_hash);
    const int rc = sqlite3_step(p.get());
    if (rc == SQLITE_ROW) {
      before.steps = sqlite3_column_int(p.get(), 0);
      before.step = sqlite3_column_int(p.get(), 1);
      before.failed_attempts = sqlite3_column_int(p.get(), 2);
    } else if (rc != SQLITE_DONE) {
      return failed("cannot read the lesson's progress");
    }
  }
  std::string why;
  const LessonProgress after = progress_after(before, a, why);
  if (!why.empty()) {
    rollback();
    error = path_ + ": the lesson attempt is not stored: " + why;
    return std::nullopt;
  }
  if (!insert_attempt(*in, a, error)) return rollback(), std::nullopt;
  {
    Stmt s;
    if (!prepare(s,
                 "INSERT INTO lesson_progress (trainee_id, lesson, lesson_hash, steps, step, "
                 "failed_attempts, updated_unix_ms) VALUES (?, ?, ?, ?, ?, ?, ?) "
                 "ON CONFLICT (trainee_id, lesson, lesson_hash) DO UPDATE SET "
                 "steps = excluded.steps, step = excluded.step, "
                 "failed_attempts = excluded.failed_attempts, "
                 "updated_unix_ms = excluded.updated_unix_ms",
                 error))
      return rollback(), std::nullopt;
    sqlite3_stmt* p = s.get();
    sqlite3_bind_int64(p, 1, in->trainee_id);
    bind_text(p, 2, a.lesson);
    bind_text(p, 3, a.lesson_hash);
    sqlite3_bind_int(p, 4, after.steps);
    sqlite3_bind_int(p, 5, after.step);
    sqlite3_bind_int(p, 6, after.failed_attempts);
    sqlite3_bind_int64(p, 7, now_unix_ms());
    if (sqlite3_step(p) != SQLITE_DONE) return failed("cannot move the lesson's progress on");
  }
  if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK)
    return failed("cannot commit the lesson attempt");
  return Added::added;
}

std::optional<bool> SqliteHistory::insert_attempt(const Inserted& in, const LessonAttempt& a,
                                                  std::string& error) {
  Stmt s;
  if (!prepare(s,
               "INSERT INTO lesson_attempts (flight_id, trainee_id, lesson, lesson_hash, step, "
               "step_title, ceiling, passed, failed_criterion, detail) "
               "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?) ON CONFLICT (flight_id) DO NOTHING",
               error))
    return std::nullopt;
  sqlite3_stmt* p = s.get();
  sqlite3_bind_int64(p, 1, in.flight_id);
  sqlite3_bind_int64(p, 2, in.trainee_id);
  bind_text(p, 3, a.lesson);
  bind_text(p, 4, a.lesson_hash);
  sqlite3_bind_int(p, 5, a.step);
  bind_text(p, 6, a.step_title);
  sqlite3_bind_double(p, 7, a.ceiling);
  sqlite3_bind_int(p, 8, a.passed ? 1 : 0);
  bind_text(p, 9, a.failed_criterion, true);
  bind_text(p, 10, a.detail);
  if (sqlite3_step(p) != SQLITE_DONE) {
    error = fail("cannot add the lesson attempt");
    return std::nullopt;
  }
  return sqlite3_changes(db_) > 0;
}

std::optional<SqliteHistory::Inserted> SqliteHistory::find_flight(const FlightRecord& f,
                                                                std::string& error) {
  Stmt s;
  const bool recorded = !f.recording_hash.empty();
  if (!prepare(s,
               recorded ? "SELECT id, trainee_id FROM flights WHERE recording_hash = ?"
                        : "SELECT f.id, f.trainee_id FROM flights f JOIN trainees t ON "
                          "t.id = f.trainee_id WHERE f.recording_hash IS NULL AND t.name = ? AND "
                          "f.station = ? AND f.started_unix_ms = ? ORDER BY f.id LIMIT 1",
               error))
    return std::nullopt;
  if (recorded) {
    bind_text(s.get(), 1, f.recording_hash);
  } else {
    bind_text(s.get(), 1, f.trainee);
    bind_text(s.get(), 2, f.station);
    sqlite3_bind_int64(s.get(), 3, f.started_unix_ms);
  }
  const int rc = sqlite3_step(s.get());
  if (rc == SQLITE_DONE) return Inserted{};
  if (rc != SQLITE_ROW) {
    error = fail("cannot look the flight up");
    return std::nullopt;
  }
  return Inserted{sqlite3_column_int64(s.get(), 0), sqlite3_column_int64(s.get(), 1)};
}

std::optional<HistoryStore::Copied> SqliteHistory::copy_flight(const StoredFlight& f,
                                                               std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = path_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  const LessonAttempt a = f.as_attempt();
  if (f.attempt())
    if (std::string why = check_attempt(a); !why.empty()) {
      error = path_ + ": the lesson attempt is not stored: " + why;
      return std::nullopt;
    }
  if (!exec("BEGIN IMMEDIATE", error, "cannot lock the history to add a flight"))
    return std::nullopt;
  Copied c;
  std::optional<Inserted> in = find_flight(f, error);
  if (in && in->flight_id == 0) {
    in = insert_flight(f, error);
    c.flight = true;
  }
  if (!in) return rollback(), std::nullopt;
  if (f.attempt()) {
    const std::optional<bool> added = insert_attempt(*in, a, error);
    if (!added) return rollback(), std::nullopt;
    c.attempt = *added;
  }
  if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK) {
    error = fail("cannot commit the flight");
    rollback();
    return std::nullopt;
  }
  return c;
}

std::optional<bool> SqliteHistory::merge_progress(const LessonProgress& lp, std::string& error) {
  if (std::string why = check_progress(lp); !why.empty()) {
    error = path_ + ": the lesson's progress is not stored: " + why;
    return std::nullopt;
  }
  if (!exec("BEGIN IMMEDIATE", error, "cannot lock the history to merge a lesson's progress"))
    return std::nullopt;
  {
    Stmt t;
    if (!prepare(t, "INSERT INTO trainees (name) VALUES (?) ON CONFLICT (name) DO NOTHING", error))
      return rollback(), std::nullopt;
    bind_text(t.get(), 1, lp.trainee);
    if (sqlite3_step(t.get()) != SQLITE_DONE) {
      error = fail("cannot add the trainee");
      return rollback(), std::nullopt;
    }
  }
  bool written = false;
  {
    Stmt s;
    if (!prepare(s,
                 "INSERT INTO lesson_progress (trainee_id, lesson, lesson_hash, steps, step, "
                 "failed_attempts, updated_unix_ms) VALUES ((SELECT id FROM trainees WHERE "
                 "name = ?), ?, ?, ?, ?, ?, ?) "
                 "ON CONFLICT (trainee_id, lesson, lesson_hash) DO UPDATE SET "
                 "steps = excluded.steps, step = excluded.step, "
                 "failed_attempts = excluded.failed_attempts, "
                 "updated_unix_ms = excluded.updated_unix_ms "
                 "WHERE excluded.updated_unix_ms > lesson_progress.updated_unix_ms",
                 error))
      return rollback(), std::nullopt;
    sqlite3_stmt* p = s.get();
    bind_text(p, 1, lp.trainee);
    bind_text(p, 2, lp.lesson);
    bind_text(p, 3, lp.lesson_hash);
    sqlite3_bind_int(p, 4, lp.steps);
    sqlite3_bind_int(p, 5, lp.step);
    sqlite3_bind_int(p, 6, lp.failed_attempts);
    sqlite3_bind_int64(p, 7, lp.updated_unix_ms);
    if (sqlite3_step(p) != SQLITE_DONE) {
      error = fail("cannot merge the lesson's progress");
      return rollback(), std::nullopt;
    }
    written = sqlite3_changes(db_) > 0;
  }
  if (sqlite3_exec(db_, "COMMIT", nullptr, nullptr, nullptr) != SQLITE_OK) {
    error = fail("cannot commit the lesson's progress");
    rollback();
    return std::nullopt;
  }
  return written;
}

bool SqliteHistory::lesson_progress(const std::string& trainee, std::vector<LessonProgress>& out,
                                    std::string& error) {
  out.clear();
  Stmt s;
  if (!prepare(s,
               "SELECT t.name, p.lesson, p.lesson_hash, p.steps, p.step, p.failed_attempts, "
               "p.updated_unix_ms FROM lesson_progress p JOIN trainees t ON t.id = p.trainee_id "
               "WHERE (?1 = '' OR t.name = ?1) ORDER BY t.name, p.lesson, p.updated_unix_ms",
               error))
    return false;
  bind_text(s.get(), 1, trainee);
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    sqlite3_stmt* p = s.get();
    LessonProgress l;
    l.trainee = column_text(p, 0);
    l.lesson = column_text(p, 1);
    l.lesson_hash = column_text(p, 2);
    l.steps = sqlite3_column_int(p, 3);
    l.step = sqlite3_column_int(p, 4);
    l.failed_attempts = sqlite3_column_int(p, 5);
    l.updated_unix_ms = sqlite3_column_int64(p, 6);
    out.push_back(std::move(l));
  }
  if (rc == SQLITE_DONE) return true;
  error = fail("cannot read the lessons' progress");
  return false;
}

bool SqliteHistory::lesson_attempts(const std::string& trainee, const std::string& lesson,
                                    const std::string& lesson_hash,
                                    std::vector<StoredAttempt>& out, std::string& error) {
  out.clear();
  Stmt s;
  if (!prepare(s,
               "SELECT a.id, a.flight_id, t.name, a.lesson, a.lesson_hash, a.step, a.step_title, "
               "a.ceiling, a.passed, a.failed_criterion, a.detail, f.started_unix_ms, "
               "f.recording_path, f.probe, m.value, "
               "(SELECT p.steps FROM lesson_progress p WHERE p.trainee_id = a.trainee_id AND "
               "p.lesson = a.lesson AND p.lesson_hash = a.lesson_hash) "
               "FROM lesson_attempts a JOIN trainees t ON t.id = a.trainee_id "
               "JOIN flights f ON f.id = a.flight_id "
               "LEFT JOIN metrics m ON m.flight_id = a.flight_id AND m.name = 'skill' "
               "WHERE t.name = ? AND a.lesson = ? AND a.lesson_hash = ? ORDER BY a.id",
               error))
    return false;
  bind_text(s.get(), 1, trainee);
  bind_text(s.get(), 2, lesson);
  bind_text(s.get(), 3, lesson_hash);
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
    sqlite3_stmt* p = s.get();
    StoredAttempt a;
    a.id = sqlite3_column_int64(p, 0);
    a.flight_id = sqlite3_column_int64(p, 1);
    a.trainee = column_text(p, 2);
    a.lesson = column_text(p, 3);
    a.lesson_hash = column_text(p, 4);
    a.step = sqlite3_column_int(p, 5);
    a.step_title = column_text(p, 6);
    a.ceiling = sqlite3_column_double(p, 7);
    a.passed = sqlite3_column_int(p, 8) != 0;
    a.failed_criterion = column_text(p, 9);
    a.detail = column_text(p, 10);
    a.started_unix_ms = sqlite3_column_int64(p, 11);
    a.recording_path = column_text(p, 12);
    a.probe = sqlite3_column_int(p, 13) != 0;
    a.skill = sqlite3_column_type(p, 14) == SQLITE_NULL ? std::numeric_limits<double>::quiet_NaN()
                                                        : sqlite3_column_double(p, 14);
    a.steps = sqlite3_column_int(p, 15);
    out.push_back(std::move(a));
  }
  if (rc == SQLITE_DONE) return true;
  error = fail("cannot read the lesson's attempts");
  return false;
}

bool SqliteHistory::reset_lesson(const std::string& trainee, const std::string& lesson,
                                 const std::string& lesson_hash, std::string& error) {
  Stmt s;
  if (!prepare(s,
               "UPDATE lesson_progress SET step = 0, failed_attempts = 0, updated_unix_ms = ? "
               "WHERE trainee_id = (SELECT id FROM trainees WHERE name = ?) AND lesson = ? AND "
               "lesson_hash = ?",
               error))
    return false;
  sqlite3_bind_int64(s.get(), 1, now_unix_ms());
  bind_text(s.get(), 2, trainee);
  bind_text(s.get(), 3, lesson);
  bind_text(s.get(), 4, lesson_hash);
  if (sqlite3_step(s.get()) == SQLITE_DONE) return true;
  error = fail("cannot start the lesson over");
  return false;
}

bool SqliteHistory::query(const Query& q, std::vector<StoredFlight>& out, std::string& error) {
  out.clear();
  // The newest `limit` flights that pass the filters, read oldest first; the same filter picks
  // their metrics. Readers take a snapshot (WAL): one transaction for both statements.
  static constexpr const char* kFilter =
      " FROM flights f JOIN trainees t ON t.id = f.trainee_id"
      " LEFT JOIN lesson_attempts a ON a.flight_id = f.id"
      " WHERE (?1 = '' OR t.name = ?1) AND (?2 = '' OR f.scenario = ?2)"
      " AND f.started_unix_ms >= ?3";
  static constexpr const char* kColumns =
      "SELECT f.id, t.name, f.station, f.scenario, f.scenario_hash, f.mode, f.pilot, "
      "f.input_device, f.input_settings_hash, f.started_unix_ms, f.duration_s, f.ended, f.probe, "
      "f.recording_path, f.recording_hash, f.app_version, f.front_end, "
      "f.parent_recording_hash, f.parent_step, f.ended_by, a.lesson, a.step, a.passed, "
      "a.failed_criterion, a.lesson_hash, a.step_title, a.ceiling, a.detail";
  // Without a limit the start-time index gives the order as it is: no sort of every row.
  const std::string flights_sql =
      q.limit > 0 ? std::string("SELECT * FROM (") + kColumns + kFilter +
                        " ORDER BY f.started_unix_ms DESC, f.id DESC LIMIT ?4)" +
                        " ORDER BY started_unix_ms, id"
                  : std::string(kColumns) + kFilter + " ORDER BY f.started_unix_ms, f.id";
  if (!exec("BEGIN", error, "cannot read the history")) return false;
  const auto bind_filter = [&](sqlite3_stmt* s) {
    bind_text(s, 1, q.trainee);
    bind_text(s, 2, q.scenario);
    sqlite3_bind_int64(s, 3, q.since_unix_ms);
  };
  {
    Stmt s;
    if (!prepare(s, flights_sql.c_str(), error)) return rollback(), false;
    bind_filter(s.get());
    if (q.limit > 0) sqlite3_bind_int64(s.get(), 4, q.limit);
    int rc;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      sqlite3_stmt* p = s.get();
      StoredFlight f;
      f.id = sqlite3_column_int64(p, 0);
      f.trainee = column_text(p, 1);
      f.station = column_text(p, 2);
      f.scenario = column_text(p, 3);
      f.scenario_hash = column_text(p, 4);
      f.mode = column_text(p, 5);
      f.pilot = column_text(p, 6);
      f.input_device = column_text(p, 7);
      f.input_settings_hash = column_text(p, 8);
      f.started_unix_ms = sqlite3_column_int64(p, 9);
      f.duration_s = sqlite3_column_double(p, 10);
      f.ended = ended_from(column_text(p, 11)).value_or(Ended::completed);
      f.probe = sqlite3_column_int(p, 12) != 0;
      f.recording_path = column_text(p, 13);
      f.recording_hash = column_text(p, 14);
      f.app_version = column_text(p, 15);
      f.front_end = column_text(p, 16);
      f.parent_recording_hash = column_text(p, 17);
      f.parent_step = sqlite3_column_type(p, 18) == SQLITE_NULL ? -1 : sqlite3_column_int64(p, 18);
      if (column_text(p, 19) == "instructor") f.ended = Ended::instructor;
      if (sqlite3_column_type(p, 20) != SQLITE_NULL) {
        f.lesson = column_text(p, 20);
        f.lesson_step = sqlite3_column_int(p, 21);
        f.lesson_passed = sqlite3_column_int(p, 22) != 0;
        f.lesson_failed = column_text(p, 23);
        f.lesson_hash = column_text(p, 24);
        f.lesson_step_title = column_text(p, 25);
        f.lesson_ceiling = sqlite3_column_double(p, 26);
        f.lesson_detail = column_text(p, 27);
      }
      out.push_back(std::move(f));
    }
    if (rc != SQLITE_DONE) {
      error = fail("cannot read the flights");
      return rollback(), false;
    }
  }
  if (!out.empty()) {
    std::unordered_map<std::int64_t, std::size_t> at;
    at.reserve(out.size());
    std::int64_t first = std::numeric_limits<std::int64_t>::max();
    for (std::size_t i = 0; i < out.size(); ++i) {
      at.emplace(out[i].id, i);
      first = std::min(first, out[i].id);
    }
    // The metrics of the same filter (those of flights past the limit are skipped by id), only
    // the names asked for when some are.
    // Every metric: read in the metrics' own order. Some: looked up flight by flight through
    // the (flight, name) index, not found among every flight's twenty.
    std::string sql;
    if (q.metrics.empty()) {
      sql = "SELECT m.flight_id, m.name, m.value FROM metrics m"
            " JOIN flights f ON f.id = m.flight_id JOIN trainees t ON t.id = f.trainee_id"
            " WHERE (?1 = '' OR t.name = ?1) AND (?2 = '' OR f.scenario = ?2)"
            " AND f.started_unix_ms >= ?3 AND f.id >= ?4 ORDER BY m.flight_id, m.position";
    } else {
      // A range of the (name, flight, value) index per name; flights the filter left out are
      // skipped below, so the filter need not be joined again.
      // (?1 to ?3, the filter's, are bound below but unused here.)
      sql = "SELECT m.flight_id, m.name, m.value FROM metrics m WHERE m.flight_id >= ?4"
            " AND m.name IN (";
      for (std::size_t i = 0; i < q.metrics.size(); ++i) sql += i ? ", ?" : "?";  // ?5, ?6, ...
      sql += ")";
    }
    Stmt s;
    if (!prepare(s, sql.c_str(), error)) return rollback(), false;
    bind_filter(s.get());
    sqlite3_bind_int64(s.get(), 4, first);
    for (std::size_t i = 0; i < q.metrics.size(); ++i) bind_text(s.get(), int(5 + i), q.metrics[i]);
    int rc;
    while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) {
      const auto it = at.find(sqlite3_column_int64(s.get(), 0));
      if (it == at.end()) continue;
      const double v = sqlite3_column_type(s.get(), 2) == SQLITE_NULL
                           ? std::numeric_limits<double>::quiet_NaN()
                           : sqlite3_column_double(s.get(), 2);
      out[it->second].metrics.emplace_back(column_text(s.get(), 1), v);
    }
    if (rc != SQLITE_DONE) {
      error = fail("cannot read the metrics");
      return rollback(), false;
    }
  }
  return exec("COMMIT", error, "cannot read the history");
}

bool SqliteHistory::trainees(std::vector<std::string>& out, std::string& error) {
  out.clear();
  Stmt s;
  if (!prepare(s, "SELECT name FROM trainees ORDER BY name", error)) return false;
  int rc;
  while ((rc = sqlite3_step(s.get())) == SQLITE_ROW) out.push_back(column_text(s.get(), 0));
  if (rc == SQLITE_DONE) return true;
  error = fail("cannot read the trainees");
  return false;
}

bool SqliteHistory::knows_recording(const std::string& hash, bool& known, std::string& error) {
  Stmt s;
  if (!prepare(s, "SELECT 1 FROM flights WHERE recording_hash = ?", error)) return false;
  bind_text(s.get(), 1, hash);
  const int rc = sqlite3_step(s.get());
  if (rc != SQLITE_ROW && rc != SQLITE_DONE) {
    error = fail("cannot look the recording up");
    return false;
  }
  known = rc == SQLITE_ROW;
  return true;
}

}  // namespace

std::unique_ptr<HistoryStore> open_sqlite(const std::string& path, std::string& error,
                                          const SqliteSettings& settings) {
  if (path.empty()) {
    error = "the history's file name is empty";
    return nullptr;
  }
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    error = path + ": is a folder, not a history file";
    return nullptr;
  }
  // SQLite would make the history wherever a dangling link points: say it instead, as every
  // reader of the project says a link to nothing.
  if (fs::is_symlink(fs::symlink_status(path, ec)) && !fs::exists(path, ec)) {
    error = path + ": is a symbolic link to nothing (" + fs::read_symlink(path, ec).string() +
            "), not a history file";
    return nullptr;
  }
  if (settings.create_folder && !make_folders(fs::path(path).parent_path(), error)) return nullptr;
  sqlite3* db = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &db,
                                 SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX,
                                 nullptr);
  auto store = std::make_unique<SqliteHistory>(path, db);  // closes db on every way out
  if (rc != SQLITE_OK) {
    error = path + ": cannot open: " + (db ? sqlite3_errmsg(db) : sqlite3_errstr(rc));
    if ((rc & 0xFF) == SQLITE_CANTOPEN || (rc & 0xFF) == SQLITE_PERM ||
        (rc & 0xFF) == SQLITE_READONLY)
      error += " (the file or its folder cannot be written)";
    return nullptr;
  }
  if (!store->init(settings, error)) return nullptr;
  return store;
}

}  // namespace mixpilot::history
