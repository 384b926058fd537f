#include "core/base/report_table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace mixpilot {

bool is_timing_field(std::string_view name) {
  return name.ends_with("_us") || name == "deadline_misses" || name == "wall_s";
}

std::string csv_field(std::string_view text) {
  if (text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + '"';
}

namespace {

void add_column(std::vector<std::string>& columns, const std::string& name) {
  if (std::find(columns.begin(), columns.end(), name) == columns.end()) columns.push_back(name);
}

std::string cell(const JsonValue& v) {
  switch (v.type) {
    case JsonValue::Type::string: return v.text;
    case JsonValue::Type::number: {
      // The shortest text that reads back as the same double (the reports write 17 digits).
      if (!std::isfinite(v.number)) return v.text;
      char buf[64];
      const auto r = std::to_chars(buf, buf + sizeof buf, v.number);
      return std::string(buf, r.ptr);
    }
    case JsonValue::Type::boolean: return v.boolean ? "true" : "false";
    default: return "";
  }
}

}  // namespace

std::string report_table_csv(const std::vector<ReportRow>& rows) {
  std::vector<std::string> keys, labels, values, timing;
  for (const ReportRow& r : rows) {
    for (const auto& [name, text] : r.keys) add_column(keys, name);
    if (!r.report) continue;
    for (const auto& [name, v] : r.report->members) {
      if (std::find(keys.begin(), keys.end(), name) != keys.end()) continue;
      if (is_timing_field(name)) add_column(timing, name);
      else if (v.is(JsonValue::Type::string)) add_column(labels, name);
      else add_column(values, name);
    }
  }
  std::vector<std::string> columns = keys;
  for (const auto* group : {&labels, &values, &timing})
    for (const std::string& c : *group)
      if (std::find(columns.begin(), columns.end(), c) == columns.end()) columns.push_back(c);

  std::string out;
  for (std::size_t c = 0; c < columns.size(); ++c) out += (c ? "," : "") + csv_field(columns[c]);
  out += '\n';
  for (const ReportRow& r : rows) {
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (c) out += ',';
      const std::string& name = columns[c];
      const auto key = std::find_if(r.keys.begin(), r.keys.end(),
                                    [&](const auto& k) { return k.first == name; });
      if (key != r.keys.end()) {
        out += csv_field(key->second);
      } else if (const JsonValue* v = r.report ? r.report->get(name) : nullptr) {
        out += csv_field(cell(*v));
      }
    }
    out += '\n';
  }
  return out;
}

}  // namespace mixpilot
