#pragma once
// Every table of an SQLite history as it stands, for push's tests: the schema is read from the
// file itself (sqlite_master, table_info, foreign_key_list), so a table or column a later
// migration adds is compared without this file knowing it. A surrogate key (`id`) is left out
// and a reference to another row is replaced by what that row stands for (a trainee by name, a
// flight by its recording hash or trainee/station/start), so two stores that hold the same
// history compare equal whatever ids they gave it. And a history that sets every column of
// every table to at least two values (fill_every_column), so a push that forgets one shows.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"

namespace mixpilot::test {

struct HistoryDump {
  // table → column names (as compared: no `id`; schema_version without its applied time).
  std::map<std::string, std::vector<std::string>> columns;
  // table → its rows, each "column=value|..." with typed values (i:, f: in hex, t:, NULL).
  std::map<std::string, std::multiset<std::string>> rows;
  // table → every column, in order (ids and times included).
  std::map<std::string, std::vector<std::string>> schema;
};

namespace detail {

inline std::vector<std::vector<std::string>> sqlite_rows(sqlite3* db, const std::string& sql) {
  std::vector<std::vector<std::string>> out;
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << sql << ": " << sqlite3_errmsg(db);
    return out;
  }
  while (sqlite3_step(s) == SQLITE_ROW) {
    std::vector<std::string> row;
    for (int i = 0; i < sqlite3_column_count(s); ++i) {
      char buf[64];
      switch (sqlite3_column_type(s, i)) {
        case SQLITE_NULL: row.emplace_back("NULL"); break;
        case SQLITE_INTEGER:
          std::snprintf(buf, sizeof buf, "i:%" PRId64, std::int64_t(sqlite3_column_int64(s, i)));
          row.emplace_back(buf);
          break;
        case SQLITE_FLOAT:
          std::snprintf(buf, sizeof buf, "f:%a", sqlite3_column_double(s, i));  // exact
          row.emplace_back(buf);
          break;
        default:
          row.push_back("t:" + std::string(reinterpret_cast<const char*>(sqlite3_column_text(s, i)),
                                           std::size_t(sqlite3_column_bytes(s, i))));
      }
    }
    out.push_back(std::move(row));
  }
  sqlite3_finalize(s);
  return out;
}

inline std::string unquoted(const std::string& typed) {
  return typed.size() > 2 && typed[1] == ':' ? typed.substr(2) : typed;
}

}  // namespace detail

inline HistoryDump dump_history(const std::filesystem::path& file) {
  HistoryDump d;
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    ADD_FAILURE() << file << ": cannot open";
    sqlite3_close(db);
    return d;
  }
  // What a row of a referenced table stands for, whatever its id.
  const std::map<std::string, std::string> natural = {
      {"trainees", "(SELECT name FROM trainees WHERE id = %s)"},
      {"flights",
       "(SELECT coalesce(x.recording_hash, (SELECT name FROM trainees WHERE id = x.trainee_id) "
       "|| '/' || x.station || '/' || x.started_unix_ms) FROM flights x WHERE x.id = %s)"}};
  for (const auto& t : detail::sqlite_rows(
           db, "SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%' "
               "ORDER BY name")) {
    const std::string table = detail::unquoted(t[0]);
    std::map<std::string, std::string> refers;  // column → referenced table
    for (const auto& fk : detail::sqlite_rows(db, "PRAGMA foreign_key_list(" + table + ")"))
      refers[detail::unquoted(fk[3])] = detail::unquoted(fk[2]);
    std::string select;
    for (const auto& c : detail::sqlite_rows(db, "PRAGMA table_info(" + table + ")")) {
      const std::string col = detail::unquoted(c[1]);
      d.schema[table].push_back(col);
      if (col == "id" && c[5] != "i:0") continue;  // a surrogate key
      if (table == "schema_version" && col == "applied_unix_ms") continue;  // when, not what
      std::string expr = table + "." + col;
      if (const auto r = refers.find(col); r != refers.end()) {
        const auto n = natural.find(r->second);
        if (n == natural.end()) {
          ADD_FAILURE() << table << "." << col << " refers to " << r->second
                        << ": tell dump_history what a row of it stands for";
          continue;
        }
        char buf[512];
        std::snprintf(buf, sizeof buf, n->second.c_str(), expr.c_str());
        expr = buf;
      }
      select += (select.empty() ? "SELECT " : ", ") + expr;
      d.columns[table].push_back(col);
    }
    for (const auto& row : detail::sqlite_rows(db, select + " FROM " + table)) {
      std::string text;
      for (std::size_t i = 0; i < row.size(); ++i)
        text += (i ? "|" : "") + d.columns[table][i] + "=" + row[i];
      d.rows[table].insert(text);
    }
    d.rows[table];  // an empty table is a table too
  }
  sqlite3_close(db);
  return d;
}

