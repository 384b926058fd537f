#include "core/history/postgres_history.hpp"

#include <libpq-fe.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <unordered_map>

#include "core/history/schema.hpp"

namespace mixpilot::history {

namespace {

std::int64_t now_unix_ms() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::string lower(std::string s) {
  for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string percent_decode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

bool is_url(const std::string& s) {
  return s.starts_with("postgresql://") || s.starts_with("postgres://");
}

// The key of a URL query parameter or a key=value pair names a password.
bool names_password(const std::string& key) {
  return lower(percent_decode(key)).find("password") != std::string::npos;
}

// Every spelling of every password `url` holds (as written and percent-decoded), longest
// first: messages are scrubbed of them, whatever libpq or the server echoes.
std::vector<std::string> secrets_of(const std::string& url) {
  std::vector<std::string> out;
  const auto keep = [&](const std::string& s) {
    if (s.empty()) return;
    out.push_back(s);
    out.push_back(percent_decode(s));
  };
  if (is_url(url)) {
    const std::size_t start = url.find("://") + 3;
    const std::size_t at = url.rfind('@');
    if (at != std::string::npos && at > start) {
      const std::string userinfo = url.substr(start, at - start);
      if (const std::size_t colon = userinfo.find(':'); colon != std::string::npos)
        keep(userinfo.substr(colon + 1));
    }
    if (const std::size_t q = url.find('?'); q != std::string::npos) {
      std::size_t i = q + 1;
      while (i <= url.size()) {
        std::size_t amp = url.find('&', i);
        if (amp == std::string::npos) amp = url.size();
        const std::string param = url.substr(i, amp - i);
        if (const std::size_t eq = param.find('=');
            eq != std::string::npos && names_password(param.substr(0, eq)))
          keep(param.substr(eq + 1));
        i = amp + 1;
      }
    }
  }
  char* err = nullptr;
  if (PQconninfoOption* opts = PQconninfoParse(url.c_str(), &err)) {
    for (PQconninfoOption* o = opts; o->keyword != nullptr; ++o)
      if (o->val != nullptr && names_password(o->keyword)) keep(o->val);
    PQconninfoFree(opts);
  }
  PQfreemem(err);
  // A key=value string: password = value, or 'quoted value'.
  if (!is_url(url)) {
    for (std::size_t at = lower(url).find("password"); at != std::string::npos;
         at = lower(url).find("password", at + 1)) {
      std::size_t i = url.find('=', at);
      if (i == std::string::npos) break;
      ++i;
      while (i < url.size() && std::isspace(static_cast<unsigned char>(url[i]))) ++i;
      std::size_t end = i;
      if (i < url.size() && url[i] == '\'') {
        end = url.find('\'', i + 1);
        keep(url.substr(i + 1, (end == std::string::npos ? url.size() : end) - i - 1));
      } else {
        while (end < url.size() && !std::isspace(static_cast<unsigned char>(url[end]))) ++end;
        keep(url.substr(i, end - i));
      }
    }
  }
  std::sort(out.begin(), out.end(),
            [](const std::string& a, const std::string& b) { return a.size() > b.size(); });
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::string scrub(std::string msg, const std::vector<std::string>& secrets) {
  for (const auto& s : secrets)
    for (std::size_t at = msg.find(s); at != std::string::npos; at = msg.find(s, at + 3))
      msg.replace(at, s.size(), "***");
  return msg;
}

// libpq's and the server's messages end in a newline and may span lines: one line each.
std::string one_line(const char* m) {
  std::string s = m ? m : "";
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n' || c == '\t') c = ' ';
  return s.empty() ? "no message" : s;
}

// The usual causes said in words.
std::string hint_for(const std::string& m, const char* sqlstate) {
  const std::string state = sqlstate ? sqlstate : "";
  if (state == "28P01" || state == "28000" ||
      m.find("password authentication failed") != std::string::npos)
    return " (check the user name and password the URL gives)";
  if (state == "3D000") return " (create the database first, or fix its name in the URL)";
  if (state.starts_with("57P") || m.find("server closed the connection") != std::string::npos ||
      m.find("no connection to the server") != std::string::npos)
    return " (the server stopped or restarted, or the network to it was cut)";
  if (state == "42501") return " (the user may not write this database)";
  if (m.find("Connection refused") != std::string::npos ||
      m.find("No such file or directory") != std::string::npos ||
      m.find("timeout expired") != std::string::npos ||
      m.find("could not translate host name") != std::string::npos)
    return " (is the server running and reachable from this station?)";
  return {};
}

// Doubles as text: the shortest form that reads back to the same value.
std::string number(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

double read_double(const char* s) {
  if (s == nullptr || *s == '\0') return std::numeric_limits<double>::quiet_NaN();
  double v = 0.0;
  const auto r = std::from_chars(s, s + std::strlen(s), v);
  if (r.ec == std::errc()) return v;
  if (std::strcmp(s, "Infinity") == 0) return std::numeric_limits<double>::infinity();
  if (std::strcmp(s, "-Infinity") == 0) return -std::numeric_limits<double>::infinity();
  return std::numeric_limits<double>::quiet_NaN();
}

std::int64_t read_int(const char* s) {
  std::int64_t v = 0;
  if (s != nullptr) std::from_chars(s, s + std::strlen(s), v);
  return v;
}

// A statement's parameters: text values or NULL.
class Params {
 public:
  Params& text(std::string v) {
    values_.push_back(std::move(v));
    null_.push_back(false);
    return *this;
  }
  Params& text_or_null(const std::string& v) { return v.empty() ? null() : text(v); }
  Params& integer(std::int64_t v) { return text(std::to_string(v)); }
  Params& null() {
    values_.emplace_back();
    null_.push_back(true);
    return *this;
  }
  int size() const { return int(values_.size()); }
  // Pointers into the values: valid while this object is unchanged.
  std::vector<const char*> pointers() const {
    std::vector<const char*> p;
    for (std::size_t i = 0; i < values_.size(); ++i)
      p.push_back(null_[i] ? nullptr : values_[i].c_str());
    return p;
  }

 private:
  std::vector<std::string> values_;
  std::vector<bool> null_;
};

// One result, cleared when it goes.
class Result {
 public:
  explicit Result(PGresult* r = nullptr) : r_(r) {}
  Result(Result&& o) noexcept : r_(std::exchange(o.r_, nullptr)) {}
  Result& operator=(Result&& o) noexcept {
    std::swap(r_, o.r_);
    return *this;
  }
  ~Result() { PQclear(r_); }
  PGresult* get() const { return r_; }
  int rows() const { return PQntuples(r_); }
  const char* at(int row, int col) const {
    return PQgetisnull(r_, row, col) ? nullptr : PQgetvalue(r_, row, col);
  }
  std::string text(int row, int col) const {
    return std::string(PQgetvalue(r_, row, col), std::size_t(PQgetlength(r_, row, col)));
  }

 private:
  PGresult* r_;
};

// Every migration of every mixpilot takes this transaction-level advisory lock first: two
// stations opening a new database at once run each migration once. ('mixp' 'hist' in ASCII.)
constexpr const char* kMigrationLock = "SELECT pg_advisory_xact_lock(7883813811238548340)";

class PostgresHistory final : public HistoryStore {
 public:
  PostgresHistory(std::string where, std::vector<std::string> secrets, PGconn* conn)
      : where_(std::move(where)), secrets_(std::move(secrets)), conn_(conn) {}
  ~PostgresHistory() override { PQfinish(conn_); }

  [[nodiscard]] bool init(std::string& error);
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
  std::string where() const override { return where_; }

  // "SERVER: what failed: the message (hint)", scrubbed of every password.
  std::string connection_failure(const char* what) const {
    const std::string m = one_line(PQerrorMessage(conn_));
    return scrub(where_ + ": " + what + ": " + m + hint_for(m, nullptr), secrets_);
  }

 private:
  // Inside a transaction begun by the caller: the flight's rows (trainee, flight, metrics). The
  // new flight's id and its trainee's (as text); an empty flight id when its recording is known
  // (nothing written); nullopt with the error (the caller rolls back).
  struct Inserted {
    std::string flight_id, trainee_id;
  };
  std::optional<Inserted> insert_flight(const FlightRecord& f, std::string& error);
  // Inside a transaction: the flight here that is `f` (copy_flight's match), or an empty id.
  std::optional<Inserted> find_flight(const FlightRecord& f, std::string& error);
  // Inside a transaction: the attempt's row of the flight `in`, unless it has one; whether
  // it was added.
  std::optional<bool> insert_attempt(const Inserted& in, const LessonAttempt& a,
                                     std::string& error);
  // Runs `sql` with `p`; the result when its status is `expected`, else nullopt with `error`.
  std::optional<Result> run(const std::string& sql, const Params& p, ExecStatusType expected,
                            const char* what, std::string& error);
  bool command(const char* sql, const char* what, std::string& error) {
    return run(sql, Params{}, PGRES_COMMAND_OK, what, error).has_value();
  }
  // Ends a transaction that failed on the way (the error is already said).
  void rollback() { PQclear(PQexec(conn_, "ROLLBACK")); }
  // A connection known to be broken is opened again.
  bool connected(std::string& error);
  // A connection that broke since the last operation (a server restart, an idle connection
  // cut) shows only when used: an operation's first statement, which has changed nothing yet,
  // is tried once more on a new connection.
  std::optional<Result> first(const std::string& sql, const Params& p, ExecStatusType expected,
                              const char* what, std::string& error);
  bool begin(const char* sql, const char* what, std::string& error) {
    return first(sql, Params{}, PGRES_COMMAND_OK, what, error).has_value();
  }

  std::string where_;
  std::vector<std::string> secrets_;
  PGconn* conn_;
  std::string last_sqlstate_;  // of the last statement that failed on the server ("" otherwise)
  // A connection serves one statement at a time: a flight closing on one thread and a panel
  // reading on another take turns.
  std::mutex mutex_;
};

std::optional<Result> PostgresHistory::run(const std::string& sql, const Params& p,
                                           ExecStatusType expected, const char* what,
                                           std::string& error) {
  const auto values = p.pointers();
  Result r(PQexecParams(conn_, sql.c_str(), p.size(), nullptr, values.data(), nullptr, nullptr, 0));
  last_sqlstate_.clear();
  if (r.get() != nullptr && PQresultStatus(r.get()) == expected) return r;
  if (r.get() != nullptr)
    if (const char* state = PQresultErrorField(r.get(), PG_DIAG_SQLSTATE)) last_sqlstate_ = state;
  if (r.get() == nullptr || PQstatus(conn_) == CONNECTION_BAD) {
    error = connection_failure(what);
  } else {
    const std::string m = one_line(PQresultErrorMessage(r.get()));
    error = scrub(where_ + ": " + what + ": " + m +
                      hint_for(m, PQresultErrorField(r.get(), PG_DIAG_SQLSTATE)),
                  secrets_);
  }
  return std::nullopt;
}

bool PostgresHistory::connected(std::string& error) {
  if (PQstatus(conn_) == CONNECTION_OK) return true;
  PQreset(conn_);
  if (PQstatus(conn_) == CONNECTION_OK) return true;
  error = connection_failure("the connection to the server was lost");
  return false;
}

std::optional<Result> PostgresHistory::first(const std::string& sql, const Params& p,
                                             ExecStatusType expected, const char* what,
                                             std::string& error) {
  if (!connected(error)) return std::nullopt;
  if (auto r = run(sql, p, expected, what, error)) return r;
  // libpq does not always mark the connection bad at once: a failure said by libpq itself (no
  // SQLSTATE), a connection exception (08) or an operator's intervention (57P) counts too.
  const std::string state = last_sqlstate_;
  if (PQstatus(conn_) != CONNECTION_BAD && !state.empty() && !state.starts_with("08") &&
      !state.starts_with("57P"))
    return std::nullopt;
  const std::string broken = error;
  PQreset(conn_);
  if (PQstatus(conn_) != CONNECTION_OK) {
    error = broken +
            "; connecting again: " + connection_failure("cannot connect to the PostgreSQL server");
    return std::nullopt;
  }
  return run(sql, p, expected, what, error);
}

bool PostgresHistory::init(std::string& error) {
  if (!command("BEGIN", "cannot start the schema check", error)) return false;
  if (!run(kMigrationLock, Params{}, PGRES_TUPLES_OK, "cannot lock the schema", error))
    return rollback(), false;
  if (!command(kCreateVersionTable, "cannot create the schema", error)) return rollback(), false;
  const auto v =
      run(kReadVersion, Params{}, PGRES_TUPLES_OK, "cannot read the schema version", error);
  if (!v || v->rows() != 1) {
    if (v) error = where_ + ": cannot read the schema version: no answer";
    return rollback(), false;
  }
  const int version = int(read_int(v->at(0, 0)));
  if (std::string why = newer_schema_message(version, where_); !why.empty()) {
    error = why;
    return rollback(), false;
  }
  for (const Statement& st : pending(version, Dialect::postgresql)) {
    Params p;
    if (st.takes_time) p.integer(now_unix_ms());
    if (!run(st.sql, p, PGRES_COMMAND_OK, "cannot migrate the schema", error))
      return rollback(), false;
  }
  if (!command("COMMIT", "cannot write the schema", error)) return rollback(), false;
  return true;
}

std::optional<PostgresHistory::Inserted> PostgresHistory::insert_flight(const FlightRecord& f,
                                                                      std::string& error) {
  if (!f.recording_hash.empty()) {
    const auto known =
        run("SELECT 1 FROM flights WHERE recording_hash = $1", Params{}.text(f.recording_hash),
            PGRES_TUPLES_OK, "cannot look the recording up", error);
    if (!known) return std::nullopt;
    if (known->rows() > 0) return Inserted{};  // nothing was written
  }
  // Two stations adding a new trainee at once: one inserts, the other waits for it and reads it.
  if (!run("INSERT INTO trainees (name) VALUES ($1) ON CONFLICT (name) DO NOTHING",
           Params{}.text(f.trainee), PGRES_COMMAND_OK, "cannot add the trainee", error))
    return std::nullopt;
  const auto trainee = run("SELECT id FROM trainees WHERE name = $1", Params{}.text(f.trainee),
                           PGRES_TUPLES_OK, "cannot find the trainee", error);
  if (!trainee) return std::nullopt;
  if (trainee->rows() != 1) {
    error = where_ + ": cannot find the trainee just added";
    return std::nullopt;
  }
  Inserted out;
  out.trainee_id = trainee->text(0, 0);
  Params p;
  p.text(out.trainee_id)
      .text(f.station)
      .text(f.scenario)
      .text(f.scenario_hash)
      .text(f.mode)
      .text(f.pilot)
      .text(f.input_device)
      .text(f.input_settings_hash)
      .integer(f.started_unix_ms)
      .text(number(f.duration_s))
      // The instructor's end is stored as interrupted, with who ended it (schema migration 5).
      .text(to_string(f.ended == Ended::instructor ? Ended::interrupted : f.ended))
      .integer(f.probe ? 1 : 0)
      .text_or_null(f.recording_path)
      .text_or_null(f.recording_hash)
      .text(f.app_version)
      .text(f.front_end)
      .text_or_null(f.parent_recording_hash);
  if (f.branch())
    p.integer(f.parent_step);
  else
    p.null();
  p.text_or_null(f.ended == Ended::instructor ? std::string("instructor") : std::string());
  // The same recording added at this moment by another station: theirs counts, ours is known.
  const auto flight =
      run("INSERT INTO flights (trainee_id, station, scenario, scenario_hash, mode, pilot, "
          "input_device, input_settings_hash, started_unix_ms, duration_s, ended, probe, "
          "recording_path, recording_hash, app_version, front_end, parent_recording_hash, "
          "parent_step, ended_by) "
          "VALUES ($1::bigint, $2, $3, $4, $5, $6, $7, $8, $9::bigint, $10::double precision, $11, "
          "$12::integer, $13, $14, $15, $16, $17, $18::bigint, $19) "
          "ON CONFLICT (recording_hash) DO NOTHING RETURNING id",
          p, PGRES_TUPLES_OK, "cannot add the flight", error);
  if (!flight) return std::nullopt;
  if (flight->rows() == 0) return Inserted{};
  out.flight_id = flight->text(0, 0);
  // The metrics, a few hundred rows per statement.
  constexpr std::size_t kRowsPerStatement = 500;
  for (std::size_t first = 0; first < f.metrics.size(); first += kRowsPerStatement) {
    const std::size_t last = std::min(f.metrics.size(), first + kRowsPerStatement);
    std::string sql = "INSERT INTO metrics (flight_id, position, name, value) VALUES ";
    Params mp;
    mp.text(out.flight_id);
    for (std::size_t i = first; i < last; ++i) {
      const int n = mp.size();
      if (i > first) sql += ", ";
      sql.append("($1::bigint, $").append(std::to_string(n + 1)).append("::integer, $");
      sql.append(std::to_string(n + 2)).append(", $").append(std::to_string(n + 3));
      sql.append("::double precision)");
      mp.integer(std::int64_t(i)).text(f.metrics[i].first);
      // Not a finite number: NULL (as the reports' JSON null).
      if (std::isfinite(f.metrics[i].second))
        mp.text(number(f.metrics[i].second));
      else
        mp.null();
    }
    if (!run(sql, mp, PGRES_COMMAND_OK, "cannot add the flight's metrics", error))
      return std::nullopt;
  }
  return out;
}

std::optional<HistoryStore::Added> PostgresHistory::add(const FlightRecord& f, std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = where_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  if (!std::isfinite(f.duration_s)) {
    error = where_ + ": the flight is not stored: its duration is not a finite number";
    return std::nullopt;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!begin("BEGIN", "cannot start adding a flight", error)) return std::nullopt;
  const std::optional<Inserted> in = insert_flight(f, error);
  if (!in) return rollback(), std::nullopt;
  if (in->flight_id.empty()) {
    rollback();  // nothing was written
    return Added::already_known;
  }
  if (!command("COMMIT", "cannot commit the flight", error)) return rollback(), std::nullopt;
  return Added::added;
}

std::optional<HistoryStore::Added> PostgresHistory::add_attempt(const FlightRecord& f,
                                                                const LessonAttempt& a,
                                                                std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = where_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  if (std::string why = check_attempt(a); !why.empty()) {
    error = where_ + ": the lesson attempt is not stored: " + why;
    return std::nullopt;
  }
  if (!std::isfinite(f.duration_s)) {
    error = where_ + ": the flight is not stored: its duration is not a finite number";
    return std::nullopt;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!begin("BEGIN", "cannot start adding a lesson attempt", error)) return std::nullopt;
  const std::optional<Inserted> in = insert_flight(f, error);
  if (!in) return rollback(), std::nullopt;
  if (in->flight_id.empty()) {
    rollback();
    return Added::already_known;
  }
  // The trainee's row of the lesson, made if need be and locked: two stations flying the same
  // trainee's lesson move it on one after the other.
  const Params key = Params{}.text(in->trainee_id).text(a.lesson).text(a.lesson_hash);
  Params made = key;
  made.integer(a.steps).integer(now_unix_ms());
  if (!run("INSERT INTO lesson_progress (trainee_id, lesson, lesson_hash, steps, step, "
           "failed_attempts, updated_unix_ms) VALUES ($1::bigint, $2, $3, $4::integer, 0, 0, "
           "$5::bigint) ON CONFLICT (trainee_id, lesson, lesson_hash) DO NOTHING",
           made, PGRES_COMMAND_OK, "cannot start the lesson's progress", error))
    return rollback(), std::nullopt;
  const auto row = run("SELECT steps, step, failed_attempts FROM lesson_progress WHERE "
                       "trainee_id = $1::bigint AND lesson = $2 AND lesson_hash = $3 FOR UPDATE",
                       key, PGRES_TUPLES_OK, "cannot read the lesson's progress", error);
  if (!row) return rollback(), std::nullopt;
  if (row->rows() != 1) {
    error = where_ + ": cannot read the lesson's progress just made";
    return rollback(), std::nullopt;
  }
  LessonProgress before;
  before.steps = int(read_int(row->at(0, 0)));
  before.step = int(read_int(row->at(0, 1)));
  before.failed_attempts = int(read_int(row->at(0, 2)));
  std::string why;
  const LessonProgress after = progress_after(before, a, why);
  if (!why.empty()) {
    rollback();
    error = where_ + ": the lesson attempt is not stored: " + why;
    return std::nullopt;
  }
  if (!insert_attempt(*in, a, error)) return rollback(), std::nullopt;
  Params up = key;
  up.integer(after.steps).integer(after.step).integer(after.failed_attempts).integer(now_unix_ms());
  if (!run("UPDATE lesson_progress SET steps = $4::integer, step = $5::integer, "
           "failed_attempts = $6::integer, updated_unix_ms = $7::bigint WHERE "
           "trainee_id = $1::bigint AND lesson = $2 AND lesson_hash = $3",
           up, PGRES_COMMAND_OK, "cannot move the lesson's progress on", error))
    return rollback(), std::nullopt;
  if (!command("COMMIT", "cannot commit the lesson attempt", error))
    return rollback(), std::nullopt;
  return Added::added;
}

bool PostgresHistory::lesson_progress(const std::string& trainee, std::vector<LessonProgress>& out,
                                      std::string& error) {
  out.clear();
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto r = first("SELECT t.name, p.lesson, p.lesson_hash, p.steps, p.step, "
                       "p.failed_attempts, p.updated_unix_ms FROM lesson_progress p "
                       "JOIN trainees t ON t.id = p.trainee_id "
                       "WHERE ($1::text = '' OR t.name = $1::text) "
                       "ORDER BY t.name COLLATE \"C\", p.lesson COLLATE \"C\", p.updated_unix_ms",
                       Params{}.text(trainee), PGRES_TUPLES_OK,
                       "cannot read the lessons' progress", error);
  if (!r) return false;
  for (int i = 0; i < r->rows(); ++i) {
    LessonProgress l;
    l.trainee = r->text(i, 0);
    l.lesson = r->text(i, 1);
    l.lesson_hash = r->text(i, 2);
    l.steps = int(read_int(r->at(i, 3)));
    l.step = int(read_int(r->at(i, 4)));
    l.failed_attempts = int(read_int(r->at(i, 5)));
    l.updated_unix_ms = read_int(r->at(i, 6));
    out.push_back(std::move(l));
  }
  return true;
}

bool PostgresHistory::lesson_attempts(const std::string& trainee, const std::string& lesson,
                                      const std::string& lesson_hash,
                                      std::vector<StoredAttempt>& out, std::string& error) {
  out.clear();
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto r = first(
      "SELECT a.id, a.flight_id, t.name, a.lesson, a.lesson_hash, a.step, a.step_title, "
      "a.ceiling, a.passed, a.failed_criterion, a.detail, f.started_unix_ms, f.recording_path, "
      "f.probe, m.value, (SELECT p.steps FROM lesson_progress p WHERE p.trainee_id = "
      "a.trainee_id AND p.lesson = a.lesson AND p.lesson_hash = a.lesson_hash) "
      "FROM lesson_attempts a JOIN trainees t ON t.id = a.trainee_id "
      "JOIN flights f ON f.id = a.flight_id "
      "LEFT JOIN metrics m ON m.flight_id = a.flight_id AND m.name = 'skill' "
      "WHERE t.name = $1 AND a.lesson = $2 AND a.lesson_hash = $3 ORDER BY a.id",
      Params{}.text(trainee).text(lesson).text(lesson_hash), PGRES_TUPLES_OK,
      "cannot read the lesson's attempts", error);
  if (!r) return false;
  for (int i = 0; i < r->rows(); ++i) {
    StoredAttempt a;
    a.id = read_int(r->at(i, 0));
    a.flight_id = read_int(r->at(i, 1));
    a.trainee = r->text(i, 2);
    a.lesson = r->text(i, 3);
    a.lesson_hash = r->text(i, 4);
    a.step = int(read_int(r->at(i, 5)));
    a.step_title = r->text(i, 6);
    a.ceiling = read_double(r->at(i, 7));
    a.passed = read_int(r->at(i, 8)) != 0;
    a.failed_criterion = r->text(i, 9);
    a.detail = r->text(i, 10);
    a.started_unix_ms = read_int(r->at(i, 11));
    a.recording_path = r->text(i, 12);
    a.probe = read_int(r->at(i, 13)) != 0;
    a.skill = read_double(r->at(i, 14));
    a.steps = int(read_int(r->at(i, 15)));
    out.push_back(std::move(a));
  }
  return true;
}

bool PostgresHistory::reset_lesson(const std::string& trainee, const std::string& lesson,
                                   const std::string& lesson_hash, std::string& error) {
  const std::lock_guard<std::mutex> lock(mutex_);
  return first("UPDATE lesson_progress SET step = 0, failed_attempts = 0, "
               "updated_unix_ms = $4::bigint WHERE trainee_id = (SELECT id FROM trainees WHERE "
               "name = $1) AND lesson = $2 AND lesson_hash = $3",
               Params{}.text(trainee).text(lesson).text(lesson_hash).integer(now_unix_ms()),
               PGRES_COMMAND_OK, "cannot start the lesson over", error)
      .has_value();
}

std::optional<bool> PostgresHistory::insert_attempt(const Inserted& in, const LessonAttempt& a,
                                                    std::string& error) {
  Params ap;
  ap.text(in.flight_id)
      .text(in.trainee_id)
      .text(a.lesson)
      .text(a.lesson_hash)
      .integer(a.step)
      .text(a.step_title)
      .text(number(a.ceiling))
      .integer(a.passed ? 1 : 0)
      .text_or_null(a.failed_criterion)
      .text(a.detail);
  const auto r = run("INSERT INTO lesson_attempts (flight_id, trainee_id, lesson, lesson_hash, "
                     "step, step_title, ceiling, passed, failed_criterion, detail) VALUES "
                     "($1::bigint, $2::bigint, $3, $4, $5::integer, $6, $7::double precision, "
                     "$8::integer, $9, $10) ON CONFLICT (flight_id) DO NOTHING RETURNING 1",
                     ap, PGRES_TUPLES_OK, "cannot add the lesson attempt", error);
  if (!r) return std::nullopt;
  return r->rows() > 0;
}

std::optional<PostgresHistory::Inserted> PostgresHistory::find_flight(const FlightRecord& f,
                                                                    std::string& error) {
  const bool recorded = !f.recording_hash.empty();
  const auto r =
      recorded
          ? run("SELECT id, trainee_id FROM flights WHERE recording_hash = $1",
                Params{}.text(f.recording_hash), PGRES_TUPLES_OK, "cannot look the flight up",
                error)
          : run("SELECT f.id, f.trainee_id FROM flights f JOIN trainees t ON "
                "t.id = f.trainee_id WHERE f.recording_hash IS NULL AND t.name = $1 AND "
                "f.station = $2 AND f.started_unix_ms = $3::bigint ORDER BY f.id LIMIT 1",
                Params{}.text(f.trainee).text(f.station).integer(f.started_unix_ms),
                PGRES_TUPLES_OK, "cannot look the flight up", error);
  if (!r) return std::nullopt;
  if (r->rows() == 0) return Inserted{};
  return Inserted{r->text(0, 0), r->text(0, 1)};
}

// Two pushes at once copy one flight at a time (an unrecorded flight has no unique key the
// server could hold them to). ('mixp' 'push' in ASCII.)
constexpr const char* kPushLock = "SELECT pg_advisory_xact_lock(7883965047007179624)";

std::optional<HistoryStore::Copied> PostgresHistory::copy_flight(const StoredFlight& f,
                                                                 std::string& error) {
  if (std::string why = check_record(f); !why.empty()) {
    error = where_ + ": the flight is not stored: " + why;
    return std::nullopt;
  }
  if (!std::isfinite(f.duration_s)) {
    error = where_ + ": the flight is not stored: its duration is not a finite number";
    return std::nullopt;
  }
  const LessonAttempt a = f.as_attempt();
  if (f.attempt())
    if (std::string why = check_attempt(a); !why.empty()) {
      error = where_ + ": the lesson attempt is not stored: " + why;
      return std::nullopt;
    }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!begin("BEGIN", "cannot start adding a flight", error)) return std::nullopt;
  if (!run(kPushLock, Params{}, PGRES_TUPLES_OK, "cannot lock the history for a push", error))
    return rollback(), std::nullopt;
  Copied c;
  std::optional<Inserted> in = find_flight(f, error);
  if (in && in->flight_id.empty()) {
    in = insert_flight(f, error);
    c.flight = true;
    // Added at this moment by a station that flew it: that row is the flight.
    if (in && in->flight_id.empty()) {
      c.flight = false;
      in = find_flight(f, error);
    }
  }
  if (!in) return rollback(), std::nullopt;
  if (in->flight_id.empty()) {
    error = where_ + ": cannot find the flight just added";
    return rollback(), std::nullopt;
  }
  if (f.attempt()) {
    const std::optional<bool> added = insert_attempt(*in, a, error);
    if (!added) return rollback(), std::nullopt;
    c.attempt = *added;
  }
  if (!command("COMMIT", "cannot commit the flight", error)) return rollback(), std::nullopt;
  return c;
}

std::optional<bool> PostgresHistory::merge_progress(const LessonProgress& lp,
                                                    std::string& error) {
  if (std::string why = check_progress(lp); !why.empty()) {
    error = where_ + ": the lesson's progress is not stored: " + why;
    return std::nullopt;
  }
  const std::lock_guard<std::mutex> lock(mutex_);
  if (!begin("BEGIN", "cannot start merging a lesson's progress", error)) return std::nullopt;
  if (!run("INSERT INTO trainees (name) VALUES ($1) ON CONFLICT (name) DO NOTHING",
           Params{}.text(lp.trainee), PGRES_COMMAND_OK, "cannot add the trainee", error))
    return rollback(), std::nullopt;
  const auto r =
      run("INSERT INTO lesson_progress (trainee_id, lesson, lesson_hash, steps, step, "
          "failed_attempts, updated_unix_ms) VALUES ((SELECT id FROM trainees WHERE name = $1), "
          "$2, $3, $4::integer, $5::integer, $6::integer, $7::bigint) "
          "ON CONFLICT (trainee_id, lesson, lesson_hash) DO UPDATE SET "
          "steps = excluded.steps, step = excluded.step, "
          "failed_attempts = excluded.failed_attempts, "
          "updated_unix_ms = excluded.updated_unix_ms "
          "WHERE excluded.updated_unix_ms > lesson_progress.updated_unix_ms RETURNING 1",
          Params{}
              .text(lp.trainee)
              .text(lp.lesson)
              .text(lp.lesson_hash)
              .integer(lp.steps)
              .integer(lp.step)
              .integer(lp.failed_attempts)
              .integer(lp.updated_unix_ms),
          PGRES_TUPLES_OK, "cannot merge the lesson's progress", error);
  if (!r) return rollback(), std::nullopt;
  if (!command("COMMIT", "cannot commit the lesson's progress", error))
    return rollback(), std::nullopt;
  return r->rows() > 0;
}

bool PostgresHistory::query(const Query& q, std::vector<StoredFlight>& out, std::string& error) {
  out.clear();
  const std::lock_guard<std::mutex> lock(mutex_);
  // The newest `limit` flights that pass the filters, read oldest first, and their metrics:
  // one snapshot for both statements.
  if (!begin("BEGIN ISOLATION LEVEL REPEATABLE READ READ ONLY", "cannot read the history", error))
    return false;
  Params p;
  p.text(q.trainee).text(q.scenario).integer(q.since_unix_ms);
  if (q.limit > 0)
    p.integer(q.limit);
  else
    p.null();  // LIMIT NULL: all
  const auto flights = run(
      "SELECT * FROM (SELECT f.id, t.name, f.station, f.scenario, f.scenario_hash, f.mode, "
      "f.pilot, f.input_device, f.input_settings_hash, f.started_unix_ms, f.duration_s, f.ended, "
      "f.probe, f.recording_path, f.recording_hash, f.app_version, f.front_end, "
      "f.parent_recording_hash, f.parent_step, f.ended_by, a.lesson, a.step, a.passed, "
      "a.failed_criterion, a.lesson_hash, a.step_title, a.ceiling, a.detail "
      "FROM flights f JOIN trainees t ON t.id = f.trainee_id "
      "LEFT JOIN lesson_attempts a ON a.flight_id = f.id "
      "WHERE ($1::text = '' OR t.name = $1::text) AND ($2::text = '' OR f.scenario = $2::text) "
      "AND f.started_unix_ms >= $3::bigint "
      "ORDER BY f.started_unix_ms DESC, f.id DESC LIMIT $4::bigint) newest "
      "ORDER BY started_unix_ms, id",
      p, PGRES_TUPLES_OK, "cannot read the flights", error);
  if (!flights) return rollback(), false;
  const int n = flights->rows();
  out.reserve(std::size_t(n));
  std::unordered_map<std::int64_t, std::size_t> at;
  at.reserve(std::size_t(n));
  std::string ids = "{";
  for (int r = 0; r < n; ++r) {
    const Result& s = *flights;
    StoredFlight f;
    f.id = read_int(s.at(r, 0));
    f.trainee = s.text(r, 1);
    f.station = s.text(r, 2);
    f.scenario = s.text(r, 3);
    f.scenario_hash = s.text(r, 4);
    f.mode = s.text(r, 5);
    f.pilot = s.text(r, 6);
    f.input_device = s.text(r, 7);
    f.input_settings_hash = s.text(r, 8);
    f.started_unix_ms = read_int(s.at(r, 9));
    f.duration_s = read_double(s.at(r, 10));
    f.ended = ended_from(s.text(r, 11)).value_or(Ended::completed);
    f.probe = read_int(s.at(r, 12)) != 0;
    f.recording_path = s.text(r, 13);
    f.recording_hash = s.text(r, 14);
    f.app_version = s.text(r, 15);
    f.front_end = s.text(r, 16);
    f.parent_recording_hash = s.text(r, 17);
    f.parent_step = s.at(r, 18) ? read_int(s.at(r, 18)) : -1;
    if (s.text(r, 19) == "instructor") f.ended = Ended::instructor;
    if (s.at(r, 20)) {
      f.lesson = s.text(r, 20);
      f.lesson_step = int(read_int(s.at(r, 21)));
      f.lesson_passed = read_int(s.at(r, 22)) != 0;
      f.lesson_failed = s.text(r, 23);
      f.lesson_hash = s.text(r, 24);
      f.lesson_step_title = s.text(r, 25);
      f.lesson_ceiling = read_double(s.at(r, 26));
      f.lesson_detail = s.text(r, 27);
    }
    if (r > 0) ids += ',';
    ids += std::to_string(f.id);
    at.emplace(f.id, out.size());
    out.push_back(std::move(f));
  }
  ids += "}";
  if (n > 0) {
    const auto metrics =
        run("SELECT flight_id, name, value FROM metrics WHERE flight_id = ANY($1::bigint[]) "
            "ORDER BY flight_id, position",
            Params{}.text(ids), PGRES_TUPLES_OK, "cannot read the metrics", error);
    if (!metrics) return out.clear(), rollback(), false;
    for (int r = 0; r < metrics->rows(); ++r) {
      const auto it = at.find(read_int(metrics->at(r, 0)));
      if (it == at.end()) continue;
      out[it->second].metrics.emplace_back(metrics->text(r, 1), read_double(metrics->at(r, 2)));
    }
  }
  if (!command("COMMIT", "cannot read the history", error)) return out.clear(), rollback(), false;
  return true;
}

bool PostgresHistory::trainees(std::vector<std::string>& out, std::string& error) {
  out.clear();
  const std::lock_guard<std::mutex> lock(mutex_);
  // Byte order, as SQLite's: the same list on either backend, whatever the server's collation.
  const auto r = first("SELECT name FROM trainees ORDER BY name COLLATE \"C\"", Params{},
                       PGRES_TUPLES_OK, "cannot read the trainees", error);
  if (!r) return false;
  for (int i = 0; i < r->rows(); ++i) out.push_back(r->text(i, 0));
  return true;
}

bool PostgresHistory::knows_recording(const std::string& hash, bool& known, std::string& error) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const auto r = first("SELECT 1 FROM flights WHERE recording_hash = $1", Params{}.text(hash),
                       PGRES_TUPLES_OK, "cannot look the recording up", error);
  if (!r) return false;
  known = r->rows() > 0;
  return true;
}

// Notices ("relation schema_version already exists, skipping") are not the user's business.
void quiet(void*, const PGresult*) {}

}  // namespace

std::string redact_postgres_url(const std::string& url) {
  if (!is_url(url)) {
    // key=value pairs: those libpq reads, without any password.
    char* err = nullptr;
    PQconninfoOption* opts = PQconninfoParse(url.c_str(), &err);
    PQfreemem(err);
    if (opts == nullptr) return "(a PostgreSQL connection string that cannot be read)";
    std::string out;
    for (PQconninfoOption* o = opts; o->keyword != nullptr; ++o)
      if (o->val != nullptr && !names_password(o->keyword)) {
        if (!out.empty()) out += ' ';
        out.append(o->keyword).append("='").append(o->val).append("'");
      }
    PQconninfoFree(opts);
    return out;
  }
  const std::size_t start = url.find("://") + 3;
  std::string rest = url.substr(start);
  // user:password@ — up to the last '@', however the password is written.
  if (const std::size_t at = rest.rfind('@'); at != std::string::npos) rest = rest.substr(at + 1);
  std::string out = url.substr(0, start);
  const std::size_t q = rest.find('?');
  out += rest.substr(0, q);
  if (q != std::string::npos) {
    std::string kept;
    std::size_t i = q + 1;
    while (i <= rest.size()) {
      std::size_t amp = rest.find('&', i);
      if (amp == std::string::npos) amp = rest.size();
      const std::string param = rest.substr(i, amp - i);
      const std::size_t eq = param.find('=');
      if (!param.empty() && !names_password(param.substr(0, eq))) {
        if (!kept.empty()) kept += '&';
        kept += param;
      }
      i = amp + 1;
    }
    if (!kept.empty()) out += "?" + kept;
  }
  return out;
}

std::unique_ptr<HistoryStore> open_postgres(const std::string& url, std::string& error) {
  const std::string where = redact_postgres_url(url);
  const std::vector<std::string> secrets = secrets_of(url);
  {
    char* err = nullptr;
    PQconninfoOption* opts = PQconninfoParse(url.c_str(), &err);
    if (opts == nullptr) {
      error = scrub(where + ": not a PostgreSQL URL (postgresql://USER@HOST[:PORT]/DATABASE): " +
                        one_line(err),
                    secrets);
      PQfreemem(err);
      return nullptr;
    }
    PQconninfoFree(opts);
  }
  // Keywords are read in order and a later one wins: the URL's own connect_timeout and
  // application name override these.
  // (client_encoding comes last: names are UTF-8 whatever the URL says.)
  const char* keys[] = {"connect_timeout", "fallback_application_name", "dbname", "client_encoding",
                        nullptr};
  const char* values[] = {"5", "mixpilot", url.c_str(), "UTF8", nullptr};
  PGconn* conn = PQconnectdbParams(keys, values, 1);
  if (conn == nullptr) {
    error = where + ": cannot connect: out of memory";
    return nullptr;
  }
  auto store =
      std::make_unique<PostgresHistory>(where, secrets, conn);  // closes conn on every way out
  if (PQstatus(conn) != CONNECTION_OK) {
    error = store->connection_failure("cannot connect to the PostgreSQL server");
    return nullptr;
  }
  PQsetNoticeReceiver(conn, quiet, nullptr);
  if (!store->init(error)) return nullptr;
  return store;
}

}  // namespace mixpilot::history
