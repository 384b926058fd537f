#include "core/scenario/sweep.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <system_error>
#include <utility>

#include "core/base/content_hash.hpp"
#include "core/base/input_file.hpp"
#include "core/base/json.hpp"
#include "core/base/toml_read.hpp"
#include "core/scenario/data_files.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/scenario/scenario_value_toml.hpp"

namespace mixpilot {

namespace {

namespace fs = std::filesystem;
using namespace toml_read;  // NOLINT: the reading vocabulary of this file

// The flight options of `fly` a sweep may set (not scenario keys).
constexpr const char* kAssist = "assist";
constexpr const char* kFloor = "floor";
constexpr const char* kCeiling = "ceiling";
bool flight_option(std::string_view key) { return key == kAssist || key == kFloor || key == kCeiling; }

// A path's characters and a file name's: letters, digits, _ and -.
bool bare_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

// ---- the sweep file -------------------------------------------------------------------------

struct Axis {
  std::string key;
  std::vector<SweepSetting> values;
};

// The keys of table `t` (nested tables joined with '.') with their values, in file order; for
// a grid a value is the array of its alternatives.
void flatten(const toml::table& t, const std::string& prefix,
             std::vector<std::pair<std::string, const toml::node*>>& out) {
  for (auto&& [k, v] : t) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + '.' + std::string(k.str());
    if (v.is_table()) flatten(*v.as_table(), key, out);
    else out.emplace_back(key, &v);
  }
}

void sort_by_position(std::vector<std::pair<std::string, const toml::node*>>& keys) {
  std::stable_sort(keys.begin(), keys.end(), [](const auto& a, const auto& b) {
    const Pos pa = pos_of(a.second->source()), pb = pos_of(b.second->source());
    return std::pair(pa.line, pa.col) < std::pair(pb.line, pb.col);
  });
}

class SweepReader {
 public:
  SweepReader(Diagnostics& d, const std::string& source) : d_(d), source_(source) {}

