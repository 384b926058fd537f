#pragma once
// Reading TOML with precise diagnostics (`<file>:<line>:<col>: <key path>: <what was expected>`):
// shared by every scenario loader and by the input settings (input/settings.cpp). It includes
// toml++: only the readers' .cpp files include it, never a public header.
//
// Debian's toml++ is the compiled shared library, built with exceptions: including TUs keep
// them on (switching them off would select the noex ABI the library does not export) and
// catch toml::parse_error themselves.
#include <toml++/toml.h>

#include "core/base/input_file.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mixpilot::toml_read {

struct Pos {
  std::uint32_t line = 1;
  std::uint32_t col = 1;
};

inline Pos pos_of(const toml::source_region& r) { return {r.begin.line, r.begin.column}; }

// Collects `<file>:<line>:<col>: <key path>: <what>` lines; reported sorted by position.
class Diagnostics {
 public:
  explicit Diagnostics(std::string file) : file_(std::move(file)) {}

  void add(Pos p, std::string_view path, std::string_view what) {
    std::string text = file_ + ':' + std::to_string(p.line) + ':' + std::to_string(p.col) + ": ";
    text.append(path).append(": ").append(what);
    // Keys, strings and file names come from the file (or a recording): a terminal must never
    // receive their control characters.
    items_.push_back({p, escape_controls(text)});
  }
  bool empty() const { return items_.empty(); }
  std::string str() {
    std::stable_sort(items_.begin(), items_.end(), [](const Item& a, const Item& b) {
      return std::pair(a.pos.line, a.pos.col) < std::pair(b.pos.line, b.pos.col);
    });
    std::string out;
    for (const Item& i : items_) out += (out.empty() ? "" : "\n") + i.text;
    return out;
  }

 private:
  struct Item {
    Pos pos;
    std::string text;
  };
  std::string file_;
  std::vector<Item> items_;
};

// Shortest round-trip text; floats keep a '.' so "got 50.0" is not mistaken for an integer.
inline std::string fmt(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}

inline std::string describe(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string:
      return "the string \"" + printable(n.as_string()->get()) + '"';
    case toml::node_type::integer:
      return std::to_string(n.as_integer()->get());
    case toml::node_type::floating_point:
      return fmt(n.as_floating_point()->get());
    case toml::node_type::boolean:
      return n.as_boolean()->get() ? "true" : "false";
    case toml::node_type::array:
      return "an array of " + std::to_string(n.as_array()->size());
    case toml::node_type::table:
      return "a table";
    default:
      return "a date/time";
  }
}

inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const auto lower = [](char c) { return (c >= 'A' && c <= 'Z') ? char(c - 'A' + 'a') : c; };
      const std::size_t sub = diag + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      diag = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, sub});
    }
  }
  return row[b.size()];
}

// The documented range of a key (docs/scenario-format.md): a closed or open interval, checked
// after the value is known to be finite. Message: `value outside (0, 3600], got 1e+300`.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string text() const {
    return std::string(lo_open ? "(" : "[") + fmt_bound(lo) + ", " + fmt_bound(hi) +
           (hi_open ? ")" : "]");
  }
  static std::string fmt_bound(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", v);
    return buf;
  }
};

struct IntRange {
  std::int64_t lo = 0;
  std::int64_t hi = 0;
  bool contains(std::int64_t v) const { return v >= lo && v <= hi; }
  std::string text() const { return '[' + std::to_string(lo) + ", " + std::to_string(hi) + ']'; }
};

constexpr double kHugeWeight = 1e9;  // cost weights: beyond this the QPs lose all precision

inline constexpr Range closed(double lo, double hi) { return {lo, hi, false, false}; }
inline constexpr Range left_open(double lo, double hi) { return {lo, hi, true, false}; }
inline constexpr Range open_interval(double lo, double hi) { return {lo, hi, true, true}; }
// A weight that may be 0, and one that must stay away from 0 (a pivot or a Hessian diagonal).
inline constexpr Range weight() { return closed(0, kHugeWeight); }
inline constexpr Range pos_weight() { return closed(1e-6, kHugeWeight); }

