// The trainee's history (SPEC §10): the store (SQLite), its schema, content hashes, writers in
// parallel and killed, damaged and locked files, hostile names; and every front end's flight
// recorded once.
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>
#include <string>
#include <vector>

#include "app/flight_rig.hpp"
#include "app/history_writer.hpp"
#include "app/offscreen.hpp"
#include "app/progress.hpp"
#include "app/progress_html.hpp"
#include "app/trainer.hpp"
#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/history/push.hpp"
#include "core/history/schema.hpp"
#include "core/history/sqlite_history.hpp"
#include "core/numerics/version.hpp"
#include "history_dump.hpp"
#include "history_test.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
using history::FlightRecord;
using history::HistoryStore;
using history::StoredFlight;

FlightRecord sample_flight(const std::string& trainee = "Ada", std::int64_t started = 1'700'000'000'000) {
  FlightRecord f;
  f.trainee = trainee;
  f.station = "station-1";
  f.scenario = "mi_helix";
  f.scenario_hash = sha256_hex("scenario text");
  f.mode = "mixed_initiative";
  f.pilot = "novice";
  f.input_device = "";
  f.input_settings_hash = "";
  f.started_unix_ms = started;
  f.duration_s = 30.0;
  f.ended = history::Ended::completed;
  f.app_version = "mixpilot 0.1.0";
  f.front_end = "fly";
  f.metrics = {{"skill", 71.5}, {"mean_lambda", 0.8}, {"min_clearance_m", INFINITY},
               {"lost", 0.0}};
  return f;
}

std::unique_ptr<HistoryStore> open_store(const fs::path& p, const history::SqliteSettings& s = {}) {
  std::string error;
  auto store = history::open_sqlite(p.string(), error, s);
  EXPECT_TRUE(store) << error;
  return store;
}

std::vector<StoredFlight> all(HistoryStore& store, const history::Query& q = {}) {
  std::vector<StoredFlight> out;
  std::string error;
  EXPECT_TRUE(store.query(q, out, error)) << error;
  return out;
}

