#pragma once
// One table from many reports (a sweep's runs, a folder's scores; docs/sweeps.md): a CSV with
// one row per report, its key columns first (index, id, the run's parameters or its
// recording), then every field any report has, in the order they first appear: the labels
// (strings), the measured values, and last the timing fields, which measure a run on its
// machine rather than the flight (is_timing_field), so that two tables of the same plan can be
// compared on everything before them.
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/base/json.hpp"

namespace mixpilot {

// Fields that measure the computer, not the flight: the controller's times (`*_us`: RTI,
// LQR, predictor), deadline misses of a paced flight, a run's wall time (`wall_s`). Every
// other field of a report is a function of the flight alone and repeats bit for bit.
bool is_timing_field(std::string_view name);

struct ReportRow {
  std::vector<std::pair<std::string, std::string>> keys;  // leading columns: name, text
  const JsonValue* report = nullptr;                      // an object of strings and numbers
};

// RFC 4180: a field with a comma, a quote or a line break is quoted, its quotes doubled.
std::string csv_field(std::string_view text);

// The table as CSV. A report's number appears as the shortest text that reads back as the same
// double (exact; the reports write 17 significant digits); a null (a value that was not
// finite), a field a report lacks, or a nested value is an empty cell.
std::string report_table_csv(const std::vector<ReportRow>& rows);

}  // namespace mixpilot