// Limits shared by every scenario kind (docs/scenario-format.md, "Ranges"). They keep memory
// and time proportionate: at most an hour simulated, 2e6 control steps (per-step buffers of a
// few hundred MB at most), 4e7 plant substeps (minutes of RK4), horizons whose QPs stay
// interactive, and every count far inside an int.
constexpr Range kDuration = left_open(0, 3600);  // [s]
constexpr Range kControlDt = closed(1e-3, 1);    // [s]
constexpr IntRange kHorizon{1, 200};             // stages
constexpr Range kPlantRate = closed(1000, 1e5);  // [Hz]
constexpr double kMaxSteps = 2e6;                // duration / dt
constexpr double kMaxSubsteps = 4e7;             // duration * rate_hz
constexpr Range kDelay = closed(0, 10);          // [s]
constexpr Range kPosition = closed(-1e3, 1e3);   // [m], any coordinate
constexpr Range kAngularRate = closed(-10, 10);  // [rad/s], helix references
constexpr Range kClimbRate = closed(-100, 100);  // [m/s]
constexpr Range kPhase = closed(-100, 100);      // [rad]
constexpr std::size_t kMaxObstacles = 64;        // per scenario

// "value outside [a, b]" for a derived (computed) quantity named in `what`.
inline std::string outside(std::string_view what, double v, const Range& r) {
  return std::string(what) + " = " + Range::fmt_bound(v) + ", outside " + r.text();
}

// The size of a run: 1 .. kMaxSteps control steps (duration / dt) and at most kMaxSubsteps
// plant substeps (duration * rate_hz). Reported at `at` (the duration, or its table).
inline void check_run_size(Diagnostics& d, Pos at, double duration, double dt, double rate_hz) {
  const double steps = duration / dt;
  if (!(steps >= 1 - 1e-9 && steps <= kMaxSteps)) {
    d.add(at, "duration",
          outside("duration / controller.dt (control steps)", steps, closed(1, kMaxSteps)));
  }
  const double substeps = duration * rate_hz;
  if (!(substeps <= kMaxSubsteps)) {
    d.add(at, "duration",
          outside("duration * plant.rate_hz (plant substeps)", substeps, closed(0, kMaxSubsteps)));
  }
}

// One TOML table being read: every key asked for is "known"; finish() reports the rest.
// A missing table (t == nullptr) reads as all-defaults.
class Section {
 public:
  Section(Diagnostics& d, const toml::table* t, std::string path, Pos pos)
      : d_(d), t_(t), path_(std::move(path)), pos_(pos) {}

  const toml::table* table() const { return t_; }
  Pos pos() const { return pos_; }
  std::string path(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + '.' + std::string(key);
  }
  // Position of key's value if given, else of this table (cross-checks on defaulted keys).
  Pos pos(std::string_view key) const {
    const toml::node* n = t_ ? t_->get(key) : nullptr;
    return n ? pos_of(n->source()) : pos_;
  }

  const toml::node* take(std::string_view key, bool required, std::string_view expected) {
    known_.emplace_back(key);
    const toml::node* n = t_ ? t_->get(key) : nullptr;
    if (!n && required) {
      d_.add(pos_, path(key), "missing required key (expected " + std::string(expected) + ')');
    }
    return n;
  }

  Section sub(std::string_view key) {
    const toml::node* n = take(key, false, "");
    if (n && !n->is_table()) {
      d_.add(pos_of(n->source()), path(key), "expected a table, got " + describe(*n));
      n = nullptr;
    }
    return Section(d_, n ? n->as_table() : nullptr, path(key), n ? pos_of(n->source()) : pos_);
  }

  bool num(std::string_view key, double& out, const Range& range, bool required = false) {
    const toml::node* n = take(key, required, "a number");
    return n && read_num(*n, path(key), out, range);
  }

  bool integer(std::string_view key, std::int64_t& out, const IntRange& range,
               bool required = false) {
    const toml::node* n = take(key, required, "an integer");
    if (!n) return false;
    if (!n->is_integer()) {
      d_.add(pos_of(n->source()), path(key), "expected an integer, got " + describe(*n));
      return false;
    }
    const std::int64_t v = n->as_integer()->get();
    if (!range.contains(v)) {
      d_.add(pos_of(n->source()), path(key),
             "value outside " + range.text() + ", got " + std::to_string(v));
      return false;
    }
    out = v;
    return true;
  }

  // Every int range lies inside int's: the narrowing below is exact.
  bool integer(std::string_view key, int& out, const IntRange& range, bool required = false) {
    std::int64_t v = out;
    if (!integer(key, v, range, required)) return false;
    out = int(v);
    return true;
  }

