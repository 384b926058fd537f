#include "core/scenario_toml.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <sstream>
#include <system_error>
#include <utility>
#include <vector>

// Debian's toml++ is the compiled shared library, built with exceptions: this TU keeps them on
// (switching them off would select the noex ABI the library does not export) and catches
// toml::parse_error itself.
#include <toml++/toml.h>

namespace mixpilot {
namespace {

struct Pos {
  std::uint32_t line = 1;
  std::uint32_t col = 1;
};

Pos pos_of(const toml::source_region& r) { return {r.begin.line, r.begin.column}; }

// Collects `<file>:<line>:<col>: <key path>: <what>` lines; reported sorted by position.
class Diagnostics {
 public:
  explicit Diagnostics(std::string file) : file_(std::move(file)) {}

  void add(Pos p, std::string_view path, std::string_view what) {
    std::string text = file_ + ':' + std::to_string(p.line) + ':' + std::to_string(p.col) + ": ";
    text.append(path).append(": ").append(what);
    items_.push_back({p, std::move(text)});
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
std::string fmt(double v) {
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  std::string s(buf, r.ptr);
  if (s.find_first_of(".eni") == std::string::npos) s += ".0";
  return s;
}

std::string describe(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::string:
      return "the string \"" + n.as_string()->get() + '"';
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

std::size_t edit_distance(std::string_view a, std::string_view b) {
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

// Range checks: nullptr when fine, else what was expected.
using Check = const char* (*)(double);
using IntCheck = const char* (*)(std::int64_t);

const char* finite(double) { return nullptr; }  // non-finite values are rejected before checks
const char* positive(double v) { return v > 0 ? nullptr : "expected a positive number"; }
const char* non_negative(double v) { return v >= 0 ? nullptr : "expected a number >= 0"; }
const char* unit_open(double v) {
  return v > 0 && v < 1 ? nullptr : "expected a number in (0, 1)";
}
const char* unit_closed(double v) {
  return v >= 0 && v <= 1 ? nullptr : "expected a number in [0, 1]";
}
const char* tilt(double v) {
  return v > 0 && v < std::numbers::pi / 2 ? nullptr : "expected an angle in (0, pi/2) rad";
}
const char* at_least_1000(double v) { return v >= 1000 ? nullptr : "expected a number >= 1000"; }
const char* int_positive(std::int64_t v) { return v >= 1 ? nullptr : "expected an integer >= 1"; }
const char* int_non_negative(std::int64_t v) {
  return v >= 0 ? nullptr : "expected an integer >= 0";
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

  bool num(std::string_view key, double& out, Check check = finite, bool required = false) {
    const toml::node* n = take(key, required, "a number");
    return n && read_num(*n, path(key), out, check);
  }

  bool integer(std::string_view key, std::int64_t& out, IntCheck check, bool required = false) {
    const toml::node* n = take(key, required, "an integer");
    if (!n) return false;
    if (!n->is_integer()) {
      d_.add(pos_of(n->source()), path(key), "expected an integer, got " + describe(*n));
      return false;
    }
    const std::int64_t v = n->as_integer()->get();
    if (const char* e = check(v)) {
      d_.add(pos_of(n->source()), path(key), std::string(e) + ", got " + std::to_string(v));
      return false;
    }
    out = v;
    return true;
  }

  bool integer(std::string_view key, int& out, IntCheck check, bool required = false) {
    std::int64_t v = out;
    if (!integer(key, v, check, required)) return false;
    if (v > std::numeric_limits<int>::max()) {
      d_.add(pos(key), path(key), "expected an integer below 2^31, got " + std::to_string(v));
      return false;
    }
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
  bool vec(std::string_view key, Eigen::Matrix<double, n, 1>& out, Check check = finite,
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
                    check) && ok;
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
  bool read_num(const toml::node& n, const std::string& path, double& out, Check check) {
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
    if (const char* e = check(v)) {
      d_.add(pos_of(n.source()), path, std::string(e) + ", got " + describe(n));
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

void read_controller(Section s, MiControllerSettings& c, Diagnostics& d) {
  const bool n_ok = s.integer("N", c.N, int_positive) || !s.table() || !s.table()->get("N");
  s.num("dt", c.dt, positive);
  s.boolean("safety_constraints", c.safety_constraints);
  std::string form;
  if (s.choice("obstacle_form", form, {"lcl", "squared"})) {
    c.obstacle_form = form == "lcl" ? ObstacleForm::lcl : ObstacleForm::squared;
  }
  s.integer("max_constrained_obstacles", c.max_constrained_obstacles, int_non_negative);
  s.num("vehicle_radius", c.vehicle_radius, non_negative);
  s.num("slack_l1", c.slack_l1, non_negative);
  s.num("slack_l2", c.slack_l2, positive);  // keeps the slack Hessian positive definite

  Section w = s.sub("weights");
  w.vec("q_eta", c.weights.q_eta, non_negative);
  w.num("q_nu", c.weights.q_nu, non_negative);
  w.vec("q_e", c.weights.q_e, non_negative);
  w.num("r", c.weights.r, positive);  // the only input weight: the Riccati input pivots need it
  w.finish();

  Section ph = s.sub("ph");
  ph.num("r", c.ph.r, positive);
  const bool nb_given = ph.integer("N_b", c.ph.N_b, int_positive);
  ph.num("mu1", c.ph.mu1, unit_open);
  ph.num("mu2", c.ph.mu2, unit_closed);
  ph.num("theta2", c.ph.theta2, positive);
  ph.num("zeta", c.ph.zeta, positive);
  ph.num("initial_lambda", c.ph.initial_lambda, unit_closed);
  ph.finish();
  if (n_ok && c.ph.N_b > c.N && (nb_given || !ph.table() || !ph.table()->get("N_b"))) {
    d.add(ph.pos("N_b"), ph.path("N_b"),
          "expected at most controller.N = " + std::to_string(c.N) + ", got " +
              std::to_string(c.ph.N_b));
  }
  s.finish();
}

PilotProfile read_pilot(Section s, const std::string& name) {
  PilotProfile p;
  p.name = name;
  s.vec("q1", p.q1, non_negative);
  s.vec("q2", p.q2, non_negative);
  s.vec("q3", p.q3, non_negative);
  s.vec("q4", p.q4, non_negative);
  s.num("q5", p.q5, non_negative);
  s.num("r1", p.r1, positive);
  s.integer("N", p.N, int_positive);
  s.num("reaction_delay", p.reaction_delay, non_negative);
  s.num("max_tilt", p.max_tilt, tilt);
  s.finish();
  return p;
}

// First time in [0, duration] at which the helix leaves the box, if any. The coordinates are
// sinusoids and a line: sampling at ≤ 1 mrad of phase misses at most ~R·5e-7 m of excursion.
std::optional<double> helix_leaves(const HelixReference& h, double duration,
                                   const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const int n = std::max(1000, int(std::ceil(std::abs(h.angular_rate) * duration / 1e-3)));
  for (int i = 0; i <= n; ++i) {
    const double t = duration * i / n;
    const Eigen::Vector3d p = h.position(t);
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) return t;
  }
  return std::nullopt;
}

std::string vec_text(const Eigen::Vector3d& v) {
  return '[' + fmt(v.x()) + ", " + fmt(v.y()) + ", " + fmt(v.z()) + ']';
}

// A computed (not user-typed) quantity, to the millimetre / millisecond.
std::string approx(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

Scenario read_scenario(const toml::table& root, Diagnostics& d) {
  Scenario sc;
  Section s(d, &root, "", Pos{1, 1});
  s.string("name", sc.name, true);
  const bool mode_ok = s.choice("mode", sc.mode, {"mixed_initiative"}, true);
  const bool model_ok = s.choice("model", sc.model, {"mikrokopter", "crazyflie", "pendubot"}, true);
  if (mode_ok && model_ok && sc.mode == "mixed_initiative" && sc.model != "mikrokopter") {
    d.add(s.pos("model"), "model",
          "expected \"mikrokopter\" for mode \"mixed_initiative\" (SPEC 5.4), got \"" + sc.model +
              '"');
  }
  const bool duration_ok = s.num("duration", sc.duration, positive) || !root.get("duration");
  const bool pilot_given = s.string("pilot", sc.default_pilot);

  read_controller(s.sub("controller"), sc.controller, d);

  Section ref = s.sub("reference");
  Eigen::Vector2d center = sc.reference.center;
  if (ref.vec("center", center)) sc.reference.center = center;
  ref.num("radius", sc.reference.radius, non_negative);
  ref.num("start_height", sc.reference.start_height);
  ref.num("climb_rate", sc.reference.climb_rate);
  ref.num("angular_rate", sc.reference.angular_rate);
  ref.num("phase", sc.reference.phase);
  ref.finish();

  Section arena = s.sub("arena");
  bool box_ok = (arena.vec("min", sc.arena.min) || !arena.table() || !arena.table()->get("min")) &
                (arena.vec("max", sc.arena.max) || !arena.table() || !arena.table()->get("max"));
  if (box_ok && !(sc.arena.min.array() < sc.arena.max.array()).all()) {
    d.add(arena.pos("max"), arena.path("max"),
          "expected every component above arena.min = " + vec_text(sc.arena.min) + ", got " +
              vec_text(sc.arena.max));
    box_ok = false;
  }
  if (const toml::node* obs = arena.take("obstacles", false, "")) {
    const toml::array* a = obs->as_array();
    if (!a || !a->is_array_of_tables()) {
      d.add(pos_of(obs->source()), arena.path("obstacles"),
            "expected an array of tables ([[arena.obstacles]]), got " + describe(*obs));
    } else {
      for (std::size_t i = 0; i < a->size(); ++i) {
        const toml::node& e = *a->get(i);
        Section o(d, e.as_table(), arena.path("obstacles") + '[' + std::to_string(i) + ']',
                  pos_of(e.source()));
        Obstacle ob;
        const bool c_ok = o.vec("center", ob.center, finite, true);
        o.num("radius", ob.radius, positive, true);
        o.finish();
        if (c_ok && box_ok &&
            ((ob.center.array() < sc.arena.min.array()).any() ||
             (ob.center.array() > sc.arena.max.array()).any())) {
          d.add(o.pos("center"), o.path("center"),
                "expected a point inside the arena " + vec_text(sc.arena.min) + " .. " +
                    vec_text(sc.arena.max) + ", got " + vec_text(ob.center));
        }
        sc.arena.obstacles.push_back(ob);
      }
    }
  }
  arena.finish();
  // The reference must stay flyable: the controller's soft walls would fight it otherwise.
  if (box_ok && duration_ok) {
    if (const auto t = helix_leaves(sc.reference, sc.duration, sc.arena.min, sc.arena.max)) {
      const Eigen::Vector3d p = sc.reference.position(*t);
      d.add(ref.pos(), "reference",
            "expected a helix inside the arena over [0, duration], but it leaves it at t = " +
                approx(*t) + " s, at (" + approx(p.x()) + ", " + approx(p.y()) + ", " +
                approx(p.z()) + ")");
    }
  }

  // [pilots.<name>]: one table per profile; TOML itself rejects a name given twice.
  Section pilots = s.sub("pilots");
  if (pilots.table()) {
    for (auto&& [k, v] : *pilots.table()) {
      const std::string name(k.str());
      if (!v.is_table()) {
        d.add(pos_of(v.source()), pilots.path(name),
              "expected a table of pilot weights ([pilots." + name + "]), got " + describe(v));
        continue;
      }
      sc.pilots[name] = read_pilot(Section(d, v.as_table(), pilots.path(name), pos_of(v.source())),
                                   name);
    }
  }
  // "reckless" (full-tilt inputs, no NMPC) is always available; its max_tilt may be overridden.
  if (!sc.pilots.count("reckless")) sc.pilots["reckless"] = PilotProfile{.name = "reckless"};
  if (!sc.pilots.count(sc.default_pilot)) {
    std::string names;
    for (const auto& [n, p] : sc.pilots) names += (names.empty() ? "" : ", ") + ('"' + n + '"');
    d.add(pilot_given ? s.pos("pilot") : Pos{1, 1}, "pilot",
          "expected the name of a profile in [pilots] (" + names + "), got \"" +
              sc.default_pilot + '"' + (pilot_given ? "" : " (the default)"));
  }

  Section plant = s.sub("plant");
  const bool rate_given = plant.num("rate_hz", sc.plant.rate_hz, at_least_1000);
  plant.num("input_delay", sc.plant.input_delay, non_negative);
  plant.num("position_noise", sc.plant.position_noise, non_negative);
  std::int64_t seed = std::int64_t(sc.plant.seed);
  if (plant.integer("seed", seed, int_non_negative)) sc.plant.seed = std::uint64_t(seed);
  plant.finish();
  // The plant takes a whole number of RK4 substeps per control step.
  const double substeps = sc.controller.dt * sc.plant.rate_hz;
  if (sc.plant.rate_hz >= 1000 && sc.controller.dt > 0 &&
      std::abs(substeps - std::round(substeps)) > 1e-9 * substeps) {
    d.add(rate_given ? plant.pos("rate_hz") : plant.pos(), plant.path("rate_hz"),
          "expected a rate giving a whole number of substeps per control step, got controller.dt "
          "* rate_hz = " + fmt(substeps));
  }

  s.finish();
  return sc;
}

// Name of the last `[table]` or `[[table]]` header before `line` (1-based), "" if none.
std::string header_before(std::string_view text, std::uint32_t line) {
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
void add_syntax_error(Diagnostics& d, const toml::parse_error& e, std::string_view text) {
  std::string desc(e.description());
  constexpr std::string_view redefine = "cannot redefine existing ";
  if (const auto at = desc.find(redefine); at != std::string::npos) {
    const auto q1 = desc.find('\'', at);
    const auto q2 = q1 == std::string::npos ? q1 : desc.find('\'', q1 + 1);
    if (q2 != std::string::npos) {
      std::string key = desc.substr(q1 + 1, q2 - q1 - 1);
      if (desc.compare(at + redefine.size(), 5, "table") != 0) {
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

}  // namespace

std::optional<Scenario> parse_scenario(std::string_view text, const std::string& source_name,
                                       std::string& error) {
  Diagnostics d(source_name);
  toml::table root;
  try {
    root = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    add_syntax_error(d, e, text);
    error = d.str();
    return std::nullopt;
  }
  Scenario sc = read_scenario(root, d);
  if (!d.empty()) {
    error = d.str();
    return std::nullopt;
  }
  sc.source_path = source_name;
  sc.source_text = std::string(text);
  error.clear();
  return sc;
}

std::optional<Scenario> load_scenario(const std::string& path, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = path + ": cannot open file (" + std::error_code(errno, std::generic_category()).message() +
            ')';
    return std::nullopt;
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) {
    error = path + ": read error";
    return std::nullopt;
  }
  return parse_scenario(text.str(), path, error);
}

}  // namespace mixpilot