// A statement's one integer answer through SQLite directly (not through the store).
std::int64_t sql_int(const fs::path& p, const char* sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &s, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::int64_t v = -1;
  if (sqlite3_step(s) == SQLITE_ROW) v = sqlite3_column_int64(s, 0);
  sqlite3_finalize(s);
  sqlite3_close(db);
  return v;
}
std::string sql_text(const fs::path& p, const char* sql) {
  sqlite3* db = nullptr;
  EXPECT_EQ(sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  sqlite3_stmt* s = nullptr;
  EXPECT_EQ(sqlite3_prepare_v2(db, sql, -1, &s, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
  std::string v;
  if (sqlite3_step(s) == SQLITE_ROW && sqlite3_column_text(s, 0))
    v = reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
  sqlite3_finalize(s);
  sqlite3_close(db);
  return v;
}

bool running_as_root() { return ::geteuid() == 0; }

// ---- Content hashes -------------------------------------------------------------------------

// FIPS 180-4's examples (NIST's SHA256.pdf) and the empty message.
TEST(HistoryHash, Sha256GivesTheStandardsVectors) {
  EXPECT_EQ(sha256_hex("abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  // A file across several read blocks hashes as its bytes do.
  const fs::path p = test::fresh_path("history", "big.bin");
  std::string bytes(200'003, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 131 % 251);
  std::ofstream(p, std::ios::binary) << bytes;
  std::string error;
  const auto h = sha256_file(p.string(), error);
  ASSERT_TRUE(h) << error;
  EXPECT_EQ(*h, sha256_hex(bytes));
  EXPECT_FALSE(sha256_file((p.parent_path() / "absent").string(), error));
  EXPECT_NE(error.find("absent"), std::string::npos) << error;
}

// ---- The schema ----------------------------------------------------------------------------

TEST(HistorySchema, OneSchemaTwoDialects) {
  const auto sqlite = history::pending(0, history::Dialect::sqlite);
  const auto pg = history::pending(0, history::Dialect::postgresql);
  ASSERT_EQ(sqlite.size(), pg.size());
  ASSERT_FALSE(sqlite.empty());
  EXPECT_TRUE(sqlite.back().takes_time);  // the version's row, last
  EXPECT_NE(sqlite[0].sql.find("INTEGER PRIMARY KEY"), std::string::npos) << sqlite[0].sql;
  EXPECT_NE(pg[0].sql.find("BIGINT GENERATED ALWAYS AS IDENTITY PRIMARY KEY"), std::string::npos)
      << pg[0].sql;
  for (const auto& s : pg) EXPECT_EQ(s.sql.find('{'), std::string::npos) << s.sql;
  EXPECT_TRUE(history::pending(history::kSchemaVersion, history::Dialect::sqlite).empty());
  EXPECT_EQ(history::newer_schema_message(history::kSchemaVersion, "f"), "");
  EXPECT_NE(history::newer_schema_message(history::kSchemaVersion + 1, "f"), "");
}

// ---- The store -----------------------------------------------------------------------------

// A flight comes back with every field it went in with, its metrics in their order; a metric
// that is not a finite number comes back as NaN (stored NULL, as the reports' null).
TEST(HistoryStore, AFlightComesBackWithEveryField) {
  const fs::path p = test::fresh_path("history", "roundtrip.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  FlightRecord f = sample_flight();
  f.input_device = "gamepad";
  f.input_settings_hash = sha256_hex("mode = 2");
  f.ended = history::Ended::lost;
  f.probe = true;
  f.recording_path = "/tmp/a.mcap";
  f.recording_hash = sha256_hex("rec");
  std::string error;
  ASSERT_EQ(store->add(f, error), HistoryStore::Added::added) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  test::expect_same_flight(f, rows[0]);
  EXPECT_EQ(rows[0].ended, history::Ended::lost);
  EXPECT_TRUE(rows[0].probe);
  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names, std::vector<std::string>{"Ada"});
  // The database holds what the schema says, with foreign keys on.
  EXPECT_EQ(sql_int(p, "SELECT max(version) FROM schema_version"), history::kSchemaVersion);
  EXPECT_EQ(sql_text(p, "PRAGMA journal_mode"), "wal");
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM metrics"), 4);
}

// A recording is one flight: the same hash again is already known and adds nothing; flights
// without a recording are each their own.
TEST(HistoryStore, ARecordingIsAddedOnce) {
  const fs::path p = test::fresh_path("history", "once.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  FlightRecord f = sample_flight();
  f.recording_hash = sha256_hex("recording");
  f.recording_path = "/r.mcap";
  std::string error;
  bool known = true;
  ASSERT_TRUE(store->knows_recording(f.recording_hash, known, error)) << error;
  EXPECT_FALSE(known);
  EXPECT_EQ(store->add(f, error), HistoryStore::Added::added) << error;
  EXPECT_EQ(store->add(f, error), HistoryStore::Added::already_known) << error;
  ASSERT_TRUE(store->knows_recording(f.recording_hash, known, error)) << error;
  EXPECT_TRUE(known);
  FlightRecord g = sample_flight();
  EXPECT_EQ(store->add(g, error), HistoryStore::Added::added) << error;
  EXPECT_EQ(store->add(g, error), HistoryStore::Added::added) << error;
  EXPECT_EQ(all(*store).size(), 3u);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM metrics"), 12);
}

TEST(HistoryStore, FiltersAndTheNewestLimit) {
  const fs::path p = test::fresh_path("history", "filters.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  std::string error;
  for (int i = 0; i < 6; ++i) {
    FlightRecord f = sample_flight(i % 2 ? "Ben" : "Ada", 1000 * (10 - i));  // newest first in
    f.scenario = i < 3 ? "mi_helix" : "mi_slalom";
    f.metrics = {{"skill", double(i)}};
    ASSERT_EQ(store->add(f, error), HistoryStore::Added::added) << error;
  }
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 6u);
  for (std::size_t i = 1; i < rows.size(); ++i)
    EXPECT_LT(rows[i - 1].started_unix_ms, rows[i].started_unix_ms) << "oldest first";
  history::Query q;
  q.trainee = "Ben";
  for (const auto& r : all(*store, q)) EXPECT_EQ(r.trainee, "Ben");
  EXPECT_EQ(all(*store, q).size(), 3u);
  q = {};
  q.scenario = "mi_slalom";
  EXPECT_EQ(all(*store, q).size(), 3u);
  q = {};
  q.since_unix_ms = 7000;  // i = 0..3 started at 10000, 9000, 8000, 7000
  EXPECT_EQ(all(*store, q).size(), 4u);
  q = {};
  q.limit = 2;  // the two newest, oldest first: i = 1 (9000), i = 0 (10000)
  const auto newest = all(*store, q);
  ASSERT_EQ(newest.size(), 2u);
  EXPECT_EQ(newest[0].started_unix_ms, 9000);
  EXPECT_EQ(newest[1].started_unix_ms, 10000);
  ASSERT_EQ(newest[1].metrics.size(), 1u);
  EXPECT_EQ(newest[1].metrics[0].second, 0.0);
  EXPECT_EQ(newest[0].metrics[0].second, 1.0);
  q = {};
  q.trainee = "nobody";
  EXPECT_TRUE(all(*store, q).empty());
}

// Names are data, never SQL: quotes and a statement in a name are stored and read back as
// they are; 10 000 characters, invalid UTF-8, control characters and an empty name are
// refused with the reason, and nothing of them is written.
TEST(HistoryStore, HostileTraineeNames) {
  const fs::path p = test::fresh_path("history", "names.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  std::string error;
  const std::vector<std::string> stored = {
      "O'Brien", "\"quoted\"", "Robert'); DROP TABLE flights; --", "'; DROP TABLE trainees",
      "Zoë Ångström 飛行", std::string(history::kMaxNameChars, 'x')};
  for (const std::string& name : stored)
    EXPECT_EQ(store->add(sample_flight(name), error), HistoryStore::Added::added)
        << name << ": " << error;
  const struct {
    std::string name;
    const char* reason;
  } refused[] = {
      {std::string(10'000, 'a'), "10000 characters long"},
      {std::string(history::kMaxNameChars + 1, 'x'), "201 characters long"},
      {"bad\xff" "byte", "not valid UTF-8"},
      {"over\xc0\xaflong", "not valid UTF-8"},
      {"cut\xe2\x82", "not valid UTF-8"},
      {"surrogate\xed\xa0\x80", "not valid UTF-8"},
      {"line\nbreak", "control character"},
      {"esc\x1b[31mred", "control character"},
      {"c1\xc2\x9b", "control character"},
      {"", "empty"},
  };
  for (const auto& r : refused) {
    error.clear();
    EXPECT_FALSE(store->add(sample_flight(r.name), error)) << r.reason;
    EXPECT_NE(error.find(r.reason), std::string::npos) << error;
    EXPECT_NE(error.find(p.string()), std::string::npos) << error;
  }
  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  std::set<std::string> want(stored.begin(), stored.end());
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()), want);
  for (const std::string& name : stored) {
    history::Query q;
    q.trainee = name;
    const auto rows = all(*store, q);
    ASSERT_EQ(rows.size(), 1u) << name;
    EXPECT_EQ(rows[0].trainee, name);
  }
  EXPECT_EQ(all(*store).size(), stored.size());  // the tables are all still there
  EXPECT_EQ(sql_text(p, "PRAGMA integrity_check"), "ok");
}

// A database an older mixpilot made (schema 1: no metrics_by_name index, no branches' parent
// columns, no lesson tables, one schema_version row) is brought forward on open; its flights
// stay.
TEST(HistoryStore, AnOlderSchemaIsMigratedForward) {
  const fs::path p = test::fresh_path("history", "migrate.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  std::string error;
  ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  store.reset();
  ASSERT_EQ(sql_int(p, "SELECT count(*) FROM sqlite_master WHERE name = 'metrics_by_name'"), 1);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
  EXPECT_EQ(sqlite3_exec(db, "DROP TABLE lesson_attempts; DROP TABLE lesson_progress; "
                             "DROP INDEX metrics_by_name; DROP INDEX flights_by_parent; "
                             "ALTER TABLE flights DROP COLUMN ended_by; "
                             "ALTER TABLE flights DROP COLUMN parent_step; "
                             "ALTER TABLE flights DROP COLUMN parent_recording_hash; "
                             "DELETE FROM schema_version WHERE version > 1",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_close(db);
  ASSERT_EQ(sql_int(p, "SELECT max(version) FROM schema_version"), 1);
  store = open_store(p);
  ASSERT_TRUE(store);
  EXPECT_EQ(sql_int(p, "SELECT max(version) FROM schema_version"), history::kSchemaVersion);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM sqlite_master WHERE name = 'metrics_by_name'"), 1);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM sqlite_master WHERE name = 'flights_by_parent'"), 1);
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  test::expect_same_flight(sample_flight(), rows[0]);  // no parent: not a branch
}

// Fly from here (SPEC §10): a branch is a row like any flight plus its parent link — the
// parent flight's recording hash and the step it was taken over at — read back as written,
// NULL for any other flight; the branches of a flight are found through the parent index. A
// half link is refused.
TEST(HistoryStore, FlyFromHereBranchRowRoundTrips) {
  const fs::path p = test::fresh_path("history", "branch.sqlite");
  auto store = open_store(p);
  ASSERT_TRUE(store);
  FlightRecord parent = sample_flight("Ada", 1'700'000'000'000);
  parent.recording_path = "/r/novice.mcap";
  parent.recording_hash = sha256_hex("the novice's recording");
  FlightRecord branch = sample_flight("Ada", 1'700'000'100'000);
  branch.pilot = "experienced";
  branch.recording_path = "/r/branch.mcap";
  branch.recording_hash = sha256_hex("the branch's recording");
  branch.parent_recording_hash = parent.recording_hash;
  branch.parent_step = 666;
  std::string error;
  ASSERT_EQ(store->add(parent, error), HistoryStore::Added::added) << error;
  ASSERT_EQ(store->add(branch, error), HistoryStore::Added::added) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 2u);
  test::expect_same_flight(parent, rows[0]);
  EXPECT_FALSE(rows[0].branch());
  test::expect_same_flight(branch, rows[1]);
  EXPECT_TRUE(rows[1].branch());
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM flights WHERE parent_step IS NULL"), 1);
  const std::string of_parent = "SELECT parent_step FROM flights WHERE parent_recording_hash = '" +
                                parent.recording_hash + "'";
  EXPECT_EQ(sql_int(p, of_parent.c_str()), 666);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM sqlite_master WHERE name = 'flights_by_parent'"), 1);
  FlightRecord half = branch;
  half.recording_hash = sha256_hex("another");
  half.parent_recording_hash.clear();
  EXPECT_FALSE(store->add(half, error));
  EXPECT_NE(error.find("a branch needs both its parent recording's hash and its parent step"),
            std::string::npos)
      << error;
  EXPECT_EQ(all(*store).size(), 2u);
}

// A newer mixpilot's history is refused with the reason and left as it was, byte for byte.
TEST(HistoryStore, ANewerSchemaIsRefusedAndLeftUntouched) {
  const fs::path p = test::fresh_path("history", "newer.sqlite");
  { ASSERT_TRUE(open_store(p)); }
  std::string error;
  {
    auto store = open_store(p);
    ASSERT_TRUE(store);
    ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  }
  EXPECT_EQ(sql_int(p, "INSERT INTO schema_version VALUES (99, 0) RETURNING version"), 99);
  const auto before = test::slurp(p);
  const auto store = history::open_sqlite(p.string(), error);
  EXPECT_FALSE(store);
  EXPECT_NE(error.find("newer mixpilot (schema version 99"), std::string::npos) << error;
  EXPECT_NE(error.find(p.string()), std::string::npos) << error;
  EXPECT_EQ(test::slurp(p), before);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM flights"), 1);
}

// A file that is not a database: refused with the file's name and what to do.
TEST(HistoryStore, ACorruptFileIsSaidAsSuch) {
  const fs::path p = test::fresh_path("history", "corrupt.sqlite");
  std::ofstream(p) << std::string(8192, 'Z');
  const auto before = test::slurp(p);
  std::string error;
  EXPECT_FALSE(history::open_sqlite(p.string(), error));
  EXPECT_NE(error.find(p.string()), std::string::npos) << error;
  EXPECT_NE(error.find("not a database"), std::string::npos) << error;
  EXPECT_NE(error.find("damaged"), std::string::npos) << error;
  EXPECT_EQ(test::slurp(p), before);
  // A real history with a page overwritten in its middle.
  const fs::path q = test::fresh_path("history", "damaged.sqlite");
  {
    auto store = open_store(q);
    ASSERT_TRUE(store);
    for (int i = 0; i < 200; ++i) ASSERT_TRUE(store->add(sample_flight(), error)) << error;
  }
  sql_int(q, "PRAGMA wal_checkpoint(TRUNCATE)");
  {
    std::fstream f(q, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(0);
    f << std::string(100, '\x5a');  // the header: no longer SQLite's
  }
  error.clear();
  EXPECT_FALSE(history::open_sqlite(q.string(), error));
  EXPECT_NE(error.find("damaged"), std::string::npos) << error;
}

// As root, permissions do not hold: the check runs in a child that drops to `nobody`.
template <class Check>
void as_a_user(Check check) {
  if (!running_as_root()) {
    check();
    return;
  }
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(77);
    check();
    ::_exit(testing::Test::HasFailure() ? 1 : 0);
  }
  int st = 0;
  ASSERT_EQ(::waitpid(pid, &st, 0), pid);
  ASSERT_TRUE(WIFEXITED(st));
  if (WEXITSTATUS(st) == 77) GTEST_SKIP() << "cannot drop root to test permissions";
  EXPECT_EQ(WEXITSTATUS(st), 0) << "the check failed as nobody (its output is above)";
}

TEST(HistoryStore, AReadOnlyFileOrFolderIsSaidAsSuch) {
  const fs::path dir = test::fresh_path("history", "ro");
  fs::create_directories(dir);
  const fs::path p = dir / "history.sqlite";
  std::string error;
  {
    auto store = open_store(p);
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->add(sample_flight(), error)) << error;
  }
  sql_int(p, "PRAGMA wal_checkpoint(TRUNCATE)");
  ::chmod(p.c_str(), 0444);
  // Readable by all (the folders on the way too), writable by nobody but root.
  for (fs::path d = dir; d != test::process_temp_dir().parent_path(); d = d.parent_path())
    ::chmod(d.c_str(), 0755);
  ::chmod(dir.c_str(), 0555);
  as_a_user([&] {
    std::string why;
    auto store = history::open_sqlite(p.string(), why);
    if (store) {
      EXPECT_FALSE(store->add(sample_flight(), why));
    }
    EXPECT_NE(why.find("cannot be written"), std::string::npos) << why;
    EXPECT_NE(why.find(p.string()), std::string::npos) << why;
    // A folder where no history can be made.
    why.clear();
    EXPECT_FALSE(history::open_sqlite((dir / "new.sqlite").string(), why));
    EXPECT_NE(why.find("cannot be written"), std::string::npos) << why;
  });
  ::chmod(dir.c_str(), 0700);
  ::chmod(p.c_str(), 0600);
}

// Another program holding the write lock past the busy timeout: the write waits that long,
// then says why.
TEST(HistoryStore, ALockedDatabaseWaitsThenSaysSo) {
  const fs::path p = test::fresh_path("history", "locked.sqlite");
  { ASSERT_TRUE(open_store(p)); }
  sqlite3* holder = nullptr;
  ASSERT_EQ(sqlite3_open(p.c_str(), &holder), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(holder, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  history::SqliteSettings s;
  s.busy_timeout_ms = 300;
  std::string error;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_FALSE(history::open_sqlite(p.string(), error, s));
  const double waited =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(waited, 0.25);
  EXPECT_LT(waited, 5.0);
  EXPECT_NE(error.find("locked"), std::string::npos) << error;
  sqlite3_exec(holder, "COMMIT", nullptr, nullptr, nullptr);
  // Opened before the lock, a store's write waits the same way.
  auto store = open_store(p, s);
  ASSERT_TRUE(store);
  ASSERT_EQ(sqlite3_exec(holder, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  error.clear();
  EXPECT_FALSE(store->add(sample_flight(), error));
  EXPECT_NE(error.find("locked"), std::string::npos) << error;
  sqlite3_exec(holder, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(holder);
  EXPECT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
}

// The default file's missing folders are made, private to the user.
TEST(HistoryStore, MissingFoldersAreMadePrivate) {
  const fs::path base = test::fresh_path("history", "xdg");
  const fs::path p = base / "a" / "b" / "history.sqlite";
  ASSERT_TRUE(open_store(p));
  EXPECT_TRUE(fs::exists(p));
  struct stat st {};
  ASSERT_EQ(::stat((base / "a" / "b").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  ASSERT_EQ(::stat((base / "a").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  // The factory: "" is the default file under $XDG_DATA_HOME; sqlite:PATH a file.
  setenv("XDG_DATA_HOME", base.c_str(), 1);
  std::string error;
  auto d = history::open_history("", error);
  ASSERT_TRUE(d) << error;
  EXPECT_EQ(d->where(), (base / "mixpilot" / "history.sqlite").string());
  auto s = history::open_history("sqlite:" + (base / "x.sqlite").string(), error);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->where(), (base / "x.sqlite").string());
  EXPECT_FALSE(history::open_history("postgresql://user:secret@host/db", error));
  EXPECT_NE(error.find("PostgreSQL"), std::string::npos) << error;
  EXPECT_EQ(error.find("secret"), std::string::npos) << error;
  EXPECT_FALSE(history::open_history(base.string(), error));  // a folder
  EXPECT_NE(error.find("folder"), std::string::npos) << error;
}

// ---- Writers at once, and killed ----------------------------------------------------------

// Processes that open the same new file together: one switches it to WAL and creates the
// schema, the others wait for it (SQLite refuses the switch at once, without its busy handler,
// while another opener holds a lock): every opener succeeds, in every round.
TEST(HistoryStore, EightProcessesOpenANewFileAtOnce) {
  constexpr int kRounds = 25, kProcs = 8;
  for (int round = 0; round < kRounds; ++round) {
    const fs::path p =
        test::fresh_path("history", "opened_together_" + std::to_string(round) + ".sqlite");
    EXPECT_EQ(test::failed_children(kProcs,
                                    [&](int k) {
                                      std::string error;
                                      if (history::open_sqlite(p.string(), error)) return 0;
                                      std::fprintf(stderr, "round %d, child %d: %s\n", round, k,
                                                   error.c_str());
                                      return 2;
                                    }),
              0)
        << "round " << round;
  }
}

// Eight processes write 50 flights each into one file at once: 400 rows, none lost.
TEST(HistoryStore, EightProcessesWriteAtOnce) {
  const fs::path p = test::fresh_path("history", "parallel.sqlite");
  constexpr int kProcs = 8, kEach = 50;
  const int failed = test::failed_children(kProcs, [&](int k) {
    return test::write_flights(p.string(), k, kEach, [](int k, int i) {
      FlightRecord f = sample_flight("writer " + std::to_string(k), i);
      f.recording_hash = sha256_hex(std::to_string(k) + "/" + std::to_string(i));
      return f;
    });
  });
  EXPECT_EQ(failed, 0) << "writers failed";
  auto store = open_store(p);
  ASSERT_TRUE(store);
  const auto rows = all(*store);
  EXPECT_EQ(rows.size(), std::size_t(kProcs * kEach));
  std::set<std::string> hashes;
  for (const auto& r : rows) hashes.insert(r.recording_hash);
  EXPECT_EQ(hashes.size(), std::size_t(kProcs * kEach));
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM metrics"), kProcs * kEach * 4);
  EXPECT_EQ(sql_int(p, "SELECT count(*) FROM schema_version"), history::kSchemaVersion);
  std::vector<std::string> names;
  std::string error;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names.size(), std::size_t(kProcs));
}

// A writer killed (SIGKILL) in the middle of its transactions: the file passes SQLite's
// integrity check and holds every flight whose commit the writer reported, and nothing half.
TEST(HistoryStore, AWriterKilledMidTransactionLosesNothingCommitted) {
  const fs::path p = test::fresh_path("history", "killed.sqlite");
  { ASSERT_TRUE(open_store(p)); }
  constexpr int kMetrics = 3000;  // a long transaction: the kill lands inside one
  const test::KilledWriter w = test::kill_a_writer_mid_transaction(
      [&] {
        std::string error;
        return history::open_sqlite(p.string(), error);
      },
      [](int i) { return sample_flight("killed", i); }, kMetrics, 20, std::chrono::milliseconds(7));
  ASSERT_TRUE(w.killed) << "the writer ended before the kill: " << w.status;
  const int last = w.last_reported;
  EXPECT_EQ(sql_text(p, "PRAGMA integrity_check"), "ok");
  EXPECT_EQ(sql_int(p, "PRAGMA foreign_key_check"), -1) << "a dangling reference";
  auto store = open_store(p);
  ASSERT_TRUE(store);
  const auto rows = all(*store);
  ASSERT_GE(rows.size(), std::size_t(last + 1));
  EXPECT_LE(rows.size(), std::size_t(last + 2));  // at most the one committed unreported
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].started_unix_ms, std::int64_t(i));
    EXPECT_EQ(rows[i].metrics.size(), std::size_t(kMetrics)) << "a flight half written";
  }
}


// ---- history push: every table, once --------------------------------------------------------

// A station's whole history pushed into a centre's (here SQLite; the Postgres.* tests push into
// PostgreSQL): every row of every table the schema has, ids aside, arrives — flights with every
// column (a branch, the instructor's end, a probe, unrecorded ones), their metrics, the lesson
// attempts and each trainee's place in each lesson — beside what the centre held (another
// station's flight, and a lesson flight an older mixpilot pushed without its verdict, which
// gains it); pushing again changes nothing.
TEST(HistoryPush, EveryTableArrivesOnceAndTwiceAddsNothing) {
  std::string error;
  const fs::path station_file = test::fresh_path("history", "push_station.sqlite");
  auto station = open_store(station_file);
  ASSERT_TRUE(station);
  ASSERT_NO_FATAL_FAILURE(test::fill_every_column(*station));
  const test::HistoryDump mine = test::dump_history(station_file);
  test::expect_every_column_varies(mine);
  for (const char* table : {"trainees", "flights", "metrics", "lesson_attempts", "lesson_progress"})
    EXPECT_FALSE(mine.rows.at(table).empty()) << table;

  const fs::path other_file = test::fresh_path("history", "push_other.sqlite");
  const fs::path centre_file = test::fresh_path("history", "push_centre.sqlite");
  auto other = open_store(other_file);
  auto centre = open_store(centre_file);
  ASSERT_TRUE(other && centre);
  FlightRecord elsewhere = sample_flight("Zoe", 1'600'000'000'000);
  elsewhere.station = "station-9";
  ASSERT_EQ(other->add(elsewhere, error), HistoryStore::Added::added) << error;
  ASSERT_EQ(centre->add(elsewhere, error), HistoryStore::Added::added) << error;
  const std::vector<StoredFlight> flights = all(*station);
  const auto lesson_flight = std::find_if(flights.begin(), flights.end(),
                                          [](const StoredFlight& f) { return f.attempt(); });
  ASSERT_NE(lesson_flight, flights.end());
  ASSERT_EQ(centre->add(*lesson_flight, error), HistoryStore::Added::added) << error;

  history::PushCounts counts;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.flights, flights.size());
  EXPECT_EQ(counts.added, flights.size() - 1);
  EXPECT_EQ(counts.already_there, 1u);
  EXPECT_EQ(counts.attempts, mine.rows.at("lesson_attempts").size());
  EXPECT_EQ(counts.progress, mine.rows.at("lesson_progress").size());
  const test::HistoryDump want = test::union_of(mine, test::dump_history(other_file));
  test::expect_same_history(test::dump_history(centre_file), want, "after a push");

  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 0u);
  EXPECT_EQ(counts.already_there, flights.size());
  EXPECT_EQ(counts.attempts, 0u);
  EXPECT_EQ(counts.progress, 0u);
  test::expect_same_history(test::dump_history(centre_file), want, "after a second push");
}

// Where a trainee is in a lesson, pushed: the row updated last wins. A centre whose row is newer
// (the trainee flew there since) keeps it; a station's newer row (a reset there) replaces it.
TEST(HistoryPush, TheNewestProgressWins) {
  std::string error;
  auto station = open_store(test::fresh_path("history", "newest_station.sqlite"));
  auto centre = open_store(test::fresh_path("history", "newest_centre.sqlite"));
  ASSERT_TRUE(station && centre);
  using Added = HistoryStore::Added;
  const auto pause = [] { std::this_thread::sleep_for(std::chrono::milliseconds(3)); };
  ASSERT_EQ(station->add_attempt(test::flight("Ada", 1000, 80.0), test::attempt(0, true), error),
            Added::added)
      << error;
  history::PushCounts counts;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.progress, 1u);
  EXPECT_EQ(test::progress_of(*centre, "Ada").step, 1);
  pause();
  ASSERT_EQ(centre->add_attempt(test::flight("Ada", 2000, 40.0), test::attempt(1, false), error),
            Added::added)
      << error;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.progress, 0u);
  history::LessonProgress p = test::progress_of(*centre, "Ada");
  EXPECT_EQ(p.step, 1);
  EXPECT_EQ(p.failed_attempts, 1);
  pause();
  ASSERT_TRUE(station->reset_lesson("Ada", "beginner", "h1", error)) << error;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.progress, 1u);
  p = test::progress_of(*centre, "Ada");
  EXPECT_EQ(p.step, 0);
  EXPECT_EQ(p.failed_attempts, 0);
  // The attempts of both stores are all at the centre.
  std::vector<history::StoredAttempt> attempts;
  ASSERT_TRUE(centre->lesson_attempts("Ada", "beginner", "h1", attempts, error)) << error;
  EXPECT_EQ(attempts.size(), 2u);
}

// ---- Every front end's flight, once ----------------------------------------------------------

const std::string kSrc = MIXPILOT_SOURCE_DIR;
const std::string kMixpilot = MIXPILOT_BINARY;

// A user's folders in a fresh place; their default history file.
fs::path fresh_home(const std::string& name) {
  const fs::path home = test::fresh_path("history_home", name);
  fs::create_directories(home);
  return home;
}
fs::path default_history(const fs::path& home) {
  return home / "data" / "mixpilot" / "history.sqlite";
}
std::int64_t rows_in(const fs::path& db) {
  return fs::exists(db) ? sql_int(db, "SELECT count(*) FROM flights") : 0;
}
int count_of(const std::string& text, const std::string& needle) {
  int n = 0;
  for (std::size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1))
    ++n;
  return n;
}

// A probe flight (`--assist off`) is a probe in the history too, with its dependence D = 0.
TEST(HistoryFrontEnds, AProbeFlightIsRememberedAsAProbe) {
  const fs::path home = fresh_home("probe");
  ASSERT_EQ(test::run_mixpilot(kMixpilot,
                               "fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot novice "
                               "--headless --duration 2 --assist off --trainee probe",
                               home),
            0)
      << test::read_file(home / "out.txt");
  std::string error;
  auto store = history::open_sqlite(default_history(home).string(), error);
  ASSERT_TRUE(store) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_TRUE(rows[0].probe);
  bool has_d = false;
  for (const auto& [name, value] : rows[0].metrics) {
    if (name != "assistance_dependence") continue;
    has_d = true;
    EXPECT_EQ(value, 0.0);
  }
  EXPECT_TRUE(has_d);
}

// `fly --headless`: one row with the flight's fields, its metrics the report's; score, replay,
// fly of the recording and import add nothing (they are not new flights).
TEST(HistoryFrontEnds, FlyHeadlessIsRememberedOnceAndReplaysAddNothing) {
  const fs::path home = fresh_home("fly");
  const fs::path rec = home / "recs" / "a.mcap", report = home / "a.json";
  fs::create_directories(rec.parent_path());
  const std::string scen = kSrc + "/scenarios/mi_helix.toml";
  ASSERT_EQ(test::run_mixpilot(kMixpilot,
                               "fly --scenario " + scen + " --pilot novice --headless --duration 3 "
                               "--trainee \"Zoë O'Brien\" --record " + rec.string() +
                                   " --report " + report.string(),
                               home),
            0)
      << test::read_file(home / "out.txt");
  const fs::path db = default_history(home);
  ASSERT_EQ(rows_in(db), 1) << test::read_file(home / "out.txt");
  std::string error;
  auto store = history::open_sqlite(db.string(), error);
  ASSERT_TRUE(store) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  const StoredFlight& f = rows[0];
  EXPECT_EQ(f.trainee, "Zoë O'Brien");
  EXPECT_EQ(f.station, history::host_name());
  EXPECT_EQ(f.scenario, "mi_helix");
  EXPECT_EQ(f.scenario_hash, sha256_hex(test::read_file(scen)));
  EXPECT_EQ(f.mode, "mixed_initiative");
  EXPECT_EQ(f.pilot, "novice");
  EXPECT_EQ(f.input_device, "");
  EXPECT_NEAR(f.duration_s, 3.0, 1e-9);
  EXPECT_EQ(f.ended, history::Ended::completed);
  EXPECT_FALSE(f.probe);
  EXPECT_EQ(f.recording_path, rec.string());
  EXPECT_EQ(f.recording_hash, *sha256_file(rec.string(), error));
  EXPECT_EQ(f.app_version, version());
  EXPECT_EQ(f.front_end, "fly");
  const auto now_ms = std::chrono::duration_cast<std::chrono::milliseconds>(
                          std::chrono::system_clock::now().time_since_epoch())
                          .count();
  EXPECT_GT(f.started_unix_ms, now_ms - 120'000);
  EXPECT_LE(f.started_unix_ms, now_ms);
  const auto reported = test::numbers(test::read_file(report));
  ASSERT_FALSE(f.metrics.empty());
  for (const auto& [name, value] : f.metrics) {
    ASSERT_TRUE(reported.count(name)) << name;
    EXPECT_NEAR(value, reported.at(name), 1e-12 * std::max(1.0, std::abs(value))) << name;
  }
  EXPECT_EQ(f.metrics.size(), reported.size());
  // Not new flights: nothing added.
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "score " + rec.string(), home), 0);
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "replay --headless " + rec.string(), home), 0);
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "fly --headless --pilot " + rec.string(), home), 0);
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history import " + rec.parent_path().string(), home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("already in the history"), std::string::npos);
  EXPECT_EQ(rows_in(db), 1);
  // --history off: nothing; another file: there.
  const fs::path other = home / "other.sqlite";
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "fly --scenario " + scen + " --pilot novice --headless "
                                          "--duration 1 --history off", home), 0);
  EXPECT_EQ(rows_in(db), 1);
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "fly --scenario " + scen + " --pilot novice --headless "
                                          "--duration 1 --history sqlite:" + other.string(), home), 0);
  EXPECT_EQ(rows_in(db), 1);
  EXPECT_EQ(rows_in(other), 1);
  // What `history` shows of it, in each form.
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history --json", home), 0);
  const std::string json = test::read_file(home / "out.txt");
  EXPECT_NE(json.find("\"trainee\": \"Zoë O'Brien\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"front_end\": \"fly\""), std::string::npos) << json;
  EXPECT_EQ(test::numbers(json).at("skill"), reported.at("skill"));
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history --csv", home), 0);
  const std::string csv = test::read_file(home / "out.txt");
  EXPECT_EQ(count_of(csv, "\n"), 2) << csv;
  EXPECT_NE(csv.find(",metrics.skill"), std::string::npos) << csv;
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history --trainee nobody", home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("0 flights"), std::string::npos);
}

