// The PostgreSQL backend of the history against a real server that the test run starts itself
// (tests/postgres_server.hpp): the server helper, the store's contract, hostile names, writers
// at once, a newer schema, credentials kept out of every message, and `history push`.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/history/postgres_history.hpp"
#include "core/history/push.hpp"
#include "core/history/schema.hpp"
#include "core/history/sqlite_history.hpp"
#include "postgres_server.hpp"
#include "history_dump.hpp"
#include "history_test.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot::test {
namespace {

namespace fs = std::filesystem;
using history::FlightRecord;
using history::HistoryStore;
using history::StoredFlight;

[[maybe_unused]] const auto* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new PostgresEnvironment);

// The run's server is reachable with its password, private (no TCP listener), and not root's.
TEST(Postgres, ServerStartsPrivateWithPassword) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  std::string error;
  ASSERT_TRUE(server->exec("postgres", "SELECT 1", error)) << error;
  ASSERT_TRUE(server->exec("postgres",
                           "DO $$ BEGIN IF current_setting('listen_addresses') <> '' THEN "
                           "RAISE EXCEPTION 'listens on %', current_setting('listen_addresses'); "
                           "END IF; END $$",
                           error))
      << error;
  ASSERT_TRUE(server->exec("postgres",
                           "DO $$ BEGIN IF current_setting('password_encryption') <> "
                           "'scram-sha-256' THEN RAISE EXCEPTION 'no scram'; END IF; END $$",
                           error))
      << error;
  EXPECT_TRUE(fs::exists(server->folder() / ".s.PGSQL.5432"));
  EXPECT_EQ(fs::status(server->folder()).permissions() & fs::perms::others_all, fs::perms::none);
}

// A second server starts beside the first, and once gone leaves no process and no folder.
TEST(Postgres, ServerStopsAndRemovesItsFolder) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  PostgresServer::Start status{};
  std::string reason;
  auto second = PostgresServer::start(status, reason);
  ASSERT_EQ(status, PostgresServer::Start::started) << reason;
  const fs::path folder = second->folder();
  std::string error;
  ASSERT_TRUE(second->create_database("scratch", error)) << error;
  ASSERT_TRUE(second->exec("scratch", "CREATE TABLE t (x INTEGER)", error)) << error;
  const fs::path pid_file = folder / "data" / "postmaster.pid";
  ASSERT_TRUE(fs::exists(pid_file));
  pid_t pid = 0;
  {
    std::ifstream in(pid_file);
    in >> pid;
  }
  ASSERT_GT(pid, 0);
  second.reset();
  EXPECT_FALSE(fs::exists(folder));
  EXPECT_NE(::kill(pid, 0), 0) << "the postmaster " << pid << " still runs";
  // The first server is untouched.
  EXPECT_TRUE(server->exec("postgres", "SELECT 1", error)) << error;
}

FlightRecord sample_flight(const std::string& trainee = "Ada",
                           std::int64_t started = 1'700'000'000'000) {
  FlightRecord f;
  f.trainee = trainee;
  f.station = "station-1";
  f.scenario = "mi_helix";
  f.scenario_hash = sha256_hex("scenario text");
  f.mode = "mixed_initiative";
  f.pilot = "novice";
  f.started_unix_ms = started;
  f.duration_s = 30.0;
  f.ended = history::Ended::completed;
  f.app_version = "mixpilot 0.1.0";
  f.front_end = "fly";
  f.metrics = {{"skill", 71.5}, {"mean_lambda", 0.8}, {"min_clearance_m", INFINITY}, {"lost", 0.0}};
  return f;
}

// A fresh database `name` on the run's server: its URL (with the password).
std::string fresh_database(const PostgresServer& server, const std::string& name) {
  std::string error;
  EXPECT_TRUE(server.create_database(name, error)) << error;
  return server.url(name);
}

// The store at `url`, through open_history as the commands open it.
std::unique_ptr<HistoryStore> open_store(const std::string& url) {
  std::string error;
  auto store = history::open_history(url, error);
  EXPECT_TRUE(store) << error;
  return store;
}

std::vector<StoredFlight> all(HistoryStore& store, const history::Query& q = {}) {
  std::vector<StoredFlight> out;
  std::string error;
  EXPECT_TRUE(store.query(q, out, error)) << error;
  return out;
}

// A statement's one answer, straight from the server (not through the store).
std::string sql(const PostgresServer& server, const std::string& db, const std::string& text) {
  std::string error;
  const auto v = server.scalar(db, text, error);
  EXPECT_TRUE(v) << text << ": " << error;
  return v.value_or("");
}

