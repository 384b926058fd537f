#include "core/scenario/scenario_keys.hpp"

#include <cstddef>

#include "core/base/toml_read.hpp"

namespace mixpilot {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// The byte offset of a toml++ position: lines are counted by '\n', columns in code points (a
// UTF-8 continuation byte 10xxxxxx starts none).
std::size_t offset_of(std::string_view text, const toml::source_position& p) {
  std::size_t at = 0;
  for (toml::source_index line = 1; line < p.line && at < text.size(); ++at)
    if (text[at] == '\n') ++line;
  for (toml::source_index col = 1; col < p.column && at < text.size(); ++at) {
    while (at + 1 < text.size() && (static_cast<unsigned char>(text[at + 1]) & 0xC0) == 0x80) ++at;
    ++col;
  }
  return at;
}

std::vector<std::string> split_path(std::string_view key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t i = 0; i <= key.size(); ++i) {
    if (i == key.size() || key[i] == '.') {
      parts.emplace_back(key.substr(start, i - start));
      start = i + 1;
    }
  }
  return parts;
}

bool bare_key(std::string_view k) {
  if (k.empty()) return false;
  for (const char c : k)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
          c == '-'))
      return false;
  return true;
}

// One setting applied to `text`; false with the reason.
bool set_one(std::string& text, const std::string& source_name, const ScenarioKey& k,
             std::string& error) {
  std::string shown;  // the value as a message shows it: one line
  for (const char c : k.value) shown += c == '\n' ? "\\n" : c == '\r' ? "\\r" : std::string(1, c);
  const std::string what = "setting " + k.key + " = " + shown + " in " + source_name + ": ";
  const std::vector<std::string> path = split_path(k.key);
  for (const std::string& part : path) {
    if (!bare_key(part)) {
      error = what + "expected a dotted path of bare keys (letters, digits, '_', '-')";
      return false;
    }
  }
  if (k.value.find_first_of("\r\n") != std::string::npos) {
    error = what + "the value must be on one line";
    return false;
  }
  bool one_value = false;
  try {
    const toml::table probe = toml::parse("v = " + k.value);
    one_value = probe.size() == 1 && probe.get("v") != nullptr;
  } catch (const toml::parse_error&) {
  }
  if (!one_value) {
    error = what + "the value is not one TOML value (strings need quotes: \"lcl\")";
    return false;
  }
  toml::table doc;
  try {
    doc = toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    error = what + "the scenario is not TOML (" + std::string(e.description()) + ")";
    return false;
  }
  const toml::table* table = &doc;
  std::string walked;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    walked += (walked.empty() ? "" : ".") + path[i];
    const toml::node* n = table->get(path[i]);
    if (!n) {
      error = what + "the scenario has no table [" + walked + "]";
      return false;
    }
    if (!n->is_table()) {
      error = what + walked + (n->is_array_of_tables() ? " is an array of tables" : " is not a table");
      return false;
    }
    table = n->as_table();
  }
  if (const toml::node* leaf = table->get(path.back())) {
    if (leaf->is_table() || leaf->is_array_of_tables()) {
      error = what + k.key + " is a table, not a key";
      return false;
    }
    const std::size_t begin = offset_of(text, leaf->source().begin);
    const std::size_t end = offset_of(text, leaf->source().end);
    text.replace(begin, end - begin, k.value);
    return true;
  }
  // Not in the file: on the line after the table's header, or at the top for the root.
  std::size_t at = 0;
  if (table != &doc) {
    // Its header names it ("[controller]"): a table made implicitly by a deeper header
    // ("[g.h]" makes g) has the deeper header's position, and none of its own.
    const std::size_t header = offset_of(text, table->source().begin);
    std::string named;
    if (header < text.size() && text[header] == '[') {
      for (std::size_t i = header + 1; i < text.size() && text[i] != ']' && text[i] != '\n'; ++i)
        if (text[i] != ' ' && text[i] != '\t') named += text[i];
    }
    if (named != walked) {
      error = what + "[" + walked + "] has no header of its own to add " + path.back() + " under";
      return false;
    }
    at = text.find('\n', header);
    at = at == std::string::npos ? text.size() : at + 1;
    if (at == text.size() && !text.empty() && text.back() != '\n') {
      text += '\n';
      at = text.size();
    }
  }
  text.insert(at, path.back() + " = " + k.value + "\n");
  return true;
}

}  // namespace

std::optional<ScenarioKey> parse_scenario_key(std::string_view text, std::string& error) {
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
  for (const ScenarioKey& k : keys)
    if (!set_one(out, source_name, k, error)) return std::nullopt;
  return out;
}

std::string describe_keys(const std::vector<ScenarioKey>& keys) {
  std::string out;
  for (const ScenarioKey& k : keys) out += (out.empty() ? "" : ", ") + k.key + " = " + k.value;
  return out;
}

}  // namespace mixpilot
