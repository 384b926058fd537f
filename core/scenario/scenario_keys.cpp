#include "core/scenario/scenario_keys.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <map>
#include <system_error>
#include <utility>

#include "core/base/json.hpp"
#include "core/scenario/scenario_value_toml.hpp"

namespace mixpilot {

using namespace toml_read;  // NOLINT: the reading vocabulary of this file

std::string shortest(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buf[64];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

namespace {

std::string toml_string(std::string_view s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    switch (ch) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (c < 0x20 || c == 0x7F) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04X", c);
          out += buf;
        } else {
          out += ch;
        }
    }
  }
  return out + '"';
}

}  // namespace

std::string ScenarioValue::toml() const {
  switch (type) {
    case Type::boolean: return boolean ? "true" : "false";
    case Type::integer: return std::to_string(integer);
    case Type::number: return std::isfinite(number) ? fmt(number) : shortest(number);
    case Type::string: return toml_string(string);
    case Type::array: {
      std::string out = "[";
      for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i].toml();
      return out + ']';
    }
  }
  return {};
}

std::string ScenarioValue::text() const {
  switch (type) {
    case Type::boolean: return boolean ? "true" : "false";
    case Type::integer: return std::to_string(integer);
    case Type::number: return shortest(number);
    case Type::string: return string;
    case Type::array: {
      std::string out = "[";
      for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i].text();
      return out + ']';
    }
  }
  return {};
}

std::string ScenarioValue::json() const {
  switch (type) {
    case Type::boolean: return boolean ? "true" : "false";
    case Type::integer: return std::to_string(integer);
    case Type::number: return std::isfinite(number) ? shortest(number) : "null";
    case Type::string: return json_quote(string);
    case Type::array: {
      std::string out = "[";
      for (std::size_t i = 0; i < items.size(); ++i) out += (i ? ", " : "") + items[i].json();
      return out + ']';
    }
  }
  return {};
}

bool scenario_value_of(const toml::node& n, ScenarioValue& out, std::string& why) {
  switch (n.type()) {
    case toml::node_type::boolean:
      out.type = ScenarioValue::Type::boolean;
      out.boolean = n.as_boolean()->get();
      return true;
    case toml::node_type::integer:
      out.type = ScenarioValue::Type::integer;
      out.integer = n.as_integer()->get();
      return true;
    case toml::node_type::floating_point:
      out.type = ScenarioValue::Type::number;
      out.number = n.as_floating_point()->get();
      return true;
    case toml::node_type::string:
      out.type = ScenarioValue::Type::string;
      out.string = n.as_string()->get();
      return true;
    case toml::node_type::array: {
      out.type = ScenarioValue::Type::array;
      for (const toml::node& e : *n.as_array()) {
        out.items.emplace_back();
        if (!scenario_value_of(e, out.items.back(), why)) return false;
      }
      return true;
    }
    default:
      why = "expected a number, a boolean, a string or an array of them, got " + describe(n);
      return false;
  }
}