TEST(Postgres, AFlightComesBackWithEveryField) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "roundtrip");
  auto store = open_store(url);
  ASSERT_TRUE(store);
  FlightRecord f = sample_flight();
  f.input_device = "gamepad";
  f.input_settings_hash = sha256_hex("mode = 2");
  f.ended = history::Ended::lost;
  f.probe = true;
  f.duration_s = 0.1 + 0.2;  // every bit of a double comes back
  f.metrics.emplace_back("tiny", 4.9406564584124654e-324);
  f.metrics.emplace_back("negative", -1.0 / 3.0);
  f.metrics.emplace_back("nan", NAN);
  f.recording_path = "/tmp/a.mcap";
  f.recording_hash = sha256_hex("rec");
  std::string error;
  ASSERT_EQ(store->add(f, error), HistoryStore::Added::added) << error;
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  expect_same_flight(f, rows[0]);
  EXPECT_EQ(rows[0].ended, history::Ended::lost);
  EXPECT_TRUE(rows[0].probe);
  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names, std::vector<std::string>{"Ada"});
  // The database holds what the schema says; an unrecorded flight's hash is NULL.
  EXPECT_EQ(sql(*server, "roundtrip", "SELECT max(version) FROM schema_version"),
            std::to_string(history::kSchemaVersion));
  EXPECT_EQ(sql(*server, "roundtrip", "SELECT count(*) FROM metrics"), "7");
  EXPECT_EQ(sql(*server, "roundtrip", "SELECT count(*) FROM metrics WHERE value IS NULL"), "2");
  ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  EXPECT_EQ(sql(*server, "roundtrip",
                "SELECT count(*) FROM flights WHERE recording_hash IS NULL "
                "AND recording_path IS NULL"),
            "1");
  // Opened again: the schema is current, nothing is migrated twice.
  store.reset();
  store = open_store(url);
  ASSERT_TRUE(store);
  EXPECT_EQ(all(*store).size(), 2u);
  EXPECT_EQ(sql(*server, "roundtrip", "SELECT count(*) FROM schema_version"),
            std::to_string(history::kSchemaVersion));
}

// A database an older mixpilot made (schema 1: no metrics_by_name index, no branches' parent
// columns, no lesson tables, one schema_version row) is brought forward on open by the same
// migrations SQLite runs; its flights stay.
TEST(Postgres, AnOlderSchemaIsMigratedForward) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "migrate");
  auto store = open_store(url);
  ASSERT_TRUE(store);
  std::string error;
  ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  store.reset();
  ASSERT_TRUE(server->exec("migrate", "DROP TABLE lesson_attempts, lesson_progress", error))
      << error;
  ASSERT_TRUE(server->exec("migrate", "DROP INDEX metrics_by_name", error)) << error;
  ASSERT_TRUE(server->exec("migrate",
                           "ALTER TABLE flights DROP COLUMN ended_by, "
                           "DROP COLUMN parent_step, "
                           "DROP COLUMN parent_recording_hash",
                           error))
      << error;
  ASSERT_TRUE(server->exec("migrate", "DELETE FROM schema_version WHERE version > 1", error))
      << error;
  ASSERT_EQ(sql(*server, "migrate", "SELECT max(version) FROM schema_version"), "1");
  store = open_store(url);
  ASSERT_TRUE(store);
  EXPECT_EQ(sql(*server, "migrate", "SELECT max(version) FROM schema_version"),
            std::to_string(history::kSchemaVersion));
  EXPECT_EQ(sql(*server, "migrate",
                "SELECT count(*) FROM pg_indexes WHERE indexname = 'metrics_by_name'"),
            "1");
  EXPECT_EQ(sql(*server, "migrate",
                "SELECT count(*) FROM pg_indexes WHERE indexname = 'flights_by_parent'"),
            "1");
  const auto rows = all(*store);
  ASSERT_EQ(rows.size(), 1u);
  expect_same_flight(sample_flight(), rows[0]);
}

// Lessons (SPEC §10): the attempts and the progress as in SQLite (tests/history_test.hpp), and
// the lesson tables made by the migration from a database of schema 3.
TEST(Postgres, LessonAttemptsAndProgressAsInSqlite) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "lessons");
  auto store = open_store(url);
  ASSERT_TRUE(store);
  std::string error;
  ASSERT_EQ(store->add(sample_flight("Before"), error), HistoryStore::Added::added) << error;
  store.reset();
  ASSERT_TRUE(server->exec("lessons", "DROP TABLE lesson_attempts, lesson_progress", error))
      << error;
  ASSERT_TRUE(server->exec("lessons", "ALTER TABLE flights DROP COLUMN ended_by", error)) << error;
  ASSERT_TRUE(server->exec("lessons", "DELETE FROM schema_version WHERE version > 3", error))
      << error;
  store = open_store(url);
  ASSERT_TRUE(store);
  EXPECT_EQ(sql(*server, "lessons", "SELECT max(version) FROM schema_version"),
            std::to_string(history::kSchemaVersion));
  EXPECT_EQ(sql(*server, "lessons",
                "SELECT count(*) FROM pg_indexes WHERE indexname = 'lesson_attempts_by_lesson'"),
            "1");
  progress_round_trip(*store);
  EXPECT_EQ(sql(*server, "lessons", "SELECT count(*) FROM lesson_attempts"), "7");
  EXPECT_EQ(sql(*server, "lessons", "SELECT count(*) FROM flights"), "9");  // 7 + 1 plain + Before
}