  std::optional<SweepPlan> read(const toml::table& root) {
    SweepPlan plan;
    plan.file = source_;
    plan.name = fs::path(source_).stem().string();
    Section top(d_, &root, "", Pos{1, 1});
    std::string scenario;
    const bool have_scenario = top.string("scenario", scenario, true);
    const Pos scenario_at = top.pos("scenario");
    plan.scenario_line = scenario_at.line;
    plan.scenario_column = scenario_at.col;
    double duration = 0.0;
    if (top.num("duration", duration, kDuration)) plan.duration = duration;
    duration_at_ = top.pos("duration");
    top.boolean("record", plan.record);
    const toml::node* pilots = top.take("pilots", false, "");
    const toml::node* seeds = top.take("seeds", false, "");
    const toml::node* set = top.take("set", false, "");
    const toml::node* grid = top.take("grid", false, "");
    const toml::node* runs = top.take("runs", false, "");
    top.finish();
    if (!have_scenario || !load_base(scenario, scenario_at, plan)) return std::nullopt;

    // [set]
    if (set) {
      if (!set->is_table()) {
        d_.add(pos_of(set->source()), "set", "expected a table of key = value, got " + describe(*set));
      } else {
        std::vector<std::pair<std::string, const toml::node*>> keys;
        flatten(*set->as_table(), "", keys);
        sort_by_position(keys);
        for (const auto& [key, node] : keys) {
          SweepSetting s;
          if (setting(key, *node, "set." + key, s)) plan.fixed.push_back(std::move(s));
        }
      }
    }
    // [grid], then pilots and seeds: the axes, slowest first.
    std::vector<Axis> axes;
    if (grid) {
      if (!grid->is_table()) {
        d_.add(pos_of(grid->source()), "grid",
               "expected a table of key = [values...], got " + describe(*grid));
      } else if (grid->as_table()->empty()) {
        d_.add(pos_of(grid->source()), "grid",
               "an empty grid: expected key = [values...] for each key to vary");
      } else {
        std::vector<std::pair<std::string, const toml::node*>> keys;
        flatten(*grid->as_table(), "", keys);
        sort_by_position(keys);
        for (const auto& [key, node] : keys) axis(key, *node, "grid." + key, axes);
      }
    }
    if (pilots) {
      if (mode_ != "mixed_initiative") {
        d_.add(pos_of(pilots->source()), "pilots",
               "pilot profiles fly mixed_initiative scenarios; " + plan.scenario_file + " is " +
                   (mode_.empty() ? "of no known mode" : mode_));
      } else {
        check_strings(*pilots, "pilots");
        axis("pilot", *pilots, "pilots", axes);
      }
    }
    if (seeds) {
      if (mode_ != "mixed_initiative") {
        d_.add(pos_of(seeds->source()), "seeds",
               "seeds set plant.seed, the noise seed of mixed_initiative scenarios; " +
                   plan.scenario_file + " is " + (mode_.empty() ? "of no known mode" : mode_) +
                   ", which has none (it flies the same flight every time)");
      } else {
        axis("plant.seed", *seeds, "seeds", axes);
      }
    }
    // [[runs]]
    std::vector<std::vector<SweepSetting>> entries;
    if (runs) {
      const toml::array* a = runs->as_array();
      if (!a || !runs->is_array_of_tables()) {
        d_.add(pos_of(runs->source()), "runs",
               "expected [[runs]] tables of key = value, got " + describe(*runs));
      } else if (a->empty()) {
        d_.add(pos_of(runs->source()), "runs", "an empty list of runs");
      } else {
        for (std::size_t i = 0; i < a->size(); ++i) {
          const toml::table& t = *a->get(i)->as_table();
          const std::string where = "runs[" + std::to_string(i) + "]";
          if (t.empty()) {
            d_.add(pos_of(t.source()), where, "an empty run: expected key = value to set");
            continue;
          }
          std::vector<std::pair<std::string, const toml::node*>> keys;
          flatten(t, "", keys);
          sort_by_position(keys);
          std::vector<SweepSetting> entry;
          for (const auto& [key, node] : keys) {
            SweepSetting s;
            if (setting(key, *node, where + '.' + key, s)) entry.push_back(std::move(s));
          }
          entries.push_back(std::move(entry));
        }
      }
    }
    if (!grid && !runs && !pilots && !seeds)
      d_.add(Pos{1, 1}, "sweep",
             "nothing to sweep: expected a [grid], [[runs]], pilots or seeds (docs/sweeps.md)");
    check_overlaps(plan, axes, entries);
    if (!d_.empty()) return std::nullopt;

    // The plan: each listed run (or the base) × every combination of the axes.
    std::size_t combos = entries.empty() ? 1 : entries.size();
    for (const Axis& a : axes) {
      if (combos > kMaxSweepRuns / std::max<std::size_t>(1, a.values.size())) {
        combos = kMaxSweepRuns + 1;
        break;
      }
      combos *= a.values.size();
    }
    if (combos > kMaxSweepRuns) {
      d_.add(Pos{1, 1}, "sweep",
             "expands to more than " + std::to_string(kMaxSweepRuns) + " runs; split it into "
             "several sweep files");
      return std::nullopt;
    }
    for (const auto& e : entries)
      for (const SweepSetting& s : e)
        if (std::find(plan.columns.begin(), plan.columns.end(), s.key) == plan.columns.end())
          plan.columns.push_back(s.key);
    for (const Axis& a : axes) plan.columns.push_back(a.key);
    if (entries.empty()) entries.emplace_back();
    std::vector<std::size_t> at(axes.size(), 0);
    for (const auto& entry : entries) {
      std::fill(at.begin(), at.end(), 0);
      while (true) {
        SweepRun run;
        run.index = plan.runs.size();
        std::vector<SweepSetting> params = entry;
        for (std::size_t a = 0; a < axes.size(); ++a) params.push_back(axes[a].values[at[a]]);
        // In column order.
        for (const std::string& c : plan.columns)
          for (const SweepSetting& s : params)
            if (s.key == c) run.parameters.push_back(s);
        plan.runs.push_back(std::move(run));
        std::size_t a = axes.size();
        while (a > 0 && ++at[a - 1] == axes[a - 1].values.size()) at[--a] = 0;
        if (a == 0) break;
      }
    }
    name_runs(plan);
    for (SweepRun& run : plan.runs)
      if (!write_run(plan, run)) break;
    if (!d_.empty()) return std::nullopt;
    notes(plan);
    plan.sha256 = plan_hash(plan);
    return plan;
  }