  bool boolean(std::string_view key, bool& out) {
    const toml::node* n = take(key, false, "");
    if (!n) return false;
    if (!n->is_boolean()) {
      d_.add(pos_of(n->source()), path(key), "expected true or false, got " + describe(*n));
      return false;
    }
    out = n->as_boolean()->get();
    return true;
  }

  bool string(std::string_view key, std::string& out, bool required = false) {
    const toml::node* n = take(key, required, "a string");
    if (!n) return false;
    if (!n->is_string() || n->as_string()->get().empty()) {
      d_.add(pos_of(n->source()), path(key), "expected a non-empty string, got " + describe(*n));
      return false;
    }
    // Names and file names end up in messages, summaries and file names.
    if (escape_controls(n->as_string()->get()) != n->as_string()->get()) {
      d_.add(pos_of(n->source()), path(key),
             "expected a string without control characters, got " + describe(*n));
      return false;
    }
    out = n->as_string()->get();
    return true;
  }

  bool choice(std::string_view key, std::string& out, std::initializer_list<const char*> allowed,
              bool required = false) {
    std::string list;
    for (const char* a : allowed) list += (list.empty() ? "" : ", ") + ('"' + std::string(a) + '"');
    const toml::node* n = take(key, required, "one of " + list);
    if (!n) return false;
    if (n->is_string()) {
      for (const char* a : allowed) {
        if (n->as_string()->get() == a) {
          out = a;
          return true;
        }
      }
    }
    d_.add(pos_of(n->source()), path(key), "expected one of " + list + ", got " + describe(*n));
    return false;
  }

  template <int n>
  bool vec(std::string_view key, Eigen::Matrix<double, n, 1>& out, const Range& range,
           bool required = false) {
    const std::string expected = "an array of " + std::to_string(n) + " numbers";
    const toml::node* node = take(key, required, expected);
    if (!node) return false;
    const toml::array* a = node->as_array();
    if (!a || a->size() != std::size_t(n)) {
      d_.add(pos_of(node->source()), path(key), "expected " + expected + ", got " + describe(*node));
      return false;
    }
    Eigen::Matrix<double, n, 1> v;
    bool ok = true;
    for (int i = 0; i < n; ++i) {
      ok = read_num(*a->get(std::size_t(i)), path(key) + '[' + std::to_string(i) + ']', v[i],
                    range) &&
           ok;
    }
    if (ok) out = v;
    return ok;
  }

  // Keys nobody asked for: typos, or keys placed in the wrong table.
  void finish() {
    if (!t_) return;
    for (auto&& [k, v] : *t_) {
      if (std::find(known_.begin(), known_.end(), k.str()) != known_.end()) continue;
      std::string what = "unknown key";
      const std::string* best = nullptr;
      std::size_t best_d = 3;  // suggest only close matches
      for (const std::string& c : known_) {
        // A prefix counts as close too ("r" for "radius").
        const bool prefix = c.starts_with(k.str()) || k.str().starts_with(c);
        const std::size_t dist = prefix ? 0 : edit_distance(k.str(), c);
        if (dist < best_d && dist < c.size()) best = &c, best_d = dist;
      }
      if (best) {
        what += " (did you mean \"" + *best + "\"?)";
      } else {
        what += "; expected one of:";
        for (const std::string& c : known_) what += ' ' + c;
      }
      d_.add(pos_of(k.source()), path(k.str()), what);
    }
  }

 private:
  bool read_num(const toml::node& n, const std::string& path, double& out, const Range& range) {
    double v = 0;
    if (n.is_floating_point()) {
      v = n.as_floating_point()->get();
    } else if (n.is_integer()) {
      v = double(n.as_integer()->get());  // `duration = 30` is as good as 30.0
    } else {
      d_.add(pos_of(n.source()), path, "expected a number, got " + describe(n));
      return false;
    }
    if (!std::isfinite(v)) {
      d_.add(pos_of(n.source()), path, "expected a finite number, got " + describe(n));
      return false;
    }
    if (!range.contains(v)) {
      d_.add(pos_of(n.source()), path, "value outside " + range.text() + ", got " + describe(n));
      return false;
    }
    out = v;
    return true;
  }

  Diagnostics& d_;
  const toml::table* t_;
  std::string path_;
  Pos pos_;
  std::vector<std::string> known_;
};