// A learning curve that means something: one trainee flies the helix five times as the novice
// profile, then five times as the experienced one (each attempt with its own position noise, so
// no two flights are alike), and a probe of each. What `history --json` gives back shows the
// skill rising and the assistance dependence D falling, each probe marked as one and scoring
// below the assisted flights of its pilot; the Progress panel's trend says the same.
TEST(HistoryLearningCurve, TheSkillRisesAndTheDependenceFalls) {
  const fs::path home = fresh_home("learning_curve");
  const std::string helix = test::read_file(kSrc + "/scenarios/mi_helix.toml");
  const auto fly = [&](const std::string& pilot, int seed, bool probe) {
    std::string toml = helix;
    const auto set = [&](const std::string& from, const std::string& to) {
      const std::size_t at = toml.find(from);
      ASSERT_NE(at, std::string::npos) << from;
      toml.replace(at, from.size(), to);
    };
    set("\nposition_noise = 0.0", "\nposition_noise = 0.01");
    set("\nseed = 1", "\nseed = " + std::to_string(seed));
    const fs::path scenario = home / ("helix_" + std::to_string(seed) + ".toml");
    std::ofstream(scenario) << toml;
    ASSERT_EQ(test::run_mixpilot(kMixpilot,
                                 "fly --scenario " + scenario.string() + " --pilot " + pilot +
                                     " --headless --duration 15 --trainee Grace" +
                                     (probe ? " --assist off" : ""),
                                 home),
              0)
        << test::read_file(home / "out.txt");
  };
  for (int seed = 1; seed <= 5; ++seed) fly("novice", seed, false);
  for (int seed = 6; seed <= 10; ++seed) fly("experienced", seed, false);
  fly("novice", 11, true);
  fly("experienced", 12, true);
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history --trainee Grace --json", home), 0);

  // One flight per line of the JSON array, oldest first.
  struct Row { std::string pilot; bool probe; double skill, d; };
  std::vector<Row> rows;
  std::istringstream json(test::read_file(home / "out.txt"));
  for (std::string line; std::getline(json, line);) {
    if (line.find("\"trainee\": \"Grace\"") == std::string::npos) continue;
    const auto numbers = test::numbers(line);
    const bool probe = line.find("\"probe\": true") != std::string::npos;
    const std::string pilot = line.find("\"pilot\": \"novice\"") != std::string::npos ? "novice"
                                                                                     : "experienced";
    rows.push_back({pilot, probe, numbers.at("skill"), numbers.at("assistance_dependence")});
  }
  ASSERT_EQ(rows.size(), 12u) << test::read_file(home / "out.txt");
  std::vector<double> skill, d;
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(rows[i].pilot, i < 5 ? "novice" : "experienced") << i;
    EXPECT_FALSE(rows[i].probe) << i;
    skill.push_back(rows[i].skill);
    d.push_back(rows[i].d);
  }
  // Rising and falling: every experienced attempt above (below) every novice one, and the
  // least-squares line through the ten attempts with the right sign.
  EXPECT_GT(*std::min_element(skill.begin() + 5, skill.end()),
            *std::max_element(skill.begin(), skill.begin() + 5));
  EXPECT_LT(*std::max_element(d.begin() + 5, d.end()), *std::min_element(d.begin(), d.begin() + 5));
  EXPECT_GT(*cli::least_squares_slope(skill), 0.0);
  EXPECT_LT(*cli::least_squares_slope(d), 0.0);
  // The noise makes attempts differ: a curve, not two repeated flights.
  EXPECT_NE(skill[0], skill[1]);
  EXPECT_NE(skill[5], skill[6]);
  // The probes: marked, D = 0, each below every assisted flight of its pilot.
  for (const int i : {10, 11}) {
    EXPECT_TRUE(rows[i].probe) << i;
    EXPECT_EQ(rows[i].d, 0.0) << i;
    const auto first = skill.begin() + (i == 10 ? 0 : 5);
    EXPECT_LT(rows[i].skill, *std::min_element(first, first + 5)) << rows[i].pilot;
  }
  // The Progress panel's view of the same rows: ten assisted attempts, two probes, a rising trend.
  std::string error;
  auto store = history::open_sqlite(default_history(home).string(), error);
  ASSERT_TRUE(store) << error;
  const ui::ProgressView v = cli::progress_view(all(*store), "Grace", "mi_helix", false);
  EXPECT_EQ(v.assisted, 10);
  EXPECT_EQ(v.probes, 2);
  EXPECT_GT(v.assisted_trend.slope, 0.0);
  EXPECT_TRUE(v.assisted_trend.words.starts_with("rising")) << v.assisted_trend.words;
  ASSERT_GE(v.best, 5);
  EXPECT_EQ(v.flights[v.best].skill, *std::max_element(skill.begin(), skill.end()));
  EXPECT_TRUE(std::isnan(v.flights[10].dependence));  // a probe's D is no measure of reliance
  EXPECT_NEAR(v.flights[9].dependence, d[9], 1e-12);
}