 private:
  // The base scenario named by `scenario`: a shipped scenario's name or a .toml path relative
  // to the sweep file.
  bool load_base(const std::string& scenario, Pos at, SweepPlan& plan) {
    std::string file;
    if (scenario.ends_with(".toml")) {
      const fs::path p(scenario);
      file = (p.is_absolute() ? p : fs::path(source_).parent_path() / p).lexically_normal().string();
    } else {
      const bool plain = std::all_of(scenario.begin(), scenario.end(), [](char c) {
        return bare_key_char(c) || c == '.';
      }) && scenario != "." && scenario != "..";
      if (!plain) {
        d_.add(at, "scenario",
               "expected a shipped scenario's name (letters, digits, _ - .) or a path ending in "
               ".toml, got \"" + printable(scenario) + '"');
        return false;
      }
      std::string why;
      const std::string dir = data_dir(&why);
      if (dir.empty()) {
        d_.add(at, "scenario", "a shipped scenario's name, but " + why);
        return false;
      }
      file = (fs::path(dir) / "scenarios" / (scenario + ".toml")).string();
      std::error_code ec;
      if (!fs::exists(file, ec)) {
        d_.add(at, "scenario",
               "expected a shipped scenario's name (a file in " + dir +
                   "/scenarios) or a path ending in .toml, got \"" + printable(scenario) + '"');
        return false;
      }
    }
    std::error_code ec;
    const fs::path abs = fs::absolute(file, ec);
    plan.scenario_file = (ec ? fs::path(file) : abs).lexically_normal().string();
    std::string error;
    if (!read_text_file(plan.scenario_file, base_text_, error)) {
      d_.add(at, "scenario", "cannot be read: " + error);
      return false;
    }
    base_text_ = normalize_text(base_text_);
    plan.scenario_sha256 = sha256_hex(base_text_);
    Diagnostics sd(plan.scenario_file);
    toml::table parsed;
    if (!parse_toml(base_text_, plan.scenario_file, sd, parsed)) {
      d_.add(at, "scenario", "is not a scenario that loads: " + sd.str());
      return false;
    }
    base_ = ScenarioEdit::open(base_text_, plan.scenario_file, error);
    if (!base_) {
      d_.add(at, "scenario", "is not a scenario that loads: " + error);
      return false;
    }
    const std::optional<std::string> mode = scenario_mode(base_text_, plan.scenario_file, error);
    if (!mode) {
      d_.add(at, "scenario", "is not a scenario that loads: " + error);
      return false;
    }
    mode_ = *mode;
    return true;
  }

  // One key = value of [set] or a run; false (with a diagnostic) when it cannot be one.
  bool setting(const std::string& key, const toml::node& node, const std::string& where,
               SweepSetting& out) {
    out.key = key;
    const Pos p = pos_of(node.source());
    out.line = p.line;
    out.column = p.col;
    std::string why;
    if (!scenario_value_of(node, out.value, why)) {
      d_.add(p, where, why);
      return false;
    }
    return check_key(out, where);
  }

  // A key = [values...] of the grid (or pilots, seeds): an axis.
  void axis(const std::string& key, const toml::node& node, const std::string& where,
            std::vector<Axis>& axes) {
    const toml::array* a = node.as_array();
    if (!a) {
      d_.add(pos_of(node.source()), where,
             "expected an array of the values to try, got " + describe(node) +
                 (where.starts_with("grid.") ? " (a value for every run goes in [set])" : ""));
      return;
    }
    if (a->empty()) {
      d_.add(pos_of(node.source()), where, "an empty list of values: expected at least one");
      return;
    }
    Axis axis{key, {}};
    bool ok = true;
    for (std::size_t i = 0; i < a->size() && ok; ++i) {  // the first problem is enough
      SweepSetting s;
      ok = setting(key, *a->get(i), where + '[' + std::to_string(i) + ']', s);
      for (const SweepSetting& other : axis.values)
        if (ok && other.value.toml() == s.value.toml()) {
          d_.add(pos_of(a->get(i)->source()), where + '[' + std::to_string(i) + ']',
                 "the value " + s.value.toml() + " is given twice");
          ok = false;
        }
      axis.values.push_back(std::move(s));
    }
    if (ok) axes.push_back(std::move(axis));
  }