// Fly from here (SPEC §10): a branch's parent link (the parent flight's recording hash and the
// step it was taken over at) read back as written, NULL for any other flight, as in SQLite.
TEST(Postgres, FlyFromHereBranchRowRoundTrips) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "branch");
  auto store = open_store(url);
  ASSERT_TRUE(store);
  FlightRecord parent = sample_flight();
  parent.recording_path = "/r/novice.mcap";
  parent.recording_hash = sha256_hex("the novice's recording");
  FlightRecord branch = sample_flight();
  branch.started_unix_ms += 100'000;
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
  expect_same_flight(parent, rows[0]);
  EXPECT_FALSE(rows[0].branch());
  expect_same_flight(branch, rows[1]);
  EXPECT_TRUE(rows[1].branch());
  EXPECT_EQ(sql(*server, "branch", "SELECT count(*) FROM flights WHERE parent_step IS NULL"), "1");
  EXPECT_EQ(sql(*server, "branch",
                "SELECT parent_step FROM flights WHERE parent_recording_hash = '" +
                    parent.recording_hash + "'"),
            "666");
}

// A recording is one flight: the same hash again is already known and adds nothing; flights
// without a recording are each their own.
TEST(Postgres, ARecordingIsAddedOnce) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  auto store = open_store(fresh_database(*server, "once"));
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
  // Already known even under another trainee's name: that trainee is not made.
  FlightRecord other = f;
  other.trainee = "Someone Else";
  EXPECT_EQ(store->add(other, error), HistoryStore::Added::already_known) << error;
  FlightRecord g = sample_flight();
  EXPECT_EQ(store->add(g, error), HistoryStore::Added::added) << error;
  EXPECT_EQ(store->add(g, error), HistoryStore::Added::added) << error;
  EXPECT_EQ(all(*store).size(), 3u);
  EXPECT_EQ(sql(*server, "once", "SELECT count(*) FROM metrics"), "12");
  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names, std::vector<std::string>{"Ada"});
  ASSERT_TRUE(store->knows_recording("", known, error)) << error;
  EXPECT_FALSE(known);
}

TEST(Postgres, FiltersAndTheNewestLimit) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  auto store = open_store(fresh_database(*server, "filters"));
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
  for (const auto& r : all(*store, q)) EXPECT_EQ(r.scenario, "mi_slalom");
  EXPECT_EQ(all(*store, q).size(), 3u);
  q.trainee = "Ada";  // i = 4
  ASSERT_EQ(all(*store, q).size(), 1u);
  EXPECT_EQ(all(*store, q)[0].started_unix_ms, 6000);
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
  ASSERT_EQ(newest[0].metrics.size(), 1u);
  EXPECT_EQ(newest[0].metrics[0].second, 1.0);
  q = {};
  q.trainee = "nobody";
  EXPECT_TRUE(all(*store, q).empty());
  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names, (std::vector<std::string>{"Ada", "Ben"}));
}