namespace {

// One part of a key path: a key, and an element of the array it names.
struct Part {
  std::string name;
  std::optional<std::size_t> index;
};

bool bare_key_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

// "a.b[2].c" → parts; false with what was expected.
bool parse_path(std::string_view key, std::vector<Part>& parts, std::string& why) {
  parts.clear();
  std::size_t i = 0;
  while (true) {
    Part p;
    const std::size_t from = i;
    while (i < key.size() && bare_key_char(key[i])) ++i;
    if (i == from) {
      why = "expected a key path of the scenario: names of letters, digits, _ and - joined by "
            "'.', each with an optional [index] (plant.rtt, arena.obstacles[0].radius)";
      return false;
    }
    p.name.assign(key.substr(from, i - from));
    if (i < key.size() && key[i] == '[') {
      const std::size_t close = key.find(']', i);
      std::size_t v = 0;
      const auto r = close == std::string_view::npos
                         ? std::from_chars_result{nullptr, std::errc::invalid_argument}
                         : std::from_chars(key.data() + i + 1, key.data() + close, v);
      if (close == std::string_view::npos || close == i + 1 || r.ec != std::errc() ||
          r.ptr != key.data() + close || v > 1000000) {
        why = "expected [index] with a whole number after \"" + p.name + "\"";
        return false;
      }
      p.index = v;
      i = close + 1;
    }
    parts.push_back(std::move(p));
    if (i == key.size()) return true;
    if (key[i] != '.') {
      why = "expected '.' or the end of the key after \"" + parts.back().name + "\"";
      return false;
    }
    ++i;
  }
}

std::string path_text(const std::vector<Part>& parts, std::size_t n) {
  std::string out;
  for (std::size_t j = 0; j < n && j < parts.size(); ++j) {
    if (j) out += '.';
    out += parts[j].name;
    if (parts[j].index) out += '[' + std::to_string(*parts[j].index) + ']';
  }
  return out;
}

// Where `parts` leads in the base scenario: the node it names, or nullptr where the scenario
// leaves it out (the loader then judges the key). False with why it cannot name a value.
bool resolve(const toml::table& root, const std::vector<Part>& parts, const toml::node*& found,
             std::string& why) {
  const toml::node* cur = &root;
  found = nullptr;
  for (std::size_t j = 0; j < parts.size(); ++j) {
    const toml::table* t = cur->as_table();
    if (!t && cur->is_array_of_tables()) {
      why = path_text(parts, j) + " is an array of tables in the scenario: expected an element " +
            "of it, " + path_text(parts, j) + "[index]." + parts[j].name;
      return false;
    }
    if (!t) {
      why = path_text(parts, j) + " is " + describe(*cur) + " in the scenario, not a table";
      return false;
    }
    const toml::node* child = t->get(parts[j].name);
    if (!child) {
      if (parts[j].index) {
        why = "the scenario has no " + parts[j].name + ": [" + std::to_string(*parts[j].index) +
              "] sets an element of an array the scenario has";
        return false;
      }
      return true;
    }
    if (parts[j].index) {
      const toml::array* a = child->as_array();
      if (!a) {
        why = parts[j].name + " is " + describe(*child) + " in the scenario, not an array";
        return false;
      }
      if (*parts[j].index >= a->size()) {
        why = "the scenario's " + path_text(parts, j) + (j ? "." : "") + parts[j].name + " has " +
              std::to_string(a->size()) + " elements: index " + std::to_string(*parts[j].index) +
              " is out of range";
        return false;
      }
      child = a->get(*parts[j].index);
    }
    cur = child;
  }
  found = cur;
  return true;
}

// Whether `v` can stand where the scenario has `n`: the same kind of value (an integer for an
// integer key; any number for a number's).
bool compatible(const toml::node& n, const ScenarioValue& v, std::string& why) {
  using T = ScenarioValue::Type;
  const auto expect = [&](const std::string& what) {
    why = "expected " + what + " like the scenario's value " + describe(n) + ", got " + v.toml();
    return false;
  };
  if (n.is_table() || n.is_array_of_tables()) {
    why = std::string(n.is_table() ? "a table" : "an array of tables") +
          " in the scenario: expected the key of a value inside it (" +
          (n.is_table() ? "table.key" : "array[index].key") + "), got " + v.toml();
    return false;
  }
  if (n.is_integer() && v.type != T::integer) return expect("an integer");
  if (n.is_floating_point() && v.type != T::number && v.type != T::integer)
    return expect("a number");
  if (n.is_boolean() && v.type != T::boolean) return expect("true or false");
  if (n.is_string() && v.type != T::string) return expect("a string");
  if (n.is_array() && v.type != T::array) return expect("an array");
  return true;
}

// Whether the node `n` of a written scenario holds `v`.
bool holds(const toml::node& n, const ScenarioValue& v) {
  using T = ScenarioValue::Type;
  switch (v.type) {
    case T::boolean: return n.is_boolean() && n.as_boolean()->get() == v.boolean;
    case T::integer: return n.is_integer() && n.as_integer()->get() == v.integer;
    case T::number: {
      if (!n.is_floating_point()) return false;
      const double x = n.as_floating_point()->get();
      return x == v.number || (std::isnan(x) && std::isnan(v.number));
    }
    case T::string: return n.is_string() && n.as_string()->get() == v.string;
    case T::array: {
      const toml::array* a = n.as_array();
      if (!a || a->size() != v.items.size()) return false;
      for (std::size_t i = 0; i < v.items.size(); ++i)
        if (!holds(*a->get(i), v.items[i])) return false;
      return true;
    }
  }
  return false;
}

// ---- writing values into the scenario's text -----------------------------------------------

// Edits of the base scenario's text: values replaced where they stand, keys the file leaves out
// added to their table, tables it lacks appended.
class TextPatch {
 public:
  explicit TextPatch(std::string_view text) : text_(text) {
    starts_.push_back(0);
    for (std::size_t i = 0; i < text_.size(); ++i)
      if (text_[i] == '\n') starts_.push_back(i + 1);
  }