  void check_strings(const toml::node& node, const std::string& where) {
    const toml::array* a = node.as_array();
    if (!a) return;  // axis() says so
    for (std::size_t i = 0; i < a->size(); ++i) {
      const toml::node& e = *a->get(i);
      if (!e.is_string() || e.as_string()->get().empty())
        d_.add(pos_of(e.source()), where + '[' + std::to_string(i) + ']',
               "expected a pilot profile's name, got " + describe(e));
    }
  }

  // The key names something the scenario can take, with a value of its kind.
  bool check_key(const SweepSetting& s, const std::string& where) {
    const Pos p{s.line, s.column};
    using T = ScenarioValue::Type;
    if (flight_option(s.key)) {
      if (mode_ != "mixed_initiative") {
        d_.add(p, where, s.key + " (fly --" + s.key + ") is for mixed_initiative scenarios; the "
               "base scenario is " + mode_);
        return false;
      }
      if (s.key == kAssist) {
        if (s.value.type != T::string || (s.value.string != "on" && s.value.string != "off")) {
          d_.add(p, where, "expected \"on\" or \"off\", got " + s.value.toml());
          return false;
        }
        return true;
      }
      const double x = s.value.type == T::integer  ? double(s.value.integer)
                       : s.value.type == T::number ? s.value.number
                                                   : std::nan("");
      if (!(x >= 0.0 && x <= 1.0)) {
        d_.add(p, where, "expected a number from 0 to 1 (the authority λ), got " + s.value.toml());
        return false;
      }
      return true;
    }
    std::string why;
    if (!base_->check(s.key, s.value, why)) {
      d_.add(p, where, why);
      return false;
    }
    return true;
  }

  // No key given twice, nor one inside another ("plant.start" and "plant.start[2]").
  void check_overlaps(const SweepPlan& plan, const std::vector<Axis>& axes,
                      const std::vector<std::vector<SweepSetting>>& entries) {
    struct Given {
      std::string key, where;
      Pos at;
    };
    std::vector<Given> outside_runs;
    for (const SweepSetting& s : plan.fixed) outside_runs.push_back({s.key, "[set]", {s.line, s.column}});
    for (const Axis& a : axes)
      outside_runs.push_back({a.key, a.key == "pilot" ? "pilots or [grid]"
                                     : a.key == "plant.seed" ? "seeds or [grid]" : "[grid]",
                              {a.values[0].line, a.values[0].column}});
    if (plan.duration)
      outside_runs.push_back({"duration", "the top-level duration", duration_at_});
    const auto inside = [](const std::string& a, const std::string& b) {
      return a == b || (b.size() > a.size() && b.compare(0, a.size(), a) == 0 &&
                        (b[a.size()] == '.' || b[a.size()] == '['));
    };
    const auto clash = [&](const Given& x, const Given& y) {
      if (!inside(x.key, y.key) && !inside(y.key, x.key)) return;
      const Given& later = std::pair(x.at.line, x.at.col) > std::pair(y.at.line, y.at.col) ? x : y;
      const Given& other = &later == &x ? y : x;
      d_.add(later.at, later.key,
             x.key == y.key ? "given in " + other.where + " and again in " + later.where +
                                  ": expected once"
                            : "overlaps " + other.key + " (" + other.where + "): expected a key "
                              "and none inside it");
    };
    for (std::size_t i = 0; i < outside_runs.size(); ++i)
      for (std::size_t j = i + 1; j < outside_runs.size(); ++j) clash(outside_runs[i], outside_runs[j]);
    for (const auto& e : entries) {
      std::vector<Given> mine;
      for (const SweepSetting& s : e) mine.push_back({s.key, "this [[runs]] entry", {s.line, s.column}});
      for (std::size_t i = 0; i < mine.size(); ++i) {
        for (std::size_t j = i + 1; j < mine.size(); ++j) clash(mine[i], mine[j]);
        for (const Given& g : outside_runs) clash(mine[i], g);
      }
    }
  }

