// The trainee's history at scale (SPEC §10): `mixpilot history` listing 100 000 flights as a
// table (to /dev/null), from a temporary SQLite history filled once in one transaction.
#include <benchmark/benchmark.h>
#include <sqlite3.h>
#include <unistd.h>
#include <fcntl.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "core/history/history.hpp"
#include "core/history/sqlite_history.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

// The score fields of a mixed-initiative flight's report: each flight holds as many metrics.
const char* const kMetrics[] = {
    "duration_s", "progress", "time_in_ball", "max_deviation_m", "rms_deviation_m",
    "mean_lambda", "min_lambda", "collisions", "min_clearance_m", "override_rms",
    "stick_smoothness", "rti_median_us", "rti_p99_us", "deadline_misses", "fallbacks", "skill",
    "input_lost_s", "safe_hold_s", "lost", "assistance_dependence"};

// A history of `flights` rows (20 trainees, 5 scenarios, 20 metrics each); its path.
std::string filled_history(int flights) {
  const fs::path dir = fs::temp_directory_path() / ("mixpilot-bench-history-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const fs::path p = dir / "history.sqlite";
  fs::remove(p);
  std::string error;
  if (!history::open_sqlite(p.string(), error)) return "";  // the schema
  sqlite3* db = nullptr;
  sqlite3_open(p.c_str(), &db);
  sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
  for (int t = 0; t < 20; ++t) {
    const std::string sql = "INSERT INTO trainees (name) VALUES ('trainee " + std::to_string(t) + "')";
    sqlite3_exec(db, sql.c_str(), nullptr, nullptr, nullptr);
  }
  sqlite3_stmt* f = nullptr;
  sqlite3_stmt* m = nullptr;
  sqlite3_prepare_v2(db,
                     "INSERT INTO flights (trainee_id, station, scenario, scenario_hash, mode, "
                     "pilot, input_device, input_settings_hash, started_unix_ms, duration_s, "
                     "ended, probe, recording_path, recording_hash, app_version, front_end) "
                     "VALUES (?, 'station-1', ?, 'abc', 'mixed_initiative', 'novice', '', '', ?, "
                     "30.0, 'completed', ?, ?, ?, 'mixpilot 0.1.0', 'window')",
                     -1, &f, nullptr);
  sqlite3_prepare_v2(db, "INSERT INTO metrics (flight_id, position, name, value) VALUES (?, ?, ?, ?)",
                     -1, &m, nullptr);
  const char* const scenarios[] = {"mi_helix", "mi_figure8", "obstacles", "tracking", "pendubot"};
  for (int i = 0; i < flights; ++i) {
    sqlite3_reset(f);
    sqlite3_bind_int64(f, 1, 1 + i % 20);
    sqlite3_bind_text(f, 2, scenarios[i % 5], -1, SQLITE_STATIC);
    sqlite3_bind_int64(f, 3, 1'700'000'000'000 + std::int64_t(i) * 60'000);
    sqlite3_bind_int(f, 4, i % 7 == 0);
    const std::string path = "/home/ada/.local/share/mixpilot/recordings/flight-" + std::to_string(i) + ".mcap";
    const std::string hash = std::to_string(i);
    sqlite3_bind_text(f, 5, path.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(f, 6, hash.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(f);
    const std::int64_t id = sqlite3_last_insert_rowid(db);
    for (int k = 0; k < 20; ++k) {
      sqlite3_reset(m);
      sqlite3_bind_int64(m, 1, id);
      sqlite3_bind_int(m, 2, k);
      sqlite3_bind_text(m, 3, kMetrics[k], -1, SQLITE_STATIC);
      sqlite3_bind_double(m, 4, 0.5 * k + i % 100);
      sqlite3_step(m);
    }
  }
  sqlite3_finalize(f);
  sqlite3_finalize(m);
  sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  return p.string();
}

// The filled history's folder, removed when the benchmarks end.
struct TempHistory {
  std::string path = filled_history(100'000);
  ~TempHistory() {
    std::error_code ec;
    if (!path.empty()) fs::remove_all(fs::path(path).parent_path(), ec);
  }
};

void BM_HistoryListing(benchmark::State& state) {
  static const TempHistory filled;
  const std::string& db = filled.path;
  if (db.empty()) {
    state.SkipWithError("cannot fill the history");
    return;
  }
  // stdout to /dev/null for the listing (the benchmark's report goes to it afterwards).
  std::fflush(stdout);
  const int saved = ::dup(1);
  const int null = ::open("/dev/null", O_WRONLY);
  std::string a0 = "mixpilot", a1 = "history", a2 = "--history", a3 = db;
  std::vector<char*> argv = {a0.data(), a1.data(), a2.data(), a3.data(), nullptr};
  int status = 0;
  for (auto _ : state) {
    ::dup2(null, 1);
    status |= cli::history_command(4, argv.data());
    std::fflush(stdout);
    ::dup2(saved, 1);
  }
  ::close(null);
  ::close(saved);
  if (status != 0) state.SkipWithError("history failed");
  state.counters["flights"] = 100'000;
}

BENCHMARK(BM_HistoryListing)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(5);

}  // namespace
}  // namespace mixpilot