// Names are data, never SQL: quotes and a statement in a name are stored and read back as they
// are; 10 000 characters, invalid UTF-8, control characters and an empty name are refused with
// the reason (the same decisions as the SQLite backend: check_record), and nothing of them is
// written. Trainees come back in byte order, as from SQLite, whatever the server's collation.
TEST(Postgres, HostileTraineeNames) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  auto store = open_store(fresh_database(*server, "names"));
  ASSERT_TRUE(store);
  std::string error;
  const std::vector<std::string> stored = {"O'Brien",
                                           "\"quoted\"",
                                           "Robert'); DROP TABLE flights; --",
                                           "'; DROP TABLE trainees",
                                           "$1 $$ \\x00 E'\\\\'",
                                           "Zoë Ångström 飛行",
                                           "zed",
                                           "Zed",
                                           std::string(history::kMaxNameChars, 'x')};
  for (const std::string& name : stored)
    EXPECT_EQ(store->add(sample_flight(name), error), HistoryStore::Added::added)
        << name << ": " << error;
  const struct {
    std::string name;
    const char* reason;
  } refused[] = {
      {std::string(10'000, 'a'), "10000 characters long"},
      {std::string(history::kMaxNameChars + 1, 'x'), "201 characters long"},
      {"bad\xff"
       "byte",
       "not valid UTF-8"},
      {"over\xc0\xaflong", "not valid UTF-8"},
      {"cut\xe2\x82", "not valid UTF-8"},
      {"surrogate\xed\xa0\x80", "not valid UTF-8"},
      {std::string("nul\0byte", 8), "control character"},
      {"line\nbreak", "control character"},
      {"esc\x1b[31mred", "control character"},
      {"c1\xc2\x9b", "control character"},
      {"", "empty"},
  };
  for (const auto& r : refused) {
    error.clear();
    EXPECT_FALSE(store->add(sample_flight(r.name), error)) << r.reason;
    EXPECT_NE(error.find(r.reason), std::string::npos) << error;
    EXPECT_NE(error.find(store->where()), std::string::npos) << error;
  }
  // Invalid UTF-8 in another text field: refused the same way, before the server sees it.
  FlightRecord bad_scenario = sample_flight();
  bad_scenario.scenario = "helix\xff";
  EXPECT_FALSE(store->add(bad_scenario, error));
  EXPECT_NE(error.find("not valid UTF-8"), std::string::npos) << error;

  std::vector<std::string> names;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  std::vector<std::string> want = stored;
  std::sort(want.begin(), want.end());  // byte order
  EXPECT_EQ(names, want);
  for (const std::string& name : stored) {
    history::Query q;
    q.trainee = name;
    const auto rows = all(*store, q);
    ASSERT_EQ(rows.size(), 1u) << name;
    EXPECT_EQ(rows[0].trainee, name);
  }
  EXPECT_EQ(all(*store).size(), stored.size());  // the tables are all still there
  EXPECT_EQ(sql(*server, "names", "SELECT count(*) FROM trainees"), std::to_string(stored.size()));
}

// Eight processes open one new database and write 50 flights each at once: the migration runs
// once, 400 rows, none lost.
TEST(Postgres, EightProcessesWriteAtOnce) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "parallel");
  constexpr int kProcs = 8, kEach = 50;
  const int failed = test::failed_children(kProcs, [&](int k) {
    return test::write_flights(url, k, kEach, [](int k, int i) {
      // Two trainees shared by all writers: their rows are made at once too.
      FlightRecord f = sample_flight(k % 2 ? "Ben" : "Ada", i);
      f.station = "station " + std::to_string(k);
      f.recording_hash = sha256_hex(std::to_string(k) + "/" + std::to_string(i));
      return f;
    });
  });
  EXPECT_EQ(failed, 0) << "writers failed";
  auto store = open_store(url);
  ASSERT_TRUE(store);
  const auto rows = all(*store);
  EXPECT_EQ(rows.size(), std::size_t(kProcs * kEach));
  std::set<std::string> hashes;
  for (const auto& r : rows) hashes.insert(r.recording_hash);
  EXPECT_EQ(hashes.size(), std::size_t(kProcs * kEach));
  EXPECT_EQ(sql(*server, "parallel", "SELECT count(*) FROM metrics"),
            std::to_string(kProcs * kEach * 4));
  EXPECT_EQ(sql(*server, "parallel", "SELECT count(*) FROM schema_version"),
            std::to_string(history::kSchemaVersion));
  std::vector<std::string> names;
  std::string error;
  ASSERT_TRUE(store->trainees(names, error)) << error;
  EXPECT_EQ(names, (std::vector<std::string>{"Ada", "Ben"}));
}

// kill -9 of a writer inside a transaction: the server rolls the open transaction back, every
// flight the writer had committed is there with all its metrics, none is half written, and the
// next writer is not kept waiting by a lock the dead one held.
TEST(Postgres, AWriterKilledMidTransactionLosesNothingCommitted) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "killed");
  { ASSERT_TRUE(open_store(url)); }
  constexpr int kMetrics = 3000;  // a long transaction: the kill lands inside one
  const test::KilledWriter w = test::kill_a_writer_mid_transaction(
      [&] {
        std::string error;
        return history::open_history(url, error);
      },
      [](int i) { return sample_flight("killed", i); }, kMetrics, 5, std::chrono::milliseconds(20));
  ASSERT_TRUE(w.killed) << "the writer ended before the kill: " << w.status;
  const int last = w.last_reported;
  auto store = open_store(url);
  ASSERT_TRUE(store);
  std::string error;
  ASSERT_EQ(store->add(sample_flight("after", 1'000'000), error), HistoryStore::Added::added)
      << error;
  history::Query q;
  q.trainee = "killed";
  const auto rows = all(*store, q);
  ASSERT_GE(rows.size(), std::size_t(last + 1));
  EXPECT_LE(rows.size(), std::size_t(last + 2));  // at most the one committed unreported
  EXPECT_EQ(sql(*server, "killed",
                "SELECT count(*) FROM flights f WHERE (SELECT count(*) FROM metrics m "
                "WHERE m.flight_id = f.id) <> " + std::to_string(kMetrics) +
                    " AND f.trainee_id = (SELECT id FROM trainees WHERE name = 'killed')"),
            "0")
      << "a flight half written";
  EXPECT_EQ(sql(*server, "killed",
                "SELECT count(*) FROM metrics m WHERE NOT EXISTS "
                "(SELECT 1 FROM flights f WHERE f.id = m.flight_id)"),
            "0");
}

// One store shared by threads (a flight closing while a panel reads): every call is served,
// none is lost.
TEST(Postgres, ThreadsShareOneStore) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  auto store = open_store(fresh_database(*server, "threads"));
  ASSERT_TRUE(store);
  constexpr int kThreads = 4, kEach = 25;
  std::atomic<int> failures{0};
  std::vector<std::thread> pool;
  for (int t = 0; t < kThreads; ++t)
    pool.emplace_back([&, t] {
      for (int i = 0; i < kEach; ++i) {
        std::string error;
        FlightRecord f = sample_flight("thread " + std::to_string(t), i);
        f.recording_hash = sha256_hex(std::to_string(t) + ":" + std::to_string(i));
        if (store->add(f, error) != HistoryStore::Added::added) ++failures;
        std::vector<StoredFlight> rows;
        if (!store->query({}, rows, error)) ++failures;
        std::vector<std::string> names;
        if (!store->trainees(names, error)) ++failures;
      }
    });
  for (auto& t : pool) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(all(*store).size(), std::size_t(kThreads * kEach));
}