  // Ids: the index, then each parameter as label=value; a label is the key's last part
  // ("rtt" for plant.rtt), or the whole key where two columns would share one.
  static void name_runs(SweepPlan& plan) {
    std::vector<std::string> labels;
    for (const std::string& c : plan.columns) {
      labels.push_back(key_label(c));
    }
    const std::vector<std::string> short_labels = labels;
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (std::count(short_labels.begin(), short_labels.end(), short_labels[i]) > 1)
        labels[i] = plan.columns[i];
    for (SweepRun& run : plan.runs) {
      const std::string index = std::to_string(run.index);
      std::string name;
      for (const SweepSetting& s : run.parameters) {
        const std::size_t c = std::size_t(
            std::find(plan.columns.begin(), plan.columns.end(), s.key) - plan.columns.begin());
        std::string value;
        if (s.value.type == ScenarioValue::Type::array) {
          for (std::size_t k = 0; k < s.value.items.size(); ++k)
            value += (k ? "_" : "") + s.value.items[k].text();
        } else {
          value = s.value.text();
        }
        name += '-' + labels[c] + '=' + value;
      }
      // File-name safe, whatever a string value holds.
      for (char& ch : name)
        if (!bare_key_char(ch) && ch != '.' && ch != '=' && ch != '+') ch = '_';
      if (name.size() > 120) name.resize(120);
      // Zero-padded to 4 digits (kMaxSweepRuns): the ids sort in plan order.
      run.id = std::string(index.size() < 4 ? 4 - index.size() : 0, '0') + index + name;
    }
  }

  // The run's scenario text: [set] and its parameters written into the base text.
  bool write_run(SweepPlan& plan, SweepRun& run) {
    ScenarioEdit patch = *base_;
    std::string said;
    std::vector<const SweepSetting*> all;
    for (const SweepSetting& s : plan.fixed) all.push_back(&s);
    for (const SweepSetting& s : run.parameters) all.push_back(&s);
    run.duration = plan.duration;
    for (const SweepSetting* s : all) {
      said += (said.empty() ? "" : ", ") + s->key + " = " + s->value.toml();
      if (s->key == kAssist) {
        run.assist = s->value.string == "off" ? Assistance::off : Assistance::on;
        continue;
      }
      if (s->key == kFloor || s->key == kCeiling) {
        const double x = s->value.type == ScenarioValue::Type::integer ? double(s->value.integer)
                                                                    : s->value.number;
        (s->key == kFloor ? run.bounds.floor : run.bounds.ceiling) = x;
        continue;
      }
      std::string why;
      if (!patch.set(s->key, s->value, why)) {
        d_.add(Pos{s->line, s->column}, s->key, why);
        return false;
      }
    }
    if (!run.bounds.valid()) {
      const SweepSetting* f = nullptr;
      for (const SweepSetting* s : all)
        if (s->key == kFloor) f = s;
      d_.add(f ? Pos{f->line, f->column} : Pos{1, 1}, kFloor,
             "floor " + shortest(run.bounds.floor) + " above ceiling " +
                 shortest(run.bounds.ceiling) + " in run " + run.id + ": expected floor <= ceiling");
      return false;
    }
    const std::string body = patch.result();
    run.scenario_text = "# " + fs::path(plan.scenario_file).filename().string() + " in sweep " +
                        plan.name + ", run " + run.id + (said.empty() ? "" : ": " + said) + "\n" +
                        body;
    // The text says what was asked: read back, every value where it belongs.
    Diagnostics check(plan.scenario_file);
    toml::table parsed;
    std::string why;
    std::optional<ScenarioEdit> written;
    if (!parse_toml(run.scenario_text, plan.scenario_file, check, parsed) ||
        !(written = ScenarioEdit::open(run.scenario_text, plan.scenario_file, why))) {
      const SweepSetting* s = all.empty() ? nullptr : all.back();
      d_.add(s ? Pos{s->line, s->column} : Pos{1, 1}, s ? s->key : "sweep",
             "cannot be written into " + plan.scenario_file + " (run " + run.id + "): " +
                 check.str() + "; give its table a [header] in the scenario");
      return false;
    }
    for (const SweepSetting* s : all) {
      if (flight_option(s->key)) continue;
      if (!written->holds(s->key, s->value)) {
        d_.add(Pos{s->line, s->column}, s->key,
               "could not be written into " + plan.scenario_file + " (run " + run.id + ")");
        return false;
      }
    }
    return true;
  }