// Each column of each table (schema_version aside) takes at least two values, NULL counting
// as one: a fixture that leaves one at a single value would let a push that drops it pass.
inline void expect_every_column_varies(const HistoryDump& d) {
  for (const auto& [table, cols] : d.columns) {
    if (table == "schema_version") continue;
    for (std::size_t i = 0; i < cols.size(); ++i) {
      std::set<std::string> values;
      for (const std::string& row : d.rows.at(table)) {
        // The i-th "col=value" field (values hold no '|' in the fixture).
        std::size_t at = 0;
        for (std::size_t k = 0; k < i; ++k) at = row.find('|', at) + 1;
        values.insert(row.substr(at, row.find('|', at) - at));
      }
      EXPECT_GE(values.size(), 2u)
          << table << "." << cols[i]
          << " takes one value in the fixture: give it another in fill_every_column()";
    }
  }
}

// `a`'s rows ⊎ `b`'s rows, table by table (schema_version: `a`'s).
inline HistoryDump union_of(const HistoryDump& a, const HistoryDump& b) {
  HistoryDump u = a;
  for (const auto& [table, rows] : b.rows)
    if (table != "schema_version") u.rows[table].insert(rows.begin(), rows.end());
  return u;
}

inline void expect_same_history(const HistoryDump& got, const HistoryDump& want,
                                 const std::string& what) {
  EXPECT_EQ(got.columns, want.columns) << what << ": the schemas differ";
  for (const auto& [table, rows] : want.rows) {
    const auto it = got.rows.find(table);
    if (it == got.rows.end()) {
      ADD_FAILURE() << what << ": no table " << table;
      continue;
    }
    std::vector<std::string> missing, extra;
    std::set_difference(rows.begin(), rows.end(), it->second.begin(), it->second.end(),
                        std::back_inserter(missing));
    std::set_difference(it->second.begin(), it->second.end(), rows.begin(), rows.end(),
                        std::back_inserter(extra));
    EXPECT_TRUE(missing.empty() && extra.empty())
        << what << ": table " << table << ": " << missing.size() << " rows missing (first: "
        << (missing.empty() ? "" : missing[0]) << "), " << extra.size()
        << " rows too many (first: " << (extra.empty() ? "" : extra[0]) << ")";
  }
}