// history import: recordings flown again and added once, a bad file named with its reason
// while the others are imported; importing again adds nothing.
TEST(HistoryFrontEnds, ImportAddsEachRecordingOnce) {
  const fs::path home = fresh_home("import");
  const fs::path dir = home / "recs";
  fs::create_directories(dir / "sub");
  const std::string scen = kSrc + "/scenarios/mi_helix.toml";
  for (const char* name : {"a.mcap", "sub/b.mcap"})
    ASSERT_EQ(test::run_mixpilot(kMixpilot, "fly --scenario " + scen + " --pilot experienced "
                                            "--headless --duration 2 --history off --record " +
                                                (dir / name).string(), home),
              0);
  std::ofstream(dir / "bad.mcap") << "not a recording";
  const fs::path db = default_history(home);
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history --json", home), 0);
  EXPECT_EQ(test::read_file(home / "out.txt"), "[]\n");
  EXPECT_FALSE(fs::exists(db)) << "a listing made a history";
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history import " + dir.string() + " --jobs 2 "
                                          "--trainee Imported", home), 1);
  const std::string out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("bad.mcap: not imported: "), std::string::npos) << out;
  EXPECT_NE(out.find("not an MCAP file"), std::string::npos) << out;
  EXPECT_NE(out.find("2 added"), std::string::npos) << out;
  EXPECT_EQ(rows_in(db), 2);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM flights WHERE front_end = 'import'"), 2);
  EXPECT_EQ(sql_text(db, "SELECT name FROM trainees"), "Imported");
  fs::remove(dir / "bad.mcap");
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history import " + dir.string(), home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("0 added, 2 already known"), std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_EQ(rows_in(db), 2);
}