  // Seeds without noise fly one flight.
  void notes(SweepPlan& plan) const {
    if (std::find(plan.columns.begin(), plan.columns.end(), "plant.seed") == plan.columns.end())
      return;
    for (const SweepRun& run : plan.runs) {
      toml::table t;
      Diagnostics d(plan.scenario_file);
      if (!parse_toml(run.scenario_text, plan.scenario_file, d, t)) continue;
      const std::optional<double> noise = t["plant"]["position_noise"].value<double>();
      if (!noise || *noise == 0.0) {
        plan.notes.push_back("seeds vary plant.seed, which draws the position noise, but "
                             "plant.position_noise is 0 in run " + run.id +
                             ": its seeds all fly the same flight (set plant.position_noise "
                             "in [set] or [grid])");
        return;
      }
    }
  }

  static std::string plan_hash(const SweepPlan& plan) {
    std::string all = "mixpilot sweep plan 1\nrecord " + std::string(plan.record ? "true" : "false") + '\n';
    for (const SweepRun& run : plan.runs) {
      // The scenario without its first line, which names the sweep (its file's name) and the
      // run: what flies, not what it is called.
      const std::string_view text = run.scenario_text;
      const std::string_view body = text.substr(std::min(text.size(), text.find('\n') + 1));
      all += "run " + run.id + "\nduration " + (run.duration ? shortest(*run.duration) : "-") +
             "\nassist " + (run.assist == Assistance::off ? "off" : "on") + "\nbounds " +
             shortest(run.bounds.floor) + ' ' + shortest(run.bounds.ceiling) + "\nscenario " +
             std::to_string(body.size()) + '\n' + std::string(body) + '\n';
    }
    return sha256_hex(all);
  }

  Diagnostics& d_;
  std::string source_;
  std::string base_text_;
  std::optional<ScenarioEdit> base_;  // the base scenario, and the runs' edits of it
  std::string mode_;
  Pos duration_at_;
};

}  // namespace

std::optional<SweepPlan> parse_sweep(std::string_view text, const std::string& source_name,
                                     std::string& error) {
  Diagnostics d(source_name);
  toml::table root;
  if (!parse_toml(text, source_name, d, root)) {
    error = d.str();
    return std::nullopt;
  }
  std::optional<SweepPlan> plan;
  try {
    SweepReader reader(d, source_name);
    plan = reader.read(root);
  } catch (const std::exception& e) {  // bad_alloc, filesystem_error: reported, never fatal
    d.add(Pos{1, 1}, "sweep", std::string("cannot be read: ") + e.what());
    plan.reset();
  }
  if (!plan || !d.empty()) {
    error = d.empty() ? source_name + ": cannot be read" : d.str();
    return std::nullopt;
  }
  error.clear();
  return plan;
}

std::optional<SweepPlan> load_sweep(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_sweep(text, path, error);
}