// A history that gives every column of every table at least two values, through the store's
// own calls (so either backend can hold it): trainees Ada, Ben and Grace; flights recorded and
// not, from two stations, of two modes, completed, interrupted, lost and ended by the
// instructor, a probe, a branch, with a gamepad's settings, score fields finite and not;
// attempts at two lessons passed and failed; progress rows at step 0 after a reset, with a
// failed attempt, and completed. Attempts wait a few milliseconds apart so each progress row's
// update time is its own.
inline void fill_every_column(history::HistoryStore& store) {
  using history::Ended;
  using history::FlightRecord;
  using Added = history::HistoryStore::Added;
  std::string error;
  std::int64_t clock = 1'700'000'000'000;
  const auto flight = [&](const std::string& trainee, const std::string& rec) {
    FlightRecord f;
    f.trainee = trainee;
    f.station = "station-1";
    f.scenario = "mi_helix";
    f.scenario_hash = sha256_hex("mi_helix text");
    f.mode = "mixed_initiative";
    f.pilot = "novice";
    f.started_unix_ms = (clock += 60'000);
    f.duration_s = 30.0 + double(clock % 7) / 8.0;
    f.app_version = "mixpilot 0.1.0";
    f.front_end = "fly";
    if (!rec.empty()) {
      f.recording_path = "/recordings/" + rec + ".mcap";
      f.recording_hash = sha256_hex(rec);
    }
    f.metrics = {{"skill", 40.0 + double(clock % 50)}, {"mean_lambda", 0.8},
                 {"min_clearance_m", INFINITY}};
    return f;
  };
  const auto attempt = [](const std::string& lesson, int steps, int step, bool passed) {
    history::LessonAttempt a;
    a.lesson = lesson;
    a.lesson_hash = sha256_hex(lesson + " file");
    a.steps = steps;
    a.step = step;
    a.step_title = lesson + " step " + std::to_string(step + 1);
    a.ceiling = 0.3 + 0.2 * step;
    a.passed = passed;
    a.failed_criterion = passed ? "" : "min_skill";
    a.detail = passed ? "skill 80.0 (at least 60)" : "skill 41.0 (at least 60)";
    return a;
  };
  const auto add = [&](const FlightRecord& f) {
    ASSERT_EQ(store.add(f, error), Added::added) << error;
  };
  const auto add_attempt = [&](const FlightRecord& f, const history::LessonAttempt& a) {
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    ASSERT_EQ(store.add_attempt(f, a, error), Added::added) << error;
  };
  FlightRecord parent = flight("Ada", "ada-1");
  add(parent);
  FlightRecord f = flight("Ada", "");
  f.station = "station-2";
  f.ended = Ended::interrupted;
  add(f);
  f = flight("Ada", "ada-probe");
  f.probe = true;
  f.pilot = "gamepad";
  f.input_device = "gamepad";
  f.input_settings_hash = sha256_hex("input.toml");
  f.front_end = "window";
  add(f);
  f = flight("Ada", "ada-branch");
  f.parent_recording_hash = parent.recording_hash;
  f.parent_step = 600;
  add(f);
  f = flight("Ben", "ben-instructor");
  f.ended = Ended::instructor;
  f.app_version = "mixpilot 0.0.9";
  add(f);
  f = flight("Ben", "");
  f.scenario = "pendubot_swingup";
  f.scenario_hash = sha256_hex("pendubot text");
  f.mode = "pendubot_swingup";
  f.pilot = "";
  f.ended = Ended::lost;
  f.metrics = {{"swing_up_time_s", 2.5}, {"settled", NAN}};
  add(f);
  // Lessons: Ada fails then passes step 1 of "beginner" and fails step 2, then starts over;
  // Ben fails step 1 (one failed attempt); Grace completes "advanced" (2 steps), unrecorded.
  add_attempt(flight("Ada", "ada-l1"), attempt("beginner", 3, 0, false));
  add_attempt(flight("Ada", ""), attempt("beginner", 3, 0, true));
  add_attempt(flight("Ada", "ada-l3"), attempt("beginner", 3, 1, false));
  std::this_thread::sleep_for(std::chrono::milliseconds(3));
  ASSERT_TRUE(store.reset_lesson("Ada", "beginner", sha256_hex("beginner file"), error)) << error;
  add_attempt(flight("Ben", "ben-l1"), attempt("beginner", 3, 0, false));
  add_attempt(flight("Grace", ""), attempt("advanced", 2, 0, true));
  add_attempt(flight("Grace", "grace-l2"), attempt("advanced", 2, 1, true));
}

}  // namespace mixpilot::test