// A newer mixpilot's database is refused with the reason, naming the server without its
// password, and left as it was.
TEST(Postgres, ANewerSchemaIsRefusedAndLeftUntouched) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "newer");
  std::string error;
  {
    auto store = open_store(url);
    ASSERT_TRUE(store);
    ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  }
  ASSERT_TRUE(server->exec("newer", "INSERT INTO schema_version VALUES (99, 0)", error)) << error;
  EXPECT_FALSE(history::open_history(url, error));
  EXPECT_NE(error.find("newer mixpilot (schema version 99"), std::string::npos) << error;
  EXPECT_NE(error.find(history::redact_postgres_url(url)), std::string::npos) << error;
  EXPECT_EQ(error.find(server->password()), std::string::npos) << error;
  EXPECT_EQ(sql(*server, "newer", "SELECT count(*) FROM flights"), "1");
  EXPECT_EQ(sql(*server, "newer", "SELECT count(*) FROM schema_version"),
            std::to_string(history::kSchemaVersion + 1));
}

// A URL's credentials never reach a message or where(): the user:password@ part and password
// parameters are dropped, and whatever libpq or the server echo is scrubbed.
TEST(Postgres, CredentialsNeverInMessages) {
  EXPECT_EQ(history::redact_postgres_url("postgresql://ada:s3cret@db.centre:5433/flights"),
            "postgresql://db.centre:5433/flights");
  EXPECT_EQ(history::redact_postgres_url(
                "postgres://ada:p@ss:w@rd@host/db?sslmode=require&password=x&sslpassword=y"),
            "postgres://host/db?sslmode=require");
  EXPECT_EQ(history::redact_postgres_url("postgresql:///db?host=%2Ftmp&PassWord=zz&port=5"),
            "postgresql:///db?host=%2Ftmp&port=5");
  EXPECT_EQ(history::redact_postgres_url("host=h dbname=d password='a b' user=u"),
            "user='u' dbname='d' host='h'");

  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "secrets");
  std::string error;
  {
    auto store = open_store(url);
    ASSERT_TRUE(store);
    EXPECT_EQ(store->where().find(server->password()), std::string::npos) << store->where();
    EXPECT_EQ(store->where().find('@'), std::string::npos) << store->where();
  }
  const std::string wrong = "Wrong-Secret-" + std::to_string(::getpid());
  const std::vector<std::string> urls = {
      server->url_with_password("secrets", wrong),
      // The same wrong password as a parameter.
      "postgresql:///secrets?host=" + server->folder().string() + "&port=5432&user=mixpilot" +
          "&password=" + wrong,
  };
  for (const std::string& u : urls) {
    error.clear();
    EXPECT_FALSE(history::open_history(u, error)) << u;
    EXPECT_NE(error.find("password authentication failed"), std::string::npos) << error;
    EXPECT_NE(error.find("check the user name and password"), std::string::npos) << error;
    EXPECT_EQ(error.find(wrong), std::string::npos) << error;
    EXPECT_EQ(error.find(server->password()), std::string::npos) << error;
  }
  // A URL libpq cannot read, with the password in the part it quotes back.
  error.clear();
  EXPECT_FALSE(history::open_history("postgresql://mixpilot:" + wrong + "%zz@/secrets", error));
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find(wrong), std::string::npos) << error;
  error.clear();
  EXPECT_FALSE(
      history::open_history("postgresql:///secrets?password=" + wrong + "&bogus=1", error));
  EXPECT_FALSE(error.empty());
  EXPECT_EQ(error.find(wrong), std::string::npos) << error;
  // No server at the socket: said as such, the password nowhere.
  error.clear();
  EXPECT_FALSE(history::open_history(
      "postgresql://mixpilot:" + wrong + "@/secrets?host=%2Fnonexistent-mixpilot", error));
  EXPECT_NE(error.find("is the server running"), std::string::npos) << error;
  EXPECT_EQ(error.find(wrong), std::string::npos) << error;
}

// A server that accepts the connection and never answers holds the open for the connect
// timeout (5 s), not forever.
TEST(Postgres, ASilentServerTimesOut) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  ASSERT_EQ(::listen(fd, 8), 0);  // the kernel completes the handshake; nobody reads
  socklen_t len = sizeof a;
  ASSERT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len), 0);
  const std::string url = "postgresql://ada:Hush-" + std::to_string(::getpid()) +
                          "@127.0.0.1:" + std::to_string(ntohs(a.sin_port)) + "/db";
  const auto t0 = std::chrono::steady_clock::now();
  std::string error;
  EXPECT_FALSE(history::open_history(url, error));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ::close(fd);
  EXPECT_GE(s, 3.0) << error;
  EXPECT_LT(s, 12.0) << error;
  EXPECT_NE(error.find("timeout"), std::string::npos) << error;
  EXPECT_EQ(error.find("Hush-"), std::string::npos) << error;
}

