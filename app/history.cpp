// mixpilot history: the trainee's flights (SPEC §10) as a table, CSV or JSON; `history import`
// adds recordings that are not in it yet; `history push` copies them into a centre's database.
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight_rig.hpp"
#include "app/progress.hpp"
#include "app/progress_html.hpp"
#include "core/base/json.hpp"
#include "core/base/output_file.hpp"
#include "core/base/input_file.hpp"
#include "core/base/content_hash.hpp"
#include "core/history/history.hpp"
#include "core/history/postgres_history.hpp"
#include "core/history/push.hpp"
#include "core/recording/replay.hpp"
#include "core/scenario/lesson.hpp"

namespace mixpilot::cli {

namespace {

namespace fs = std::filesystem;

constexpr const char* kHistoryUsage =
    "usage: mixpilot history [--trainee NAME] [--scenario NAME] [--since DATE] [--limit N]\n"
    "                        [--csv | --json] [--history LOCATION]\n"
    "       mixpilot history --trainee NAME --html OUT.html [--force] [--scenario NAME] ...\n"
    "       mixpilot history import DIR [--jobs N] [--trainee NAME] [--lesson FILE]...\n"
    "                               [--history LOCATION]\n"
    "       mixpilot history push postgresql://[USER@]HOST[:PORT]/DATABASE [--history LOCATION]\n"
    "\n"
    "The flights mixpilot remembers (SPEC §10): every flight of the window and of `fly`, one\n"
    "row each (a replay or `score` adds none). Oldest first, so the newest is next to the\n"
    "prompt. A table on the terminal, or every field with --csv or --json. A branch (fly from\n"
    "here: flown on from a moment of a recorded flight) names that flight by its recording's\n"
    "hash and the step it was taken over at (parent_recording_hash, parent_step; ^ in the\n"
    "table). A lesson step's attempt (mixpilot lesson, the window's lesson picker) names the\n"
    "lesson, the step (1-based) and its verdict (lesson, lesson_step, lesson_passed,\n"
    "lesson_failed: the criterion that failed; the table's lesson column), and the table ends\n"
    "with where each trainee is in each lesson.\n"
    "\n"
    "  --trainee NAME     only this trainee's flights\n"
    "  --scenario NAME    only this scenario's flights (its name, as in the table)\n"
    "  --since DATE       only flights started at or after DATE, local time: YYYY-MM-DD,\n"
    "                     YYYY-MM-DDTHH:MM or YYYY-MM-DDTHH:MM:SS (a space for the T too)\n"
    "  --limit N          only the newest N flights\n"
    "  --csv              comma-separated values, a header line and one line per flight, every\n"
    "                     score field in a column of its own (metrics.NAME)\n"
    "  --json             a JSON array, one object per flight, its score fields in \"metrics\"\n"    "  --html OUT.html    the trainee's progress report to take home: one self-contained file\n"
    "                     (curves of skill per attempt, assisted and probe flights, and D per\n"
    "                     scenario; the best run, the trend, every flight), no network needed,\n"
    "                     printable. Needs --trainee. Never replaces a file without --force\n"
    "  --force            --html may replace OUT.html\n"
    "  --history LOCATION the history: an SQLite file (PATH or sqlite:PATH; default\n"
    "                     $XDG_DATA_HOME/mixpilot/history.sqlite) or postgresql://...\n"
    "\n"
    "history import DIR: flies each recording (*.mcap) under DIR again and checks it, as score\n"
    "does, and adds those the history does not know yet (by the SHA-256 of the file: importing\n"
    "twice adds nothing). The trainee is the recording's; --trainee names one for recordings\n"
    "without (default: the login name). The start time is the file's modification time minus\n"
    "the flight's duration. Progress on stderr; a file that cannot be read or replayed is named\n"
    "with the reason, and the others are still imported. A lesson step's recording (its\n"
    "metadata names the lesson, its SHA-256 and the step) is imported with its verdict, judged\n"
    "again against that lesson: a shipped one or a --lesson FILE whose SHA-256 is the\n"
    "recording's (else the flight alone is imported, and said). Where each trainee is in a\n"
    "lesson is left as it is (mixpilot lesson --status says it; --reset starts over).\n"
    "  --jobs N           replay N recordings in parallel (default: the number of cores)\n"
    "  --lesson FILE      a lesson file to judge lesson steps' recordings against, besides the\n"
    "                     shipped lessons (repeatable)\n"
    "\n"
    "history push URL: copies this station's history (--history, default the SQLite file above)\n"
    "into a training centre's PostgreSQL database: every flight once, with its score fields and,\n"
    "for a lesson step's attempt, its verdict: a recorded flight is matched by its recording's\n"
    "SHA-256, a flight without a recording by its trainee, station and start time (to the\n"
    "millisecond); then where each trainee is in each lesson, the row updated last winning.\n"
    "Pushing again adds only what changed since (a flight already there gains its lesson\n"
    "verdict if an older mixpilot pushed it without).\n"
    "The URL is libpq's (options such as ?sslmode=require after it); keep the password out of\n"
    "it, where other users' `ps` would see it: PGPASSWORD or ~/.pgpass. No message repeats a\n"
    "password. The connection gives up after 5 s unless the URL sets connect_timeout.\n"
    "\n"
    "exit status: 0 done, 1 the history cannot be read or written, or (import) a recording\n"
    "could not be imported, or (push) a flight could not be copied, 2 usage\n";

// --since's text as unix milliseconds (local time); nullopt when it is not one of the forms.
std::optional<std::int64_t> parse_since(const std::string& text) {
  std::tm tm{};
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  char sep = 0, end = 0;
  int n = std::sscanf(text.c_str(), "%4d-%2d-%2d%c%2d:%2d:%2d%c", &y, &mo, &d, &sep, &h, &mi, &s,
                      &end);
  const bool date_only = n == 3 && text.size() == 10;
  const bool minutes = n == 6 && text.size() == 16;
  const bool seconds = n == 7 && text.size() == 19;
  if (!date_only && !minutes && !seconds) return std::nullopt;
  if (!date_only && sep != 'T' && sep != ' ') return std::nullopt;
  if (mo < 1 || mo > 12 || d < 1 || d > 31 || h > 23 || mi > 59 || s > 60 || y < 1970)
    return std::nullopt;
  tm.tm_year = y - 1900;
  tm.tm_mon = mo - 1;
  tm.tm_mday = d;
  tm.tm_hour = h;
  tm.tm_min = mi;
  tm.tm_sec = s;
  tm.tm_isdst = -1;
  const std::time_t t = std::mktime(&tm);
  if (t == std::time_t(-1) || tm.tm_mday != d) return std::nullopt;  // 2024-02-31
  return std::int64_t(t) * 1000;
}

std::string local_time(std::int64_t unix_ms, const char* format) {
  const std::time_t t = std::time_t(unix_ms / 1000);
  std::tm tm{};
  localtime_r(&t, &tm);
  char text[64];
  return std::strftime(text, sizeof text, format, &tm) ? text : "";
}

// The table's "YYYY-MM-DD HH:MM" of a flight, the local time zone looked up once per quarter
// hour (every zone's offset changes on a quarter hour): a long listing spends no time there.
std::string table_minutes(std::int64_t unix_ms) {
  static std::int64_t block = -1;
  static std::tm start{};
  const std::int64_t s = unix_ms >= 0 ? unix_ms / 1000 : (unix_ms - 999) / 1000;
  const std::int64_t b = s >= 0 ? s / 900 : (s - 899) / 900;
  if (b != block) {
    block = b;
    const std::time_t t = std::time_t(b * 900);
    localtime_r(&t, &start);
  }
  const int minutes = start.tm_min + int((s - b * 900) / 60);
  char text[64];  // room for any int the compiler can imagine in each field
  std::snprintf(text, sizeof text, "%04d-%02d-%02d %02d:%02d", start.tm_year + 1900,
                start.tm_mon + 1, start.tm_mday, start.tm_hour, minutes);
  return text;
}

// `text` in a terminal column of `width` characters: control characters escaped, cut with an
// ellipsis when longer, padded with spaces (UTF-8 code points counted as one column each).
std::string cell(std::string_view raw, std::size_t width, bool right = false) {
  // Printable ASCII that fits, the common case: padded as it is.
  if (raw.size() <= width &&
      std::all_of(raw.begin(), raw.end(), [](char c) { return c >= 0x20 && c < 0x7F; })) {
    std::string out(width, ' ');
    raw.copy(out.data() + (right ? width - raw.size() : 0), raw.size());
    return out;
  }
  const std::string text = escape_controls(raw);
  std::string out;
  std::size_t cols = 0, i = 0;
  const auto next = [&](std::size_t at) {
    std::size_t len = 1;
    while (at + len < text.size() && (static_cast<unsigned char>(text[at + len]) & 0xC0) == 0x80)
      ++len;
    return len;
  };
  std::size_t total = 0;
  for (std::size_t k = 0; k < text.size(); k += next(k)) ++total;
  while (i < text.size() && cols < width) {
    if (total > width && cols + 1 == width) {
      out += "\u2026";
      ++cols;
      break;
    }
    const std::size_t len = next(i);
    out.append(text, i, len);
    i += len;
    ++cols;
  }
  const std::string pad(width - cols, ' ');
  return right ? pad + out : out + pad;
}

std::string number(double v, const char* format = "%.17g") {
  if (!std::isfinite(v)) return "";
  char text[40];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

// A path for the terminal: as it is when it is printable ASCII (the common case), else with
// its control characters escaped.
std::string printable_path(const std::string& p) {
  return std::all_of(p.begin(), p.end(), [](char c) { return c >= 0x20 && c < 0x7F; })
             ? p
             : escape_controls(p);
}

void print_table(const std::vector<history::StoredFlight>& rows) {
  // Each row's cells appended to one line buffer (its capacity kept): a long history prints
  // without a string per cell.
  std::string line;
  const auto add = [&line](std::string_view text, std::size_t width, bool right = false) {
    if (text.size() <= width &&
        std::all_of(text.begin(), text.end(), [](char c) { return c >= 0x20 && c < 0x7F; })) {
      if (right) line.append(width - text.size(), ' ');
      line.append(text);
      if (!right) line.append(width - text.size(), ' ');
    } else {
      line += cell(text, width, right);
    }
    line += ' ';
  };
  add("id", 6, true);
  add("started", 16);
  add("trainee", 16);
  add("scenario", 18);
  add("pilot", 12);
  add("time_s", 7, true);
  add("ended", 13);  // "interrupted*^"
  add("skill", 6, true);
  add("from", 7);
  const bool lessons =
      std::any_of(rows.begin(), rows.end(), [](const auto& f) { return f.lesson_step >= 0; });
  if (lessons) add("lesson", 16);
  line += "recording\n";
  std::fputs(line.c_str(), stdout);
  char number_text[32];
  for (const history::StoredFlight& f : rows) {
    line.clear();
    std::snprintf(number_text, sizeof number_text, "%lld", static_cast<long long>(f.id));
    add(number_text, 6, true);
    add(table_minutes(f.started_unix_ms), 16);
    add(f.trainee, 16);
    add(f.scenario, 18);
    add(f.pilot.empty() ? "-" : f.pilot, 12);
    add(number(f.duration_s, "%.1f"), 7, true);
    std::string_view ended = history::to_string(f.ended);
    std::snprintf(number_text, sizeof number_text, "%.*s%s%s", int(ended.size()), ended.data(),
                  f.probe ? "*" : "", f.branch() ? "^" : "");
    add(number_text, 13);
    const auto skill = metric_of(f, "skill");
    add(skill ? number(*skill, "%.1f") : "-", 6, true);
    add(f.front_end, 7);
    if (lessons) {
      // "beginner 2 ✓": the lesson, the step (1-based) and its verdict.
      if (f.lesson_step < 0) {
        add("-", 16);
      } else {
        const std::string tail = " " + std::to_string(f.lesson_step + 1) +
                                 (f.lesson_passed ? " \u2713" : " \u2717");
        const std::string name = cell(f.lesson, tail.size() > 14 ? 1 : 16 - (tail.size() - 2));
        std::string trimmed = name;
        while (!trimmed.empty() && trimmed.back() == ' ') trimmed.pop_back();
        add(trimmed + tail, 16);
      }
    }
    line += f.recording_path.empty() ? "-" : printable_path(f.recording_path);
    line += '\n';
    std::fputs(line.c_str(), stdout);
  }
  const bool probes = std::any_of(rows.begin(), rows.end(), [](const auto& f) { return f.probe; });
  const bool branches =
      std::any_of(rows.begin(), rows.end(), [](const auto& f) { return f.branch(); });
  std::string notes;
  if (probes) notes = "* a probe flight: unassisted";
  if (branches)
    notes += std::string(notes.empty() ? "" : "; ") +
             "^ a branch: flown on from a moment of another flight";
  if (lessons)
    notes += std::string(notes.empty() ? "" : "; ") +
             "lesson: the lesson and step the flight was an attempt at, \u2713 passed, \u2717 not";
  std::printf("%zu flight%s%s\n", rows.size(), rows.size() == 1 ? "" : "s",
              notes.empty() ? "" : (" (" + notes + ")").c_str());
}

// Where each trainee is in each lesson they attempted (the table's footer).
void print_lesson_progress(const std::vector<history::LessonProgress>& progress) {
  if (progress.empty()) return;
  std::printf("lessons:\n");
  for (const history::LessonProgress& p : progress) {
    std::string where;
    if (p.completed()) {
      where = "every step passed (" + std::to_string(p.steps) + ")";
    } else {
      where = "on step " + std::to_string(p.step + 1) + " of " + std::to_string(p.steps);
      if (p.failed_attempts > 0)
        where += ", " + std::to_string(p.failed_attempts) + " failed attempt" +
                 (p.failed_attempts == 1 ? "" : "s") + " at it";
    }
    std::printf("  %s  %s (%.12s)  %s\n", escape_controls(p.trainee).c_str(),
                escape_controls(p.lesson).c_str(), p.lesson_hash.c_str(), where.c_str());
  }
}

// A CSV field (RFC 4180): quoted when it holds a comma, a quote or a line break.
std::string csv(std::string_view s) {
  if (s.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(s);
  std::string out = "\"";
  for (char c : s) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

const char* const kFields[] = {"id", "trainee", "station", "scenario", "scenario_hash", "mode",
                               "pilot", "input_device", "input_settings_hash", "started",
                               "started_unix_ms", "duration_s", "ended", "probe",
                               "recording_path", "recording_hash", "app_version", "front_end",
                               "parent_recording_hash", "parent_step", "lesson", "lesson_step",
                               "lesson_passed", "lesson_failed"};

std::vector<std::string> field_values(const history::StoredFlight& f) {
  return {std::to_string(f.id),  f.trainee, f.station, f.scenario, f.scenario_hash, f.mode,
          f.pilot, f.input_device, f.input_settings_hash,
          local_time(f.started_unix_ms, "%Y-%m-%dT%H:%M:%S%z"), std::to_string(f.started_unix_ms),
          number(f.duration_s), history::to_string(f.ended), f.probe ? "1" : "0",
          f.recording_path, f.recording_hash, f.app_version, f.front_end,
          f.parent_recording_hash, f.branch() ? std::to_string(f.parent_step) : std::string(),
          f.lesson,
          f.lesson_step >= 0 ? std::to_string(f.lesson_step + 1) : std::string(),
          f.lesson_step >= 0 ? (f.lesson_passed ? "1" : "0") : std::string(),
          f.lesson_failed};
}

void print_csv(const std::vector<history::StoredFlight>& rows) {
  // The score fields' columns: every name any row has, in the order first seen.
  std::vector<std::string> names;
  for (const auto& f : rows)
    for (const auto& [k, v] : f.metrics)
      if (std::find(names.begin(), names.end(), k) == names.end()) names.push_back(k);
  std::string line;
  for (const char* f : kFields) {
    if (!line.empty()) line += ',';
    line += f;
  }
  for (const auto& n : names) {
    line += ',';
    line += csv("metrics." + n);  // as in the JSON; never one of the flight's own columns
  }
  std::printf("%s\n", line.c_str());
  for (const auto& f : rows) {
    line.clear();
    for (const std::string& v : field_values(f)) {
      if (!line.empty()) line += ',';
      line += csv(v);
    }
    for (const auto& n : names) {
      line += ',';
      if (const auto v = metric_of(f, n)) line += number(*v);
    }
    std::printf("%s\n", line.c_str());
  }
}

void print_json(const std::vector<history::StoredFlight>& rows) {
  std::string out = "[";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const history::StoredFlight& f = rows[i];
    const std::vector<std::string> values = field_values(f);
    out += i ? ",\n  {" : "\n  {";
    for (std::size_t k = 0; k < values.size(); ++k) {
      const std::string_view name = kFields[k];
      out += (k ? ", " : "") + json_quote(name) + ": ";
      if (name == "id" || name == "started_unix_ms")
        out += values[k];
      else if (name == "duration_s" || name == "parent_step")
        out += values[k].empty() ? "null" : values[k];
      else if (name == "parent_recording_hash" && values[k].empty())
        out += "null";  // not a branch
      else if (name == "lesson_step")
        out += values[k].empty() ? "null" : values[k];  // 1-based
      else if (name == "lesson_passed")
        out += values[k].empty() ? "null" : f.lesson_passed ? "true" : "false";
      else if ((name == "lesson" || name == "lesson_failed") && values[k].empty())
        out += "null";  // not a lesson's attempt, or it passed
      else if (name == "probe")
        out += f.probe ? "true" : "false";
      else
        out += json_quote(values[k]);
    }
    out += ", \"metrics\": {";
    for (std::size_t m = 0; m < f.metrics.size(); ++m) {
      const std::string v = number(f.metrics[m].second);
      out += (m ? ", " : "") + json_quote(f.metrics[m].first) + ": " + (v.empty() ? "null" : v);
    }
    out += "}}";
  }
  out += rows.empty() ? "]\n" : "\n]\n";
  std::fputs(out.c_str(), stdout);
}

// Nothing at `file` yet (a link to nothing is something: opening it says so).
bool no_file_yet(const std::string& file) {
  std::error_code ec, link_ec;
  return !file.empty() && !fs::exists(file, ec) && !ec &&
         !fs::is_symlink(fs::symlink_status(file, link_ec));
}

// ---- import ----------------------------------------------------------------------------------

struct ImportRow {
  std::string file;
  std::string hash;
  enum class State { failed, known, scored } state = State::failed;
  std::optional<history::StoredFlight> record;  // with its lesson attempt's fields, if any
  std::string error;
  std::string note;  // what was imported short of the whole (a lesson attempt without verdict)
};

// A lesson step's recording (its metadata: lesson, lesson_hash, lesson_step 1-based,
// lesson_steps, lesson_step_title): its attempt's verdict, judged again against the lesson of
// that name and hash among `lessons`, onto `row`; else why not in `note` (not a lesson's flight:
// nothing).
void judge_for_import(const RecordingContents& rec, const std::vector<Lesson>& lessons,
                      const Metrics& metrics, bool completed, history::StoredFlight& row,
                      std::string& note) {
  const auto meta = [&rec](const char* key) {
    const auto it = rec.metadata.find(key);
    return it == rec.metadata.end() ? std::string() : it->second;
  };
  const std::string name = meta("lesson"), hash = meta("lesson_hash");
  if (name.empty()) return;
  const std::string step_text = meta("lesson_step");
  char* end = nullptr;
  const long step = std::strtol(step_text.c_str(), &end, 10);
  const auto lesson = std::find_if(lessons.begin(), lessons.end(), [&](const Lesson& l) {
    return l.name == name && l.hash == hash;
  });
  if (lesson == lessons.end()) {
    note = "its lesson attempt (" + name + ", step " + step_text +
           ") is not: no lesson file here has its SHA-256 (--lesson FILE names one)";
    return;
  }
  if (end == step_text.c_str() || *end != '\0' || step < 1 || step > long(lesson->steps.size())) {
    note = "its lesson attempt is not: its metadata's lesson_step '" + step_text +
           "' is not a step of " + name;
    return;
  }
  const LessonStep& s = lesson->steps[std::size_t(step - 1)];
  const auto field = [&metrics](const char* key) {
    for (const auto& [k, v] : metrics)
      if (k == key) return v;
    return 0.0;
  };
  LessonScore score;
  score.skill = field("skill");
  score.time_in_ball = field("time_in_ball");
  score.collisions = field("collisions");
  score.completed = completed;
  const LessonVerdict verdict = judge(s, score);
  row.lesson = lesson->name;
  row.lesson_hash = lesson->hash;
  row.lesson_step = int(step - 1);
  row.lesson_step_title = s.title;
  row.lesson_ceiling = s.flown_ceiling();
  row.lesson_passed = verdict.passed;
  row.lesson_failed = verdict.failed;
  // In words as the flight's own verdict was (app/flight_rig.cpp).
  row.lesson_detail.clear();
  if (verdict.passed) {
    for (const CriterionResult& r : verdict.results)
      row.lesson_detail += (row.lesson_detail.empty() ? "" : "; ") + r.text;
  } else {
    row.lesson_detail = verdict.detail;
  }
}

// The recording flown again and checked (as score does), as the history's row.
void score_for_import(ImportRow& row, const std::string& trainee,
                      const std::vector<Lesson>& lessons) {
  FlyOptions o;
  o.pilot = row.file;
  o.replay = true;
  o.command = "history import";
  std::string error;
  int status = kExitOk;
  const std::unique_ptr<FlightRig> rig = FlightRig::assemble(o, error, status);
  if (!rig) {
    row.error = error;
    return;
  }
  rig->start();
  while (rig->step()) {
  }
  if (const std::string diff = rig->replay_difference(); !diff.empty()) {
    row.error = row.file + ": its replay differs from the recording (" + diff +
                "): its score would not be that flight's";
    return;
  }
  const RecordingContents& rec = *rig->flight().recording;
  const bool early = !recording_ended_early(rec, rig->mode()).empty();
  auto r = rig->flight_record(early, error);
  if (!r) {
    row.error = error;
    return;
  }
  if (const auto it = rec.metadata.find("trainee"); it == rec.metadata.end() || it->second.empty())
    r->trainee = trainee.empty() ? r->trainee : trainee;
  if (r->front_end != "vehicle") r->front_end = "import";
  std::error_code ec;
  const fs::path abs = fs::absolute(row.file, ec);
  r->recording_path = (ec ? fs::path(row.file) : abs).lexically_normal().string();
  r->recording_hash = row.hash;
  struct stat st {};
  const std::int64_t mtime_ms =
      ::stat(row.file.c_str(), &st) == 0
          ? std::int64_t(st.st_mtim.tv_sec) * 1000 + st.st_mtim.tv_nsec / 1'000'000
          : 0;
  r->started_unix_ms = std::max<std::int64_t>(0, mtime_ms - std::int64_t(r->duration_s * 1000));
  history::StoredFlight stored;
  static_cast<history::FlightRecord&>(stored) = std::move(*r);
  judge_for_import(rec, lessons, rig->metrics(), !early && !rig->mode().lost(), stored, row.note);
  row.record = std::move(stored);
  row.state = ImportRow::State::scored;
}

// The lessons a lesson step's recording may name: the shipped ones and `files` (--lesson);
// false with the reason when one of `files` is no lesson.
bool import_lessons(const std::vector<std::string>& files, std::vector<Lesson>& out,
                    std::string& error) {
  for (const std::string& f : shipped_lessons())
    if (std::string why; auto l = load_lesson(f, why)) out.push_back(std::move(*l));
  for (const std::string& f : files) {
    auto l = load_lesson(f, error);
    if (!l) return error = "--lesson " + error, false;
    out.push_back(std::move(*l));
  }
  return true;
}

int import_command(history::HistoryStore& store, const std::string& dir, int jobs,
                   const std::string& trainee, const std::vector<Lesson>& lessons) {
  std::vector<ImportRow> rows;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    std::fprintf(stderr, "mixpilot history import: %s: %s\n", escape_controls(dir).c_str(),
                 ec ? ec.message().c_str() : "not a folder");
    return kExitError;
  }
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().extension() == ".mcap" && it->is_regular_file(ec))
      rows.push_back({it->path().string(), {}, ImportRow::State::failed, {}, {}});
  if (ec) {
    std::fprintf(stderr, "mixpilot history import: %s: %s\n", escape_controls(dir).c_str(),
                 ec.message().c_str());
    return kExitError;
  }
  std::sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.file < b.file; });
  // Known recordings are skipped before they are flown: importing again costs only the hashes.
  std::string error;
  for (ImportRow& r : rows) {
    const auto h = sha256_file(r.file, r.error);
    if (!h) continue;
    r.hash = *h;
    bool known = false;
    if (!store.knows_recording(r.hash, known, error)) {
      std::fprintf(stderr, "mixpilot history import: %s\n", escape_controls(error).c_str());
      return kExitError;
    }
    if (known) r.state = ImportRow::State::known;
  }
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex io;
  std::size_t added = 0, known = 0, failed = 0;
  const auto say = [&](const ImportRow& r, const std::string& what) {
    std::fprintf(stderr, "[%zu/%zu] %s: %s\n", ++done, rows.size(), escape_controls(r.file).c_str(),
                 escape_controls(what).c_str());
  };
  // Progress as each recording is done; the counts at the end.
  const auto report = [&](const ImportRow& r) {
    if (r.state == ImportRow::State::known) {
      ++known;
      say(r, "already in the history");
    } else if (r.state == ImportRow::State::scored) {
      ++added;
      const auto skill = std::find_if(r.record->metrics.begin(), r.record->metrics.end(),
                                      [](const auto& m) { return m.first == "skill"; });
      std::string what = skill != r.record->metrics.end()
                             ? "added (skill " + number(skill->second, "%.1f") + ")"
                             : "added (" + r.record->mode + ")";
      if (r.record->attempt())
        what += ", " + r.record->lesson + " step " + std::to_string(r.record->lesson_step + 1) +
                (r.record->lesson_passed ? " passed" : " not passed");
      if (!r.note.empty()) what += "; " + r.note;
      say(r, what);
    } else {
      ++failed;
      say(r, "not imported: " + r.error);
    }
  };
  for (const ImportRow& r : rows)
    if (r.state == ImportRow::State::known || r.hash.empty()) report(r);
  const auto worker = [&] {
    for (std::size_t i = next++; i < rows.size(); i = next++) {
      ImportRow& r = rows[i];
      if (r.state == ImportRow::State::known || r.hash.empty()) continue;
      score_for_import(r, trainee, lessons);
      // One writer at a time in this process; other processes wait on the database's lock.
      const std::lock_guard<std::mutex> lock(io);
      if (r.state == ImportRow::State::scored) {
        // The flight with its lesson attempt's verdict, the trainee's place left as it is.
        std::string why;
        const auto c = store.copy_flight(*r.record, why);
        if (!c) {
          r.state = ImportRow::State::failed;
          r.error = why;
        } else if (!c->flight) {
          r.state = ImportRow::State::known;
        }
      }
      report(r);
    }
  };
  {
    std::vector<std::thread> pool;
    for (int j = 0; j < std::min<int>(jobs, int(rows.size())); ++j) pool.emplace_back(worker);
    for (auto& t : pool) t.join();
  }
  std::printf("mixpilot history import: %zu added, %zu already known, %zu not imported (%s)\n",
              added, known, failed, escape_controls(store.where()).c_str());
  return failed > 0 ? kExitError : kExitOk;
}

