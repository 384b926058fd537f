#include "core/history/history.hpp"

#include <pwd.h>
#include <unistd.h>

#include <climits>
#include <cstdlib>

#include "core/history/postgres_history.hpp"
#include "core/history/sqlite_history.hpp"
#include "core/scenario/data_files.hpp"

namespace mixpilot::history {

const char* to_string(Ended e) {
  switch (e) {
    case Ended::completed: return "completed";
    case Ended::interrupted: return "interrupted";
    case Ended::lost: return "lost";
    case Ended::instructor: return "instructor";
  }
  return "completed";
}

std::optional<Ended> ended_from(std::string_view text) {
  for (Ended e : {Ended::completed, Ended::interrupted, Ended::lost, Ended::instructor})
    if (text == to_string(e)) return e;
  return std::nullopt;
}

namespace {

// The code points of `s`, or nullopt with `why` for invalid UTF-8 (overlong forms, surrogates
// and values past U+10FFFF included). `control`: set when a C0, DEL or C1 control was seen.
std::optional<std::size_t> utf8_chars(std::string_view s, std::string& why, bool& control) {
  std::size_t n = 0;
  control = false;
  for (std::size_t i = 0; i < s.size(); ++n) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    std::size_t len = 0;
    std::uint32_t cp = 0;
    if (c < 0x80) {
      len = 1, cp = c;
    } else if ((c & 0xE0) == 0xC0) {
      len = 2, cp = c & 0x1F;
    } else if ((c & 0xF0) == 0xE0) {
      len = 3, cp = c & 0x0F;
    } else if ((c & 0xF8) == 0xF0) {
      len = 4, cp = c & 0x07;
    } else {
      why = "byte " + std::to_string(i) + " is not UTF-8";
      return std::nullopt;
    }
    if (i + len > s.size()) {
      why = "it ends inside a UTF-8 sequence";
      return std::nullopt;
    }
    for (std::size_t k = 1; k < len; ++k) {
      const unsigned char cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) {
        why = "byte " + std::to_string(i + k) + " is not UTF-8";
        return std::nullopt;
      }
      cp = (cp << 6) | (cc & 0x3F);
    }
    static constexpr std::uint32_t kMin[] = {0, 0, 0x80, 0x800, 0x10000};
    if (cp < kMin[len] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) {
      why = "byte " + std::to_string(i) + " starts an invalid UTF-8 sequence";
      return std::nullopt;
    }
    if (cp < 0x20 || (cp >= 0x7F && cp < 0xA0)) control = true;
    i += len;
  }
  return n;
}

std::string check_text(const char* field, std::string_view s) {
  std::string why;
  bool control = false;
  if (s.size() > kMaxTextBytes)
    return std::string(field) + " is longer than " + std::to_string(kMaxTextBytes) + " bytes";
  if (!utf8_chars(s, why, control)) return std::string(field) + " is not valid UTF-8: " + why;
  return {};
}

std::string check_name(const char* what, std::string_view name) {
  std::string why;
  bool control = false;
  if (name.empty()) return std::string(what) + " is empty";
  const auto n = utf8_chars(name, why, control);
  if (!n) return std::string(what) + " is not valid UTF-8 (" + why + ")";
  if (*n > kMaxNameChars)
    return std::string(what) + " is " + std::to_string(*n) + " characters long; at most " +
           std::to_string(kMaxNameChars) + " are kept";
  if (control) return std::string(what) + " holds a control character (a tab, newline, escape...)";
  return {};
}

}  // namespace

std::string check_trainee(std::string_view name) { return check_name("the trainee's name", name); }

std::string check_record(const FlightRecord& f) {
  if (std::string why = check_trainee(f.trainee); !why.empty()) return why;
  const std::pair<const char*, const std::string*> texts[] = {
      {"the station", &f.station},         {"the scenario", &f.scenario},
      {"the scenario hash", &f.scenario_hash}, {"the mode", &f.mode},
      {"the pilot", &f.pilot},             {"the input device", &f.input_device},
      {"the input settings hash", &f.input_settings_hash},
      {"the recording's path", &f.recording_path}, {"the recording's hash", &f.recording_hash},
      {"the app version", &f.app_version}, {"the front end", &f.front_end},
      {"the parent recording's hash", &f.parent_recording_hash}};
  for (const auto& [field, text] : texts)
    if (std::string why = check_text(field, *text); !why.empty()) return why;
  // A branch names its parent by its recording's hash and the step it was taken over at.
  if (f.parent_step < -1) return "the parent step is negative";
  if (f.branch() != !f.parent_recording_hash.empty())
    return "a branch needs both its parent recording's hash and its parent step";
  for (const auto& [name, value] : f.metrics)
    if (std::string why = check_name("a metric's name", name); !why.empty()) return why;
  return {};
}