// The server goes away under an open store: the next write fails at once with a clear
// message (the flight flies on), and nothing hangs.
TEST(Postgres, AServerThatGoesAwayIsSaidClearly) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  PostgresServer::Start status{};
  std::string reason;
  auto doomed = PostgresServer::start(status, reason);
  ASSERT_EQ(status, PostgresServer::Start::started) << reason;
  std::string error;
  ASSERT_TRUE(doomed->create_database("doomed", error)) << error;
  auto store = open_store(doomed->url("doomed"));
  ASSERT_TRUE(store);
  ASSERT_EQ(store->add(sample_flight(), error), HistoryStore::Added::added) << error;
  const std::string password = doomed->password();
  doomed.reset();
  const auto t0 = std::chrono::steady_clock::now();
  error.clear();
  EXPECT_FALSE(store->add(sample_flight(), error));
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 12.0);
  EXPECT_NE(error.find(store->where()), std::string::npos) << error;
  EXPECT_NE(error.find("server"), std::string::npos) << error;
  EXPECT_EQ(error.find(password), std::string::npos) << error;
  std::vector<StoredFlight> rows;
  EXPECT_FALSE(store->query({}, rows, error));
}

// The server restarts between two flights (a crash, an update): the store's next write
// connects again and the flight is kept; nothing was lost of the first.
TEST(Postgres, AServerRestartBetweenFlightsCostsNothing) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  PostgresServer::Start status{};
  std::string error;
  auto own = PostgresServer::start(status, error);
  ASSERT_EQ(status, PostgresServer::Start::started) << error;
  ASSERT_TRUE(own->create_database("restarted", error)) << error;
  auto store = open_store(own->url("restarted"));
  ASSERT_TRUE(store);
  ASSERT_EQ(store->add(sample_flight("Ada", 1), error), HistoryStore::Added::added) << error;
  ASSERT_TRUE(own->restart(error)) << error;
  EXPECT_EQ(store->add(sample_flight("Ada", 2), error), HistoryStore::Added::added) << error;
  ASSERT_TRUE(own->restart(error)) << error;
  std::vector<std::string> names;
  EXPECT_TRUE(store->trainees(names, error)) << error;
  ASSERT_TRUE(own->restart(error)) << error;
  EXPECT_EQ(all(*store).size(), 2u);
  ASSERT_TRUE(own->restart(error)) << error;
  bool known = true;
  EXPECT_TRUE(store->knows_recording("x", known, error)) << error;
  EXPECT_FALSE(known);
}