// Name of the last `[table]` or `[[table]]` header before `line` (1-based), "" if none.
inline std::string header_before(std::string_view text, std::uint32_t line) {
  std::string header;
  std::uint32_t n = 1;
  for (std::size_t at = 0; at < text.size() && n < line; ++n) {
    std::size_t end = text.find('\n', at);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(at, end - at);
    at = end + 1;
    const std::size_t b = l.find_first_not_of(" \t");
    if (b == std::string_view::npos || l[b] != '[') continue;
    const std::size_t close = l.find(']', b);
    if (close == std::string_view::npos) continue;
    header.clear();
    for (char c : l.substr(b, close - b)) {
      if (c != '[' && c != ' ' && c != '\t') header += c;
    }
  }
  return header;
}

// toml++ says "Error while parsing <what>: <detail>"; a redefinition names the key, which then
// goes in the key-path slot (this is how a duplicate [pilots.<name>] is reported). toml++ names
// a table by its full path but a plain key relative to its table: prefix that table's header.
inline void add_syntax_error(Diagnostics& d, const toml::parse_error& e, std::string_view text) {
  std::string desc(e.description());
  constexpr std::string_view redefine = "cannot redefine existing ";
  if (const auto at = desc.find(redefine); at != std::string::npos) {
    const auto q1 = desc.find('\'', at);
    const auto q2 = q1 == std::string::npos ? q1 : desc.find('\'', q1 + 1);
    if (q2 != std::string::npos) {
      std::string key = desc.substr(q1 + 1, q2 - q1 - 1);
      if (desc.compare(at + redefine.size(), 5, "table") != 0) {
        // toml++ 3.3 garbles a quoted key in this message ('"cocontroller.N" ' for
        // "controller.N"): the key as written, before the '=' of the line, instead.
        if (key.find_first_of("\" '") != std::string::npos) {
          std::string_view l = text;
          for (std::uint32_t n = 1; n < e.source().begin.line && !l.empty(); ++n) {
            const std::size_t nl = l.find('\n');
            l = nl == std::string_view::npos ? std::string_view() : l.substr(nl + 1);
          }
          l = l.substr(0, std::min(l.find('\n'), l.find('=')));
          while (!l.empty() && (l.front() == ' ' || l.front() == '\t')) l.remove_prefix(1);
          while (!l.empty() && (l.back() == ' ' || l.back() == '\t')) l.remove_suffix(1);
          if (!l.empty()) key = std::string(l);
        }
        const std::string table = header_before(text, e.source().begin.line);
        if (!table.empty()) key = table + '.' + key;
      }
      d.add(pos_of(e.source()), key,
            "defined twice (" + desc.substr(at) + "); each key, table and pilot profile may "
            "appear once");
      return;
    }
  }
  if (desc.rfind("Error", 0) == 0) desc[0] = 'e';
  d.add(pos_of(e.source()), "TOML syntax", desc);
}

// Deepest nesting a mixpilot TOML file may use: keys of tables of arrays of inline tables, a
// handful of levels; anything near this bound is not a settings file.
inline constexpr int kMaxTomlNesting = 32;