std::string sweep_plan_json(const SweepPlan& plan, std::string_view version) {
  const auto parameters = [](const std::vector<SweepSetting>& settings) {
    std::string out = "{";
    for (std::size_t i = 0; i < settings.size(); ++i)
      out += (i ? ", " : "") + json_quote(settings[i].key) + ": " + settings[i].value.json();
    return out + '}';
  };
  std::error_code ec;
  const fs::path abs = fs::absolute(plan.file, ec);
  std::string out = "{\n";
  out += "  \"format\": \"mixpilot sweep plan 1\",\n";
  out += "  \"sweep\": " + json_quote(plan.name) + ",\n";
  out += "  \"sweep_file\": " + json_quote((ec ? fs::path(plan.file) : abs).lexically_normal().string()) + ",\n";
  out += "  \"scenario\": " + json_quote(plan.scenario_file) + ",\n";
  out += "  \"scenario_sha256\": " + json_quote(plan.scenario_sha256) + ",\n";
  out += "  \"plan_sha256\": " + json_quote(plan.sha256) + ",\n";
  out += "  \"version\": " + json_quote(version) + ",\n";
  out += "  \"duration_s\": " + (plan.duration ? shortest(*plan.duration) : std::string("null")) + ",\n";
  out += "  \"record\": " + std::string(plan.record ? "true" : "false") + ",\n";
  out += "  \"set\": " + parameters(plan.fixed) + ",\n";
  out += "  \"columns\": [";
  for (std::size_t i = 0; i < plan.columns.size(); ++i)
    out += (i ? ", " : "") + json_quote(plan.columns[i]);
  out += "],\n";
  out += "  \"runs_total\": " + std::to_string(plan.runs.size()) + ",\n";
  out += "  \"runs\": [";
  for (std::size_t i = 0; i < plan.runs.size(); ++i) {
    const SweepRun& r = plan.runs[i];
    out += std::string(i ? "," : "") + "\n    {\"index\": " + std::to_string(r.index) +
           ", \"id\": " + json_quote(r.id) + ", \"parameters\": " + parameters(r.parameters) + '}';
  }
  out += "\n  ]\n}\n";
  return out;
}

std::vector<std::string> explain_run_error(const SweepPlan& plan, const SweepRun& run,
                                           const std::string& loader_error) {
  const auto at = [&](std::uint32_t line, std::uint32_t col) {
    return plan.file + ':' + std::to_string(line) + ':' + std::to_string(col) + ": ";
  };
  std::string settings;
  for (const SweepSetting& s : plan.fixed)
    settings += (settings.empty() ? "" : ", ") + s.key + " = " + s.value.toml();
  for (const SweepSetting& s : run.parameters)
    settings += (settings.empty() ? "" : ", ") + s.key + " = " + s.value.toml();
  std::vector<std::string> out;
  std::size_t from = 0;
  while (from < loader_error.size()) {
    std::size_t eol = loader_error.find('\n', from);
    if (eol == std::string::npos) eol = loader_error.size();
    const std::string line = loader_error.substr(from, eol - from);
    from = eol + 1;
    if (line.empty()) continue;
    // "<scenario>:<line>:<col>: <key>: <what>" or "<scenario>: <what>": the positions are the
    // run's text's, not the file's; the key says what it is about.
    std::string rest = line;
    if (rest.starts_with(plan.scenario_file + ':')) {
      rest = rest.substr(plan.scenario_file.size() + 1);
      std::size_t i = 0;
      int fields = 0;
      while (fields < 2) {
        const std::size_t d0 = i;
        while (i < rest.size() && rest[i] >= '0' && rest[i] <= '9') ++i;
        if (i == d0 || i >= rest.size() || rest[i] != ':') break;
        ++i;
        ++fields;
      }
      if (fields == 2) rest = rest.substr(i);
      while (!rest.empty() && rest[0] == ' ') rest.erase(0, 1);
    }
    const std::size_t colon = rest.find(": ");
    const std::string key = colon == std::string::npos ? "" : rest.substr(0, colon);
    // The setting the complaint is about: its key, a part of its value (reference.center[1]),
    // or a table it adds (nowhere.x: "nowhere: unknown key").
    const auto within = [](const std::string& inner, const std::string& outer) {
      return inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
             (inner[outer.size()] == '[' || inner[outer.size()] == '.');
    };
    const SweepSetting* match = nullptr;
    for (const auto* list : {&run.parameters, &plan.fixed})
      for (const SweepSetting& s : *list)
        if (!match && !key.empty() && (key == s.key || within(key, s.key) || within(s.key, key)))
          match = &s;
    if (match) {
      out.push_back(at(match->line, match->column) + rest);
    } else {
      out.push_back(at(plan.scenario_line, plan.scenario_column) + "scenario: " +
                    plan.scenario_file + (settings.empty() ? "" : " with " + settings) + ": " +
                    rest);
    }
    out.back() = escape_controls(out.back());
  }
  return out;
}

}  // namespace mixpilot