  // Sets `parts` to `v`; false with why it cannot be written.
  bool set(const toml::table& root, const std::vector<Part>& parts, const ScenarioValue& v,
           std::string& why) {
    const toml::node* cur = &root;
    std::string header_path;   // the path of `cur` as a table header names it
    bool under_array = false;  // `cur` is an element of an array of tables, or inside one
    for (std::size_t j = 0; j + 1 < parts.size(); ++j) {
      const toml::table* t = cur->as_table();
      const toml::node* child = t ? t->get(parts[j].name) : nullptr;
      const std::string child_path = header_path + (header_path.empty() ? "" : ".") + parts[j].name;
      if (!child) {  // tables the scenario lacks: appended, each with its header
        for (std::size_t m = j; m < parts.size(); ++m)
          if (parts[m].index) {
            why = "the scenario has no " + parts[m].name + " to set element [" +
                  std::to_string(*parts[m].index) + "] of";
            return false;
          }
        if (under_array) {
          why = "cannot add the table " + path_text(parts, parts.size() - 1) +
                " inside an element of an array of tables; write it in the scenario";
          return false;
        }
        std::string table = child_path;
        for (std::size_t m = j + 1; m + 1 < parts.size(); ++m) table += '.' + parts[m].name;
        appended_[table] += parts.back().name + " = " + v.toml() + '\n';
        return true;
      }
      if (parts[j].index) {
        const toml::array* a = child->as_array();
        child = a ? a->get(*parts[j].index) : nullptr;
        under_array = true;
      }
      if (!child || !child->is_table()) {
        why = path_text(parts, j + 1) + " is not a table in the scenario";
        return false;
      }
      cur = child;
      header_path = child_path;
    }
    const toml::table* t = cur->as_table();
    const Part& last = parts.back();
    const toml::node* n = t->get(last.name);
    if (n && last.index) {
      const toml::array* a = n->as_array();
      n = a ? a->get(*last.index) : nullptr;
      if (!n) {
        why = "the scenario has no element " + path_text(parts, parts.size());
        return false;
      }
    } else if (!n && last.index) {
      why = "the scenario has no " + last.name + " to set element [" + std::to_string(*last.index) +
            "] of";
      return false;
    }
    const std::string line = last.name + " = " + v.toml();
    if (n) {  // replaced where it stands
      const std::size_t from = offset(n->source().begin), to = offset(n->source().end);
      if (from >= to || to > text_.size()) {
        why = "cannot find its value in the scenario's text";
        return false;
      }
      edits_.push_back({from, to - from, v.toml(), edits_.size()});
      return true;
    }
    if (t == &root) {  // a top-level key: before the first table
      edits_.push_back({0, 0, line + '\n', edits_.size()});
      return true;
    }
    if (t->is_inline()) {  // { a = 1 }: before its closing brace
      const std::size_t end = offset(t->source().end);
      if (end == 0 || end > text_.size() || text_[end - 1] != '}') {
        why = "cannot find the end of its inline table in the scenario's text";
        return false;
      }
      const bool first = t->empty() && added_inline_[t]++ == 0;
      edits_.push_back({end - 1, 0, (first ? " " : ", ") + line + ' ', edits_.size()});
      return true;
    }
    // A table with its own [header] (or an element's [[header]]): on the line after it.
    const std::size_t at = offset(t->source().begin);
    if (header_at(at) == header_path) {
      const std::uint32_t l = t->source().begin.line;
      if (l < starts_.size()) {
        edits_.push_back({starts_[l], 0, line + '\n', edits_.size()});
      } else {  // the header is the last line, without a line break
        edits_.push_back({text_.size(), 0, '\n' + line + '\n', edits_.size()});
      }
      return true;
    }
    // A table the file only names in its sub-tables' headers: its own header, appended.
    if (under_array) {
      why = "cannot add " + last.name + " to " + path_text(parts, parts.size() - 1) +
            ", which has no [header] of its own in the scenario; write it there";
      return false;
    }
    appended_[header_path] += line + '\n';
    return true;
  }