// history import of a lesson step's recording: the flight and its attempt's verdict, judged
// again against the lesson its metadata names (the shipped one by its SHA-256), row for row as
// the station that flew it wrote them; where the trainee is in the lesson is left alone. A
// recording of a lesson no file here has is imported as a flight and said; with --lesson FILE
// its verdict comes too.
TEST(HistoryFrontEnds, ImportKeepsALessonAttemptsVerdict) {
  const fs::path home = fresh_home("import_lesson");
  const fs::path recs = home / "recs", flown = home / "flown.sqlite";
  fs::create_directories(recs / "mine");
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "lesson beginner --trainee Ada --headless --pilot "
                                          "experienced --record-dir " + recs.string() +
                                          " --history " + flown.string(), home),
            0)
      << test::read_file(home / "out.txt");
  // The same course, edited (another SHA-256), flown once too.
  {
    std::ifstream in(kSrc + "/scenarios/lessons/beginner.toml");
    std::ofstream out(home / "mine.toml");
    out << in.rdbuf() << "# edited: another lesson\n";
  }
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "lesson " + (home / "mine.toml").string() +
                                          " --trainee Ada --headless --pilot experienced "
                                          "--record-dir " + (recs / "mine").string() +
                                          " --history " + (home / "mine.sqlite").string(), home),
            0)
      << test::read_file(home / "out.txt");

  const fs::path imported = home / "imported.sqlite";
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history import " + recs.string() + " --history " +
                                          imported.string(), home),
            0);
  const std::string out = test::read_file(home / "out.txt");
  EXPECT_NE(out.find("added (skill"), std::string::npos) << out;
  EXPECT_NE(out.find("beginner step 1 passed"), std::string::npos) << out;
  EXPECT_NE(out.find("its lesson attempt (beginner, step 1) is not: no lesson file here has its "
                     "SHA-256"),
            std::string::npos)
      << out;
  EXPECT_EQ(rows_in(imported), 2);
  // The shipped lesson's attempt: the same row as the station's (flight by recording hash).
  const test::HistoryDump a = test::dump_history(flown), b = test::dump_history(imported);
  ASSERT_EQ(a.rows.at("lesson_attempts").size(), 1u);
  EXPECT_EQ(b.rows.at("lesson_attempts"), a.rows.at("lesson_attempts"));
  EXPECT_TRUE(b.rows.at("lesson_progress").empty());
  // The edited lesson's recording, into a fresh history with its file named.
  const fs::path with_file = home / "with_file.sqlite";
  ASSERT_EQ(test::run_mixpilot(kMixpilot, "history import " + (recs / "mine").string() +
                                          " --lesson " + (home / "mine.toml").string() +
                                          " --history " + with_file.string(), home),
            0);
  EXPECT_EQ(test::dump_history(with_file).rows.at("lesson_attempts"),
            test::dump_history(home / "mine.sqlite").rows.at("lesson_attempts"));
  // A --lesson that is no lesson: said, nothing imported.
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history import " + recs.string() + " --lesson " +
                                          (home / "out.txt").string() + " --history " +
                                          (home / "none.sqlite").string(), home),
            1);
  EXPECT_NE(test::read_file(home / "out.txt").find("--lesson " + (home / "out.txt").string()),
            std::string::npos);
  EXPECT_FALSE(fs::exists(home / "none.sqlite"));
}