// Where `text` nests deeper than kMaxTomlNesting, before a parser sees it: toml++ recurses per
// dotted-key part and per table-header part and has no bound of its own there, so a key of
// 50 000 parts overflows the stack. Depth is that of the document's tree: one level per key
// part (of dotted keys, keys in inline tables and [table.header]s) and per array. Strings and
// comments are skipped;
// dots in values (numbers, dates) are not key parts. A text that is not TOML is left to the
// parser's own errors: only the depth is judged here.
inline std::optional<Pos> too_deep(std::string_view text) {
  enum class Ctx { key, value };
  struct Open {
    char c;     // '[' array, '{' inline table
    int parts;  // parts of the key whose value it opens
  };
  std::vector<Open> open;
  Ctx ctx = Ctx::key;
  int parts = 1;        // parts of the current key
  int outer = 0;        // levels of the open arrays and inline tables and of their keys
  bool header = false;  // inside a [table] or [[array.of.tables]] header
  std::uint32_t line = 1, col = 1;
  std::size_t i = 0;
  const auto advance = [&](std::size_t n) {
    for (std::size_t k = 0; k < n && i < text.size(); ++k, ++i) {
      if (text[i] == '\n') ++line, col = 1;
      else ++col;
    }
  };
  const auto skip_string = [&] {
    const char q = text[i];
    const std::string_view delim = text.substr(i, 3) == std::string_view(q == '"' ? "\"\"\"" : "'''")
                                       ? text.substr(i, 3)
                                       : text.substr(i, 1);
    advance(delim.size());
    while (i < text.size()) {
      if (q == '"' && text[i] == '\\') {
        advance(2);  // an escape, \" included
      } else if (text.substr(i, delim.size()) == delim) {
        advance(delim.size());
        return;
      } else if (delim.size() == 1 && text[i] == '\n') {
        return;  // unterminated: the parser reports it
      } else {
        advance(1);
      }
    }
  };
  const auto depth = [&] { return outer + parts; };
  const auto close = [&] {
    outer -= open.back().parts + (open.back().c == '[' ? 1 : 0);
    parts = open.back().parts;
    open.pop_back();
  };
  while (i < text.size()) {
    const char c = text[i];
    if (c == '#') {
      while (i < text.size() && text[i] != '\n') advance(1);
      continue;
    }
    if (c == '"' || c == '\'') {
      skip_string();
      continue;
    }
    const Pos here{line, col};
    if (header) {
      if (c == '.' && ++parts > kMaxTomlNesting) return here;
      if (c == ']' || c == '\n') header = false;
      advance(1);
      continue;
    }
    if (ctx == Ctx::key) {
      if (c == '[' && open.empty()) {  // a table header starts a line
        header = true;
        parts = 1;
        while (i < text.size() && text[i] == '[') advance(1);
        continue;
      }
      if (c == '.') {
        ++parts;
        if (depth() > kMaxTomlNesting) return here;
      } else if (c == '=') {
        ctx = Ctx::value;
      } else if (c == '}' && !open.empty() && open.back().c == '{') {
        close();  // an empty inline table
        ctx = Ctx::value;
      } else if (c == '\n' && open.empty()) {
        parts = 1;
      }
      advance(1);
      continue;
    }
    // Value context.
    if (c == '[' || c == '{') {
      open.push_back({c, parts});
      outer += parts + (c == '[' ? 1 : 0);
      parts = 0;
      if (depth() > kMaxTomlNesting) return here;
      if (c == '{') ctx = Ctx::key, parts = 1;
    } else if (c == ']' || c == '}') {
      if (!open.empty()) close();
    } else if (c == ',' && !open.empty() && open.back().c == '{') {
      ctx = Ctx::key;
      parts = 1;
    } else if (c == '\n' && open.empty()) {
      ctx = Ctx::key;
      parts = 1;
    }
    advance(1);
  }
  return std::nullopt;
}

// Parses TOML text; a syntax error becomes a diagnostic. No exception escapes.
inline bool parse_toml(std::string_view text, const std::string& source_name, Diagnostics& d,
                       toml::table& root) {
  // A byte-order mark and CR-only line ends are an editor's habit, not an error.
  const std::string normalized = normalize_text(text);
  text = normalized;
  if (const std::optional<Pos> at = too_deep(text)) {
    d.add(*at, "TOML syntax",
          "nested more than " + std::to_string(kMaxTomlNesting) +
              " levels deep (keys, tables and arrays); a mixpilot file needs a few");
    return false;
  }
  try {
    root = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    add_syntax_error(d, e, text);
    return false;
  } catch (const std::exception& e) {
    d.add(Pos{1, 1}, "TOML syntax", std::string("cannot be parsed: ") + e.what());
    return false;
  }
  return true;
}

// Parses `text` and reads it with read(root, diagnostics) into a scenario struct T; on any
// diagnostic returns nullopt with all of them in `error`. Sets T::source_path.
template <class T, class Read>
std::optional<T> parse_document(std::string_view text, const std::string& source_name,
                                std::string& error, Read read) {
  Diagnostics d(source_name);
  toml::table root;
  if (!parse_toml(text, source_name, d, root)) {
    error = d.str();
    return std::nullopt;
  }
  T value;
  try {
    value = read(root, d);
  } catch (const std::exception& e) {  // bad_alloc, filesystem_error: reported, never fatal
    d.add(Pos{1, 1}, "scenario", std::string("cannot be loaded: ") + e.what());
  }
  if (!d.empty()) {
    error = d.str();
    return std::nullopt;
  }
  value.source_path = source_name;
  error.clear();
  return value;
}

}  // namespace mixpilot::toml_read