  std::string result() const {
    std::string out(text_);
    std::vector<Edit> edits = edits_;
    std::sort(edits.begin(), edits.end(), [](const Edit& a, const Edit& b) {
      return a.at != b.at ? a.at > b.at : a.order > b.order;
    });
    for (const Edit& e : edits) out.replace(e.at, e.length, e.with);
    if (!appended_.empty() && !out.empty() && out.back() != '\n') out += '\n';
    for (const auto& [table, lines] : appended_) out += "\n[" + table + "]\n" + lines;
    return out;
  }

 private:
  struct Edit {
    std::size_t at, length;
    std::string with;
    std::size_t order;
  };

  // The byte offset of a toml++ position (1-based line, column in code points).
  std::size_t offset(const toml::source_position& p) const {
    if (p.line == 0 || p.line > starts_.size()) return text_.size() + 1;
    std::size_t i = starts_[p.line - 1];
    for (std::uint32_t c = 1; c < p.column && i < text_.size(); ++c) {
      ++i;
      while (i < text_.size() && (static_cast<unsigned char>(text_[i]) & 0xC0) == 0x80) ++i;
    }
    return i;
  }

  // The table a [header] or [[header]] at `at` names ("" when there is none).
  std::string header_at(std::size_t at) const {
    if (at >= text_.size() || text_[at] != '[') return {};
    const std::size_t close = text_.find(']', at);
    const std::size_t eol = text_.find('\n', at);
    if (close == std::string_view::npos || (eol != std::string_view::npos && close > eol))
      return {};
    std::string name;
    for (char c : text_.substr(at, close - at))
      if (c != '[' && c != ' ' && c != '\t') name += c;
    return name;
  }

  std::string_view text_;
  std::vector<std::size_t> starts_;  // byte offset of each line
  std::vector<Edit> edits_;
  std::map<std::string, std::string> appended_;  // table path → its lines
  std::map<const toml::table*, int> added_inline_;
};

}  // namespace

// The text as given and its table, shared by every copy of an edit (a sweep's runs).
struct ScenarioEdit::State {
  struct Base {
    std::string text;
    toml::table doc;
  };
  std::shared_ptr<const Base> base;
  TextPatch patch;
};

ScenarioEdit::ScenarioEdit(std::unique_ptr<State> s) : s_(std::move(s)) {}
ScenarioEdit::ScenarioEdit(const ScenarioEdit& o) : s_(std::make_unique<State>(*o.s_)) {}
ScenarioEdit& ScenarioEdit::operator=(const ScenarioEdit& o) {
  if (this != &o) s_ = std::make_unique<State>(*o.s_);
  return *this;
}
ScenarioEdit::ScenarioEdit(ScenarioEdit&&) noexcept = default;
ScenarioEdit& ScenarioEdit::operator=(ScenarioEdit&&) noexcept = default;
ScenarioEdit::~ScenarioEdit() = default;

