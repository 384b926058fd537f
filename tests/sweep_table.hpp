#pragma once
// A sweep's or a folder score's merged table (DIR/table.csv) read back for comparison: rows of
// fields (RFC 4180 quoting), and the same without the timing columns (is_timing_field), which
// is what two runs of one plan share wherever and however they were flown.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "core/base/report_table.hpp"

namespace mixpilot::test {

using Table = std::vector<std::vector<std::string>>;

inline Table read_csv_table(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  Table rows(1);
  std::string field;
  bool quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') field += '"', ++i;
      else if (c == '"') quoted = false;
      else field += c;
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      rows.back().push_back(field);
      field.clear();
    } else if (c == '\n') {
      rows.back().push_back(field);
      field.clear();
      rows.emplace_back();
    } else {
      field += c;
    }
  }
  if (rows.back().empty()) rows.pop_back();
  return rows;
}

inline Table non_timing(const Table& t) {
  if (t.empty()) return t;
  std::vector<bool> keep;
  for (const std::string& h : t[0]) keep.push_back(!is_timing_field(h));
  Table out;
  for (const auto& row : t) {
    EXPECT_EQ(row.size(), keep.size());
    std::vector<std::string> r;
    for (std::size_t c = 0; c < row.size() && c < keep.size(); ++c)
      if (keep[c]) r.push_back(row[c]);
    out.push_back(r);
  }
  return out;
}

}  // namespace mixpilot::test