// ---- push -------------------------------------------------------------------------------------

// mixpilot history push URL [--history SOURCE]. The URL may hold a password: no message
// repeats the argument as given, only its redacted form.
int push_command(int argc, char** argv) {
  const char* cmd = "history push";
  std::string source, destination;
  for (int i = 3; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::fputs(kHistoryUsage, stdout);
      return kExitOk;
    } else if (a == "--history") {
      source = option_value(cmd, argc, argv, i);
      if (source == "off") usage_error(cmd, "--history off: there is no history to push");
    } else if (destination.empty() &&
               (a.starts_with("postgresql://") || a.starts_with("postgres://"))) {
      destination = a;
    } else if (!a.empty() && a[0] != '-' && destination.empty()) {
      usage_error(cmd, "the centre's database is a postgresql://... URL, not '" +
                           escape_controls(history::redact_postgres_url(std::string(a))) + "'");
    } else {
      usage_error(cmd, "unexpected '" +
                           escape_controls(history::redact_postgres_url(std::string(a))) + "'");
    }
  }
  if (destination.empty())
    usage_error(cmd, "which database? (mixpilot history push postgresql://HOST/DATABASE)");
  std::string error;
  // The station's history is read, never made: no SQLite file is nothing to push.
  if (!source.starts_with("postgres")) {
    const std::string file = source.empty()                   ? history::default_history_path()
                             : source.starts_with("sqlite:") ? source.substr(7)
                                                              : source;
    if (no_file_yet(file)) {
      std::fprintf(stderr, "mixpilot history push: %s: no history here yet: nothing to push\n",
                   escape_controls(file).c_str());
      return kExitError;
    }
  }
  const auto from = history::open_history(source, error);
  if (!from) {
    std::fprintf(stderr, "mixpilot history push: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  const auto to = history::open_history(destination, error);
  if (!to) {
    std::fprintf(stderr, "mixpilot history push: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  history::PushCounts counts;
  const bool ok = history::push_history(*from, *to, counts, error, [](std::size_t done,
                                                                      std::size_t total) {
    if (done % 1000 == 0 && done < total)
      std::fprintf(stderr, "mixpilot history push: %zu of %zu flights\n", done, total);
  });
  if (!ok)
    std::fprintf(stderr, "mixpilot history push: %s\n", escape_controls(error).c_str());
  std::printf("mixpilot history push: %zu added, %zu already there; lessons: %zu attempts "
              "added, %zu progress rows updated (%s -> %s)\n",
              counts.added, counts.already_there, counts.attempts, counts.progress,
              escape_controls(from->where()).c_str(), escape_controls(to->where()).c_str());
  return ok ? kExitOk : kExitError;
}

}  // namespace

int history_command(int argc, char** argv) {
  const char* cmd = "history";
  history::Query q;
  std::string location, import_dir, trainee_for_import;
  std::vector<std::string> lesson_files;  // import's --lesson
  std::string html;
  bool as_csv = false, as_json = false, importing = false, force = false;
  int jobs = int(std::max(1u, std::thread::hardware_concurrency()));
  int first = 2;
  if (argc > 2 && std::string_view(argv[2]) == "import") {
    importing = true;
    first = 3;
  } else if (argc > 2 && std::string_view(argv[2]) == "push") {
    return push_command(argc, argv);
  }
  for (int i = first; i < argc; ++i) {
    const std::string_view a = argv[i];
    const auto value = [&] { return option_value(cmd, argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kHistoryUsage, stdout);
      return kExitOk;
    } else if (a == "--history") {
      location = value();
      if (location == "off") usage_error(cmd, "--history off: there is no history to read");
    } else if (a == "--trainee") {
      const std::string v = value();
      if (const std::string why = history::check_trainee(v); !why.empty())
        usage_error(cmd, "--trainee: " + why);
      (importing ? trainee_for_import : q.trainee) = v;
    } else if (!importing && a == "--scenario") {
      q.scenario = value();
    } else if (!importing && a == "--since") {
      const std::string v = value();
      const auto t = parse_since(v);
      if (!t)
        usage_error(cmd, "--since expects YYYY-MM-DD, YYYY-MM-DDTHH:MM or YYYY-MM-DDTHH:MM:SS, "
                         "got '" + escape_controls(v) + "'");
      q.since_unix_ms = *t;
    } else if (!importing && a == "--limit") {
      const std::string v = value();
      char* end = nullptr;
      const long long n = std::strtoll(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1)
        usage_error(cmd, "--limit expects a whole number of flights ≥ 1, got '" +
                             escape_controls(v) + "'");
      q.limit = n;
    } else if (!importing && a == "--csv") {
      as_csv = true;
    } else if (!importing && a == "--json") {
      as_json = true;
    } else if (!importing && a == "--html") {
      html = value();
    } else if (!importing && a == "--force") {
      force = true;
    } else if (importing && a == "--jobs") {
      const std::string v = value();
      char* end = nullptr;
      const long n = std::strtol(v.c_str(), &end, 10);
      if (end == v.c_str() || *end != '\0' || n < 1 || n > 256)
        usage_error(cmd, "--jobs expects a whole number from 1 to 256, got '" +
                             escape_controls(v) + "'");
      jobs = int(n);
    } else if (importing && a == "--lesson") {
      lesson_files.push_back(file_argument(cmd, "a lesson file", value()));
    } else if (importing && (a.empty() || a[0] != '-') && import_dir.empty()) {
      import_dir = file_argument(cmd, "a folder of recordings", a);
    } else {
      usage_error(cmd, "unexpected '" + escape_controls(a) + "'");
    }
  }
  if (int(as_csv) + int(as_json) + int(!html.empty()) > 1)
    usage_error(cmd, "one of --csv, --json and --html");
  if (!html.empty() && q.trainee.empty())
    usage_error(cmd, "--html is one trainee's report: say whose (--trainee NAME)");
  if (!html.empty()) {
    std::vector<std::pair<std::string, std::string>> inputs;
    for (const std::string& file : history::sqlite_files(location))
      inputs.emplace_back("the history", file);
    check_not_an_input(cmd, "--html", html, inputs);
  }
  if (importing && import_dir.empty())
    usage_error(cmd, "which folder? (mixpilot history import DIR)");
  std::string error;
  std::vector<history::StoredFlight> rows;
  std::vector<history::LessonProgress> progress;  // the table's footer
  // The report's file is checked before any work (never clobbered without --force).
  OutputFile report;
  if (!html.empty() && !report.open(html, force, error)) {
    std::fprintf(stderr, "mixpilot history: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  const auto print = [&] {
    if (!html.empty()) {
      const std::string text = progress_html(
          q.trainee, rows,
          std::chrono::duration_cast<std::chrono::milliseconds>(
              std::chrono::system_clock::now().time_since_epoch())
              .count());
      if (std::fwrite(text.data(), 1, text.size(), report.stream()) != text.size() ||
          !report.commit(error)) {
        if (error.empty()) error = html + ": cannot write: " + report.keep_partial();
        std::fprintf(stderr, "mixpilot history: %s\n", escape_controls(error).c_str());
        return kExitError;
      }
      std::printf("mixpilot history: %s's progress report (%zu flight%s) in %s\n",
                  escape_controls(q.trainee).c_str(), rows.size(), rows.size() == 1 ? "" : "s",
                  escape_controls(html).c_str());
      return kExitOk;
    }
    if (as_csv) {
      print_csv(rows);
    } else if (as_json) {
      print_json(rows);
    } else {
      print_table(rows);
      print_lesson_progress(progress);
    }
    return kExitOk;
  };
  // A listing never creates a history: no SQLite file yet is no flight yet.
  if (!importing && !location.starts_with("postgres")) {
    const std::string file = location.empty()            ? history::default_history_path()
                             : location.starts_with("sqlite:") ? location.substr(7)
                                                               : location;
    if (no_file_yet(file)) return print();
  }
  // The lessons to judge lesson steps' recordings against, before the history is opened (a
  // bad --lesson makes none).
  std::vector<Lesson> lessons;
  if (importing && !import_lessons(lesson_files, lessons, error)) {
    std::fprintf(stderr, "mixpilot history import: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  const auto store = history::open_history(location, error);
  if (!store) {
    report.discard();
    std::fprintf(stderr, "mixpilot history: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  if (importing) return import_command(*store, import_dir, jobs, trainee_for_import, lessons);
  // The table shows one score field: reading the others (twenty a flight) is what would make a
  // long history slow to list.
  if (!as_csv && !as_json && html.empty()) q.metrics = {"skill"};
  if (!store->query(q, rows, error) ||
      (!as_csv && !as_json && html.empty() && !store->lesson_progress(q.trainee, progress, error))) {
    report.discard();
    std::fprintf(stderr, "mixpilot history: %s\n", escape_controls(error).c_str());
    return kExitError;
  }
  return print();
}

}  // namespace mixpilot::cli