std::optional<ScenarioEdit> ScenarioEdit::open(std::string_view text, const std::string& source_name,
                                               std::string& why) {
  auto base = std::make_shared<State::Base>();
  base->text.assign(text);
  try {
    base->doc = toml::parse(base->text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    why = std::string(e.description());
    return std::nullopt;
  }
  const std::string_view view = base->text;  // stays where it is: the base is never moved
  return ScenarioEdit(std::make_unique<State>(State{std::move(base), TextPatch(view)}));
}

bool ScenarioEdit::check(std::string_view key, const ScenarioValue& v, std::string& why) const {
  std::vector<Part> parts;
  const toml::node* n = nullptr;
  return parse_path(key, parts, why) && resolve(s_->base->doc, parts, n, why) &&
         (!n || compatible(*n, v, why));
}

bool ScenarioEdit::set(std::string_view key, const ScenarioValue& v, std::string& why) {
  std::vector<Part> parts;
  return check(key, v, why) && parse_path(key, parts, why) &&
         s_->patch.set(s_->base->doc, parts, v, why);
}

bool ScenarioEdit::holds(std::string_view key, const ScenarioValue& v) const {
  std::vector<Part> parts;
  std::string why;
  const toml::node* n = nullptr;
  return parse_path(key, parts, why) && resolve(s_->base->doc, parts, n, why) && n &&
         mixpilot::holds(*n, v);
}

std::string ScenarioEdit::result() const { return s_->patch.result(); }

std::optional<ScenarioValue> parse_scenario_value(std::string_view text, std::string& why) {
  if (text.find_first_of("\r\n") != std::string_view::npos) {
    why = "the value must be on one line";
    return std::nullopt;
  }
  toml::table probe;
  try {
    probe = toml::parse("v = " + std::string(text));
  } catch (const toml::parse_error&) {
  }
  ScenarioValue v;
  const toml::node* n = probe.size() == 1 ? probe.get("v") : nullptr;
  std::string kind;
  if (!n || !scenario_value_of(*n, v, kind)) {
    why = "the value is not one TOML value (strings need quotes: \"lcl\")" +
          (kind.empty() ? std::string() : ": " + kind);
    return std::nullopt;
  }
  return v;
}

std::string key_label(std::string_view key) {
  std::vector<Part> parts;
  std::string why;
  if (!parse_path(key, parts, why)) return std::string(key);
  std::string label = parts.back().name;
  if (parts.back().index) label += std::to_string(*parts.back().index);
  return label;
}

std::optional<ScenarioKey> parse_scenario_key(std::string_view text, std::string& error) {
  const auto trim = [](std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
  };
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos) {
    error = "expected KEY=VALUE (e.g. plant.rtt=0.012), got '" + std::string(text) + "'";
    return std::nullopt;
  }
  ScenarioKey k{std::string(trim(text.substr(0, eq))), std::string(trim(text.substr(eq + 1)))};
  if (k.key.empty() || k.value.empty()) {
    error = "expected KEY=VALUE with neither empty, got '" + std::string(text) + "'";
    return std::nullopt;
  }
  return k;
}

std::optional<std::string> set_scenario_keys(std::string_view text, const std::string& source_name,
                                             const std::vector<ScenarioKey>& keys,
                                             std::string& error) {
  std::string out(text);
  for (const ScenarioKey& k : keys) {
    std::string shown;  // the value as a message shows it: one line
    for (const char c : k.value) shown += c == '\n' ? "\\n" : c == '\r' ? "\\r" : std::string(1, c);
    const std::string what = "setting " + k.key + " = " + shown + " in " + source_name + ": ";
    std::string why;
    const std::optional<ScenarioValue> v = parse_scenario_value(k.value, why);
    if (!v) {
      error = what + why;
      return std::nullopt;
    }
    // Each setting on the text the ones before it wrote: a later setting of a key wins.
    std::optional<ScenarioEdit> edit = ScenarioEdit::open(out, source_name, why);
    if (!edit) {
      error = what + "the scenario is not TOML (" + why + ")";
      return std::nullopt;
    }
    if (!edit->set(k.key, *v, why)) {
      error = what + why;
      return std::nullopt;
    }
    out = edit->result();
  }
  return out;
}

std::string describe_keys(const std::vector<ScenarioKey>& keys) {
  std::string out;
  for (const ScenarioKey& k : keys) out += (out.empty() ? "" : ", ") + k.key + " = " + k.value;
  return out;
}

}  // namespace mixpilot