// A station's SQLite history pushed into the centre's database: every flight once, with its
// fields; pushing again adds nothing, recorded or not; a flight flown since is the one added
// by the next push; a second station's flights join the first's.
TEST(Postgres, PushTwiceAddsNothingTheSecondTime) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "centre");
  std::string error;
  const fs::path file = fresh_path("postgres", "station.sqlite");
  auto station = history::open_sqlite(file.string(), error);
  ASSERT_TRUE(station) << error;
  for (int i = 0; i < 6; ++i) {
    FlightRecord f = sample_flight(i % 2 ? "O'Brien" : "Ada", 1'700'000'000'000 + 1000 * i);
    if (i < 4) {  // two without a recording
      f.recording_path = "/rec/" + std::to_string(i) + ".mcap";
      f.recording_hash = sha256_hex("recording " + std::to_string(i));
    }
    f.metrics.emplace_back("attempt", double(i));
    ASSERT_EQ(station->add(f, error), HistoryStore::Added::added) << error;
  }
  auto centre = open_store(url);
  ASSERT_TRUE(centre);
  history::PushCounts counts;
  std::size_t progress_calls = 0;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error,
                                    [&](std::size_t, std::size_t) { ++progress_calls; }))
      << error;
  EXPECT_EQ(counts.flights, 6u);
  EXPECT_EQ(counts.added, 6u);
  EXPECT_EQ(counts.already_there, 0u);
  EXPECT_EQ(progress_calls, 6u);
  const auto mine = all(*station);
  auto pushed = all(*centre);
  ASSERT_EQ(pushed.size(), mine.size());
  for (std::size_t i = 0; i < mine.size(); ++i) {
    EXPECT_EQ(pushed[i].trainee, mine[i].trainee);
    EXPECT_EQ(pushed[i].station, mine[i].station);
    EXPECT_EQ(pushed[i].started_unix_ms, mine[i].started_unix_ms);
    EXPECT_EQ(pushed[i].recording_hash, mine[i].recording_hash);
    EXPECT_EQ(pushed[i].recording_path, mine[i].recording_path);
    EXPECT_EQ(pushed[i].duration_s, mine[i].duration_s);
    ASSERT_EQ(pushed[i].metrics.size(), mine[i].metrics.size());
    for (std::size_t m = 0; m < mine[i].metrics.size(); ++m) {
      EXPECT_EQ(pushed[i].metrics[m].first, mine[i].metrics[m].first);
      if (std::isfinite(mine[i].metrics[m].second))
        EXPECT_EQ(pushed[i].metrics[m].second, mine[i].metrics[m].second);
      else
        EXPECT_TRUE(std::isnan(pushed[i].metrics[m].second));
    }
  }

  // Again: nothing added, recorded or not.
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 0u);
  EXPECT_EQ(counts.already_there, 6u);
  EXPECT_EQ(sql(*server, "centre", "SELECT count(*) FROM flights"), "6");
  EXPECT_EQ(sql(*server, "centre", "SELECT count(*) FROM metrics"), std::to_string(6 * 5));

  // A flight flown since, without a recording, at the same moment as another trainee's.
  FlightRecord later = sample_flight("Ben", 1'700'000'000'000);
  ASSERT_EQ(station->add(later, error), HistoryStore::Added::added) << error;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 1u);
  EXPECT_EQ(counts.already_there, 6u);

  // Another station's flight at the same moment by the same trainee is another flight.
  const fs::path file2 = fresh_path("postgres", "station2.sqlite");
  auto station2 = history::open_sqlite(file2.string(), error);
  ASSERT_TRUE(station2) << error;
  FlightRecord elsewhere = sample_flight("Ada", 1'700'000'000'000);
  elsewhere.station = "station-2";
  ASSERT_EQ(station2->add(elsewhere, error), HistoryStore::Added::added) << error;
  ASSERT_TRUE(history::push_history(*station2, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 1u);
  ASSERT_TRUE(history::push_history(*station2, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 0u);
  EXPECT_EQ(sql(*server, "centre", "SELECT count(*) FROM flights"), "8");
}

// A station's whole history pushed into PostgreSQL: every table of the schema holds what the
// station's does, once, after two pushes (row counts on the server; the server's tables have
// the same columns as SQLite's), and pushing the centre back into a fresh SQLite file gives a
// history equal to the station's, row for row, ids aside. A history written into PostgreSQL
// directly comes out through a push with every column still set (what the backend reads).
TEST(Postgres, PushCarriesEveryTable) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  std::string error;
  const fs::path station_file = fresh_path("postgres", "every_table.sqlite");
  auto station = history::open_sqlite(station_file.string(), error);
  ASSERT_TRUE(station) << error;
  ASSERT_NO_FATAL_FAILURE(fill_every_column(*station));
  const HistoryDump mine = dump_history(station_file);
  expect_every_column_varies(mine);

  const std::string url = fresh_database(*server, "centre_every_table");
  auto centre = open_store(url);
  ASSERT_TRUE(centre);
  history::PushCounts counts;
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, mine.rows.at("flights").size());
  EXPECT_EQ(counts.attempts, mine.rows.at("lesson_attempts").size());
  EXPECT_EQ(counts.progress, mine.rows.at("lesson_progress").size());
  ASSERT_TRUE(history::push_history(*station, *centre, counts, error)) << error;
  EXPECT_EQ(counts.added, 0u);
  EXPECT_EQ(counts.attempts, 0u);
  EXPECT_EQ(counts.progress, 0u);
  for (const auto& [table, columns] : mine.schema) {
    std::string sqlite_columns;
    for (const std::string& c : columns) sqlite_columns += (sqlite_columns.empty() ? "" : ",") + c;
    EXPECT_EQ(sql(*server, "centre_every_table",
                  "SELECT string_agg(column_name, ',' ORDER BY ordinal_position) FROM "
                  "information_schema.columns WHERE table_schema = current_schema() AND "
                  "table_name = '" + table + "'"),
              sqlite_columns)
        << table;
    if (table == "schema_version") continue;
    EXPECT_EQ(sql(*server, "centre_every_table", "SELECT count(*) FROM " + table),
              std::to_string(mine.rows.at(table).size()))
        << table;
  }
  const fs::path back_file = fresh_path("postgres", "every_table_back.sqlite");
  {
    auto back = history::open_sqlite(back_file.string(), error);
    ASSERT_TRUE(back) << error;
    ASSERT_TRUE(history::push_history(*centre, *back, counts, error)) << error;
  }
  expect_same_history(dump_history(back_file), mine, "station -> PostgreSQL -> SQLite");

  const std::string direct_url = fresh_database(*server, "written_directly");
  auto direct = open_store(direct_url);
  ASSERT_TRUE(direct);
  ASSERT_NO_FATAL_FAILURE(fill_every_column(*direct));
  const fs::path out_file = fresh_path("postgres", "written_directly.sqlite");
  {
    auto out = history::open_sqlite(out_file.string(), error);
    ASSERT_TRUE(out) << error;
    ASSERT_TRUE(history::push_history(*direct, *out, counts, error)) << error;
  }
  const HistoryDump theirs = dump_history(out_file);
  expect_every_column_varies(theirs);
  for (const auto& [table, rows] : mine.rows) {
    if (table != "schema_version") {
      EXPECT_EQ(theirs.rows.at(table).size(), rows.size()) << table;
    }
  }
}