// A history that cannot be used: fly says so once on stderr, and still flies, records and
// exits 0.
TEST(HistoryFrontEnds, ABrokenHistoryNeverCostsTheFlight) {
  const std::string scen = kSrc + "/scenarios/mi_helix.toml";
  struct Case {
    const char* name;
    std::function<void(const fs::path&)> make;  // breaks the history at this path
    const char* said;
  };
  const Case cases[] = {
      {"corrupt", [](const fs::path& p) { std::ofstream(p) << std::string(4096, 'x'); },
       "not a database"},
      {"newer",
       [](const fs::path& p) {
         { ASSERT_TRUE(open_store(p)); }
         sql_int(p, "INSERT INTO schema_version VALUES (7, 0) RETURNING version");
       },
       "newer mixpilot"},
      {"folder", [](const fs::path& p) { fs::create_directories(p); }, "is a folder"},
  };
  for (const Case& c : cases) {
    const fs::path home = fresh_home(std::string("broken_") + c.name);
    const fs::path db = home / "h.sqlite", rec = home / "r.mcap";
    c.make(db);
    EXPECT_EQ(test::run_mixpilot(kMixpilot, "fly --scenario " + scen + " --pilot novice "
                                            "--headless --duration 1 --history " + db.string() +
                                                " --record " + rec.string(), home),
              0)
        << c.name;
    const std::string out = test::read_file(home / "out.txt");
    EXPECT_EQ(count_of(out, "history: "), 1) << c.name << ": " << out;
    EXPECT_NE(out.find(c.said), std::string::npos) << c.name << ": " << out;
    EXPECT_NE(out.find("flown but not remembered"), std::string::npos) << out;
    EXPECT_NE(out.find("recorded " + rec.string()), std::string::npos) << out;
    EXPECT_TRUE(fs::exists(rec)) << c.name;
  }
}