std::string check_attempt(const LessonAttempt& a) {
  const std::pair<const char*, const std::string*> texts[] = {
      {"the lesson", &a.lesson},           {"the lesson hash", &a.lesson_hash},
      {"the step's title", &a.step_title}, {"the failed criterion", &a.failed_criterion},
      {"the verdict", &a.detail}};
  for (const auto& [field, text] : texts)
    if (std::string why = check_text(field, *text); !why.empty()) return why;
  if (a.lesson.empty() || a.lesson_hash.empty()) return "the lesson's name or hash is empty";
  if (a.steps < 1 || a.step < 0 || a.step >= a.steps)
    return "step " + std::to_string(a.step) + " is not one of the lesson's " +
           std::to_string(a.steps);
  if (!(a.ceiling > 0.0 && a.ceiling <= 1.0)) return "the ceiling is outside (0, 1]";
  if (a.passed != a.failed_criterion.empty())
    return "a verdict names a failed criterion exactly when it failed";
  return {};
}

std::string check_progress(const LessonProgress& p) {
  if (std::string why = check_trainee(p.trainee); !why.empty()) return why;
  const std::pair<const char*, const std::string*> texts[] = {{"the lesson", &p.lesson},
                                                              {"the lesson hash", &p.lesson_hash}};
  for (const auto& [field, text] : texts)
    if (std::string why = check_text(field, *text); !why.empty()) return why;
  if (p.lesson.empty() || p.lesson_hash.empty()) return "the lesson's name or hash is empty";
  if (p.steps < 1 || p.step < 0 || p.step > p.steps)
    return "step " + std::to_string(p.step) + " is not one of the lesson's " +
           std::to_string(p.steps) + " (or past its last)";
  if (p.failed_attempts < 0) return "the failed attempts are negative";
  return {};
}

LessonAttempt StoredFlight::as_attempt() const {
  LessonAttempt a;
  a.lesson = lesson;
  a.lesson_hash = lesson_hash;
  a.steps = lesson_step + 1;
  a.step = lesson_step;
  a.step_title = lesson_step_title;
  a.ceiling = lesson_ceiling;
  a.passed = lesson_passed;
  a.failed_criterion = lesson_failed;
  a.detail = lesson_detail;
  return a;
}

LessonProgress progress_after(const LessonProgress& before, const LessonAttempt& a,
                              std::string& why) {
  why.clear();
  LessonProgress p = before;
  if (before.steps > 0 && before.step >= before.steps) {
    why = "the trainee has passed every step of " + a.lesson + " already";
    return p;
  }
  if (a.step != before.step) {
    why = "the trainee is on step " + std::to_string(before.step + 1) + " of " + a.lesson +
          ", not step " + std::to_string(a.step + 1) + " (another flight moved them on)";
    return p;
  }
  p.steps = a.steps;
  if (a.passed) {
    p.step = a.step + 1;
    p.failed_attempts = 0;
  } else {
    ++p.failed_attempts;
  }
  return p;
}

std::string host_name() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return {};
  return name;
}

std::string login_name() {
  if (const passwd* pw = ::getpwuid(::geteuid()); pw && pw->pw_name) return pw->pw_name;
  if (const char* user = std::getenv("USER"); user && *user) return user;
  return {};
}

std::string default_history_path(std::string* why) {
  const std::string base = xdg_dir("XDG_DATA_HOME", ".local/share", why);
  return base.empty() ? std::string() : base + "/mixpilot/history.sqlite";
}

std::vector<std::string> sqlite_files(const std::string& location) {
  if (location == "off" || location.starts_with("postgresql://") ||
      location.starts_with("postgres://"))
    return {};
  const std::string db = location.empty()                 ? default_history_path()
                         : location.starts_with("sqlite:") ? location.substr(7)
                                                           : location;
  if (db.empty()) return {};
  return {db, db + "-wal", db + "-shm", db + "-journal"};
}

std::unique_ptr<HistoryStore> open_history(const std::string& location, std::string& error) {
  if (location.empty()) {
    std::string why;
    const std::string path = default_history_path(&why);
    if (path.empty()) {
      error = "no folder for the history (" + why + "); set XDG_DATA_HOME or --history";
      return nullptr;
    }
    return open_sqlite(path, error);
  }
  if (location.starts_with("postgresql://") || location.starts_with("postgres://"))
    return open_postgres(location, error);
  if (location.starts_with("sqlite:")) {
    const std::string path = location.substr(7);
    if (path.empty()) {
      error = "sqlite: names no file (sqlite:PATH)";
      return nullptr;
    }
    return open_sqlite(path, error);
  }
  return open_sqlite(location, error);
}

}  // namespace mixpilot::history