// `mixpilot history push` as a user runs it: twice, the second adds nothing; the password
// appears in no output, not even in a usage error that quotes the URL.
TEST(Postgres, PushCommandTwiceAddsNothingTheSecondTime) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  const std::string url = fresh_database(*server, "centre_cli");
  std::string error;
  const fs::path home = fresh_path("postgres", "cli_home");
  fs::create_directories(home);
  const fs::path file = home / "station.sqlite";
  {
    auto station = history::open_sqlite(file.string(), error);
    ASSERT_TRUE(station) << error;
    for (int i = 0; i < 3; ++i) {
      FlightRecord f = sample_flight("Ada", 1'700'000'000'000 + i);
      if (i == 0) f.recording_hash = sha256_hex("cli recording");
      ASSERT_EQ(station->add(f, error), HistoryStore::Added::added) << error;
    }
  }
  const std::string push = "history push '" + url + "' --history '" + file.string() + "'";
  ASSERT_EQ(run_mixpilot(MIXPILOT_BINARY, push, home), 0) << read_file(home / "out.txt");
  std::string out = read_file(home / "out.txt");
  EXPECT_NE(out.find("3 added, 0 already there"), std::string::npos) << out;
  EXPECT_EQ(out.find(server->password()), std::string::npos) << out;
  ASSERT_EQ(run_mixpilot(MIXPILOT_BINARY, push, home), 0) << read_file(home / "out.txt");
  out = read_file(home / "out.txt");
  EXPECT_NE(out.find("0 added, 3 already there"), std::string::npos) << out;
  EXPECT_EQ(sql(*server, "centre_cli", "SELECT count(*) FROM flights"), "3");

  // A wrong password, a URL given twice, no history: said, exit status 1 or 2, no password.
  const std::string wrong = server->url_with_password("centre_cli", "Not-The-Pw-42");
  EXPECT_EQ(run_mixpilot(MIXPILOT_BINARY,
                         "history push '" + wrong + "' --history '" + file.string() + "'", home),
            1);
  out = read_file(home / "out.txt");
  EXPECT_NE(out.find("password authentication failed"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not-The-Pw-42"), std::string::npos) << out;
  EXPECT_EQ(run_mixpilot(MIXPILOT_BINARY, "history push '" + url + "' '" + wrong + "'", home), 2);
  out = read_file(home / "out.txt");
  EXPECT_NE(out.find("unexpected"), std::string::npos) << out;
  EXPECT_EQ(out.find("Not-The-Pw-42"), std::string::npos) << out;
  EXPECT_EQ(run_mixpilot(MIXPILOT_BINARY, "history push 'https://user:Not-The-Pw-42@x/'", home), 2);
  out = read_file(home / "out.txt");
  EXPECT_EQ(out.find("Not-The-Pw-42"), std::string::npos) << out;
  EXPECT_EQ(
      run_mixpilot(MIXPILOT_BINARY,
                   "history push '" + url + "' --history '" + (home / "none.sqlite").string() + "'",
                   home),
      1);
  EXPECT_NE(read_file(home / "out.txt").find("nothing to push"), std::string::npos);
  EXPECT_FALSE(fs::exists(home / "none.sqlite"));
  EXPECT_EQ(run_mixpilot(MIXPILOT_BINARY, "history push --help", home), 0);
  EXPECT_NE(read_file(home / "out.txt").find("trainee, station"), std::string::npos);
}

// A push that cannot write says which flight stopped it and why, without the password.
TEST(Postgres, APushThatFailsSaysWhere) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  std::string error;
  PostgresServer::Start status{};
  auto doomed = PostgresServer::start(status, error);
  ASSERT_EQ(status, PostgresServer::Start::started) << error;
  ASSERT_TRUE(doomed->create_database("centre", error)) << error;
  auto centre = open_store(doomed->url("centre"));
  ASSERT_TRUE(centre);
  const fs::path file = fresh_path("postgres", "failing.sqlite");
  auto station = history::open_sqlite(file.string(), error);
  ASSERT_TRUE(station) << error;
  FlightRecord recorded = sample_flight();
  recorded.recording_hash = sha256_hex("a recording");
  ASSERT_EQ(station->add(recorded, error), HistoryStore::Added::added) << error;
  const std::string password = doomed->password();
  doomed.reset();
  history::PushCounts counts;
  EXPECT_FALSE(history::push_history(*station, *centre, counts, error));
  EXPECT_NE(error.find("flight 1 of 1"), std::string::npos) << error;
  EXPECT_NE(error.find("is the server running"), std::string::npos) << error;
  EXPECT_NE(error.find(centre->where()), std::string::npos) << error;
  EXPECT_EQ(error.find(password), std::string::npos) << error;
  EXPECT_EQ(counts.added, 0u);
}

}  // namespace
}  // namespace mixpilot::test