// The rig (every front end's flight) with the history locked past its busy timeout: the
// flight flies and records, the close says why the row is missing; once the lock is gone the
// next flight is remembered. And a replay's rig never writes a row.
TEST(HistoryFrontEnds, ALockedHistoryCostsOnlyTheRow) {
  const fs::path dir = test::fresh_path("history", "rig_locked");
  fs::create_directories(dir);
  const fs::path db = dir / "h.sqlite";
  history::SqliteSettings s;
  s.busy_timeout_ms = 200;
  std::string error;
  { ASSERT_TRUE(history::open_sqlite(db.string(), error, s)) << error; }
  cli::HistoryWriter writer([&](std::string& why) { return history::open_sqlite(db.string(), why, s); });
  // The writer's outcome of the flight just closed.
  const auto outcome = [&] {
    writer.wait_idle();
    std::vector<cli::HistoryWriter::Outcome> out;
    EXPECT_TRUE(writer.poll(out));
    EXPECT_EQ(out.size(), 1u);
    return out.empty() ? cli::HistoryWriter::Outcome{} : out.back();
  };
  const auto fly = [&](const fs::path& rec) {
    cli::FlyOptions o;
    o.scenario_path = kSrc + "/scenarios/mi_helix.toml";
    o.pilot = "novice";
    o.duration = 1.0;
    int status = 0;
    std::string why;
    auto rig = cli::FlightRig::assemble(o, why, status);
    EXPECT_TRUE(rig) << why;
    EXPECT_TRUE(rig->record(rec.string(), "Lena", {}, true, why)) << why;
    rig->remember(&writer, "Lena", "fly");
    rig->start();
    while (rig->step()) {
    }
    return rig->close(false);
  };
  sqlite3* holder = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &holder), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(holder, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  const auto locked = fly(dir / "locked.mcap");
  EXPECT_EQ(locked.recorded, (dir / "locked.mcap").string());
  EXPECT_EQ(locked.error, "");
  EXPECT_TRUE(locked.remembering);
  const auto locked_row = outcome();
  EXPECT_FALSE(locked_row.remembered);
  EXPECT_NE(locked_row.error.find("locked"), std::string::npos) << locked_row.error;
  sqlite3_exec(holder, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(holder);
  (void)fly(dir / "free.mcap");
  const auto free_row = outcome();
  EXPECT_TRUE(free_row.remembered) << free_row.error;
  EXPECT_EQ(rows_in(db), 1);
  // A replay of it: the rig is given the store, and adds nothing.
  cli::FlyOptions o;
  o.pilot = (dir / "free.mcap").string();
  o.replay = true;
  int status = 0;
  auto rig = cli::FlightRig::assemble(o, error, status);
  ASSERT_TRUE(rig) << error;
  rig->remember(&writer, "Lena", "fly");
  rig->start();
  while (rig->step()) {
  }
  const auto replayed = rig->close(false);
  EXPECT_FALSE(replayed.remembering);
  writer.wait_idle();
  EXPECT_EQ(rows_in(db), 1);
}

// The window's live flight, driven through the app as the window does (no frames needed): the
// trainee typed in the session panel, recorded, remembered once as "window"; a flight that was
// made ready but never started is not.
TEST(HistoryFrontEnds, TheWindowsLiveFlightIsRememberedOnce) {
  const fs::path home = fresh_home("window");
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
  cli::FlyOptions o;
  o.scenario_path = kSrc + "/scenarios/mi_helix.toml";
  o.pilot = "novice";
  o.duration = 1.5;
  o.record = (home / "w.mcap").string();
  {
    cli::Trainer app(o);
    std::string error;
    int status = 0;
    ASSERT_TRUE(app.open_live(error, status)) << error;
    app.act(ui::LiveRequest{ui::SetTrainee{"Marie-Hélène"}});
    app.start();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (app.live()->rig->running() && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    testing::internal::CaptureStdout();
    EXPECT_EQ(app.finish(), 0);
    testing::internal::GetCapturedStdout();
  }
  {
    cli::Trainer app(o);  // opened, never started
    std::string error;
    int status = 0;
    ASSERT_TRUE(app.open_live(error, status)) << error;
    testing::internal::CaptureStdout();
    (void)app.finish();
    testing::internal::GetCapturedStdout();
  }
  const fs::path db = default_history(home);
  ASSERT_EQ(rows_in(db), 1);
  std::string error;
  auto store = history::open_sqlite(db.string(), error);
  ASSERT_TRUE(store) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].trainee, "Marie-Hélène");
  EXPECT_EQ(rows[0].front_end, "window");
  EXPECT_EQ(rows[0].pilot, "novice");
  EXPECT_NEAR(rows[0].duration_s, 1.5, 0.02);
  EXPECT_EQ(rows[0].recording_path, o.record);
  EXPECT_EQ(rows[0].recording_hash, *sha256_file(o.record, error));
}

// ---- The history's thread, the window's view of it, the report --------------------------------

// The window with another program holding the history locked: a flight closes and its row
// waits on the writer's thread while every frame is drawn in time; once the lock is gone the
// row lands and the status line says so.
TEST(HistoryWindow, ALockedHistoryNeverStallsAFrame) {
  const fs::path home = fresh_home("window_locked");
  setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
  const fs::path db = default_history(home);
  std::string error;
  { ASSERT_TRUE(history::open_sqlite(db.string(), error)) << error; }
  cli::Offscreen screen;
  if (!screen.open(640, 360, error)) GTEST_SKIP() << "no EGL device: " << error;
  cli::FlyOptions o;
  o.scenario_path = kSrc + "/scenarios/mi_helix.toml";
  o.pilot = "novice";
  o.duration = 1.0;
  o.record = (home / "w.mcap").string();
  sqlite3* holder = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &holder), SQLITE_OK);
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::LiveRequest{ui::SetTrainee{"Ada"}});
  double longest = 0.0;
  const auto frame = [&] {
    const auto t0 = std::chrono::steady_clock::now();
    screen.frame([&] { app.build_frame(1.0 / 60.0); });
    longest = std::max(longest, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  };
  for (int i = 0; i < 5; ++i) screen.frame([&] { app.build_frame(1.0 / 60.0); });  // fonts, first layout
  ASSERT_EQ(sqlite3_exec(holder, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  app.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!app.over() && std::chrono::steady_clock::now() < deadline) frame();
  ASSERT_TRUE(app.over());
  // The row waits for the lock (the store's busy timeout is 5 s) while it is held for 3 s more:
  // frames go on meanwhile. A UI thread that waited on the store would show one frame as long
  // as the rest of the hold; a busy machine only makes each frame slower, never that long.
  constexpr double kHold = 3.0;  // [s]
  const auto held_until = std::chrono::steady_clock::now() + std::chrono::duration<double>(kHold);
  int frames_while_held = 0;
  while (std::chrono::steady_clock::now() < held_until) {
    frame();
    ++frames_while_held;
  }
  EXPECT_GE(frames_while_held, 3);
  EXPECT_EQ(sql_int(db, "SELECT count(*) FROM flights"), 0);  // WAL: a reader is not blocked
  EXPECT_EQ(app.run_info().message.find("remembered"), std::string::npos) << app.run_info().message;
  sqlite3_exec(holder, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(holder);
  const auto landed = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (app.run_info().message.find("remembered") == std::string::npos &&
         std::chrono::steady_clock::now() < landed)
    frame();
  EXPECT_NE(app.run_info().message.find("remembered in the history (Ada, "), std::string::npos)
      << app.run_info().message;
  EXPECT_EQ(rows_in(db), 1);
  EXPECT_LT(longest, kHold / 3) << "a frame took " << longest * 1e3 << " ms: it waited on the store";
  testing::internal::CaptureStdout();
  (void)app.finish();
  testing::internal::GetCapturedStdout();
}

// The writer past the store's busy timeout: each flight's outcome says why, and the window's
// status line says it once however many flights it costs.
TEST(HistoryWriter, ALockedHistoryIsSaidOnce) {
  const fs::path dir = test::fresh_path("history", "writer_locked");
  fs::create_directories(dir);
  const fs::path db = dir / "h.sqlite";
  history::SqliteSettings s;
  s.busy_timeout_ms = 100;
  std::string error;
  { ASSERT_TRUE(history::open_sqlite(db.string(), error, s)) << error; }
  sqlite3* holder = nullptr;
  ASSERT_EQ(sqlite3_open(db.c_str(), &holder), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(holder, "BEGIN EXCLUSIVE", nullptr, nullptr, nullptr), SQLITE_OK);
  cli::HistoryWriter writer([&](std::string& why) { return history::open_sqlite(db.string(), why, s); });
  writer.remember(sample_flight("Ada", 1), "");
  writer.remember(sample_flight("Ada", 2), "");
  writer.wait_idle();
  std::vector<cli::HistoryWriter::Outcome> out;
  ASSERT_TRUE(writer.poll(out));
  ASSERT_EQ(out.size(), 2u);
  for (const auto& o : out) {
    EXPECT_FALSE(o.remembered);
    EXPECT_NE(o.error.find("locked"), std::string::npos) << o.error;
  }
  EXPECT_FALSE(writer.poll(out)) << "outcomes are handed over once";
  // The window's status line: the same failure twice is said once.
  ui::RunInfo run;
  cli::StatusLine status(run);
  cli::FlyOptions fo;
  cli::InputController input("", status);
  cli::LiveController live(fo, input, status, &writer);
  live.history_outcome(out[0]);
  const std::string said = run.message;
  EXPECT_NE(said.find("history: "), std::string::npos) << said;
  status.say("recorded x.mcap");
  live.history_outcome(out[1]);
  EXPECT_EQ(run.message, "recorded x.mcap") << "said twice";
  sqlite3_exec(holder, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(holder);
  // Once the lock is gone the next flight lands.
  writer.remember(sample_flight("Ada", 3), "");
  writer.wait_idle();
  out.clear();
  ASSERT_TRUE(writer.poll(out));
  EXPECT_TRUE(out.back().remembered) << out.back().error;
}

// The session panel's picker: the trainees the history knows, loaded on the writer's thread
// into the snapshot, and the chosen trainee's progress on the chosen scenario.
TEST(HistoryWriter, TheSnapshotHoldsTheTraineesAndTheProgress) {
  const fs::path dir = test::fresh_path("history", "writer_view");
  fs::create_directories(dir);
  const fs::path db = dir / "h.sqlite";
  cli::HistoryWriter writer(db.string());
  writer.show("Bo", "mi_helix");
  writer.wait_idle();
  ASSERT_TRUE(writer.view());
  EXPECT_TRUE(writer.view()->trainees.empty());
  EXPECT_FALSE(fs::exists(db)) << "showing the history created it";
  for (const char* who : {"Zoë", "Bo", "Ada", "Bo"}) writer.remember(sample_flight(who, std::rand()), "");
  writer.wait_idle();
  const auto v = writer.view();
  ASSERT_TRUE(v);
  EXPECT_EQ(v->trainees, (std::vector<std::string>{"Ada", "Bo", "Zoë"}));
  EXPECT_EQ(v->progress.trainee, "Bo");
  EXPECT_EQ(v->progress.flights.size(), 2u);
  EXPECT_EQ(v->progress.error, "");
}

history::StoredFlight attempt(int i, double skill, bool probe, double d = NAN) {
  history::StoredFlight f;
  static_cast<FlightRecord&>(f) = sample_flight("Ada", 1'700'000'000'000 + i * 60'000);
  f.id = i + 1;
  f.probe = probe;
  f.metrics = {{"skill", skill}};
  if (!std::isnan(d)) f.metrics.emplace_back("assistance_dependence", d);
  return f;
}

// The Progress panel's numbers: the trend's sign and words, the best run, D only where rows
// have it.
TEST(HistoryProgress, TrendSignAndBestRun) {
  std::vector<history::StoredFlight> rows;
  for (int i = 0; i < 12; ++i) rows.push_back(attempt(i, 40.0 + 3.0 * i + (i % 2 ? 2.0 : -2.0), false, 0.6 - 0.04 * i));
  rows.push_back(attempt(12, 30.0, true, 0.0));  // a probe's D, 0 by construction: not shown
  rows.push_back(attempt(13, 20.0, true));
  rows.push_back(attempt(14, 10.0, true));
  const ui::ProgressView v = cli::progress_view(rows, "Ada", "mi_helix", false);
  EXPECT_EQ(v.assisted, 12);
  EXPECT_EQ(v.probes, 3);
  EXPECT_GT(v.assisted_trend.slope, 2.0);
  EXPECT_EQ(v.assisted_trend.over, cli::kTrendAttempts);
  EXPECT_TRUE(v.assisted_trend.words.starts_with("rising")) << v.assisted_trend.words;
  EXPECT_LT(v.probe_trend.slope, 0.0);
  EXPECT_TRUE(v.probe_trend.words.starts_with("falling")) << v.probe_trend.words;
  EXPECT_EQ(v.best, 11);  // 40 + 33 + 2
  EXPECT_NEAR(v.flights[11].skill, 75.0, 1e-9);
  EXPECT_TRUE(v.has_dependence);
  EXPECT_TRUE(std::isnan(v.flights[12].dependence));
  // Too few for a trend; no D anywhere.
  const ui::ProgressView few = cli::progress_view({attempt(0, 50, false), attempt(1, 60, false)},
                                                  "Ada", "mi_helix", false);
  EXPECT_TRUE(std::isnan(few.assisted_trend.slope));
  EXPECT_TRUE(few.assisted_trend.words.starts_with("no trend yet")) << few.assisted_trend.words;
  EXPECT_FALSE(few.has_dependence);
  EXPECT_EQ(few.best, 1);
  const std::vector<double> flat = {5, 5, 5, 5};
  EXPECT_NEAR(*cli::least_squares_slope(flat), 0.0, 1e-12);
  const std::vector<double> line = {1, 3, 5, 7};
  EXPECT_NEAR(*cli::least_squares_slope(line), 2.0, 1e-12);
}

// The report to take home: every string from the database escaped, nothing fetched from
// anywhere, a curve per scenario.
TEST(HistoryHtml, EscapesEveryStringAndFetchesNothing) {
  const std::string evil = "<script>alert(\"x\")</script> & 'O'Brien'";
  std::vector<history::StoredFlight> rows;
  for (int i = 0; i < 4; ++i) {
    auto f = attempt(i, 50.0 + i, i == 3, 0.5);
    f.trainee = evil;
    f.scenario = i < 2 ? "<b>bold</b>" : "mi_helix";
    f.recording_path = "/tmp/\"quoted\" & <odd>.mcap";
    rows.push_back(f);
  }
  const std::string html = cli::progress_html(evil, rows, 1'700'000'000'000);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<b>"), std::string::npos);
  EXPECT_EQ(html.find("<odd>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt; &amp; &#39;O&#39;Brien&#39;"),
            std::string::npos);
  EXPECT_NE(html.find("/tmp/&quot;quoted&quot; &amp; &lt;odd&gt;.mcap"), std::string::npos);
  for (const char* fetch : {"src=", "href=", "<link", "@import", "url(", "https:"})
    EXPECT_EQ(html.find(fetch), std::string::npos) << fetch;
  EXPECT_EQ(count_of(html, "<svg"), 2);
  EXPECT_EQ(count_of(html, "<section>"), 2);
  EXPECT_NE(html.find("@media print"), std::string::npos);
  EXPECT_EQ(cli::html_escape("a<b>&\"'"), "a&lt;b&gt;&amp;&quot;&#39;");
}

// `history --html`: written through the outputs' rules (never replaced without --force), and
// only for one trainee.
TEST(HistoryHtml, TheCommandWritesOneFileAndNeverClobbers) {
  const fs::path home = fresh_home("html");
  const fs::path db = home / "h.sqlite", out = home / "ada.html";
  {
    auto store = open_store(db);
    ASSERT_TRUE(store);
    std::string error;
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(store->add(sample_flight("Ada <3", 1'700'000'000'000 + i), error)) << error;
  }
  const std::string base = "history --history " + db.string() + " --trainee 'Ada <3' --html " + out.string();
  ASSERT_EQ(test::run_mixpilot(kMixpilot, base, home), 0) << test::read_file(home / "out.txt");
  const std::string html = test::read_file(out);
  EXPECT_NE(html.find("Progress report: Ada &lt;3"), std::string::npos);
  EXPECT_EQ(count_of(html, "<tr>") + count_of(html, "<tr class"), 4);  // the header and 3 flights
  EXPECT_NE(test::run_mixpilot(kMixpilot, base, home), 0);
  EXPECT_NE(test::read_file(home / "out.txt").find("exists"), std::string::npos)
      << test::read_file(home / "out.txt");
  EXPECT_EQ(test::run_mixpilot(kMixpilot, base + " --force", home), 0);
  EXPECT_EQ(test::run_mixpilot(kMixpilot, "history --history " + db.string() + " --html " +
                                              (home / "x.html").string(), home), 2);
}

}  // namespace
}  // namespace mixpilot
