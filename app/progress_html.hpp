#pragma once
// A trainee's progress report to take home (SPEC §10): one self-contained HTML file — inline
// SVG curves of skill per attempt (assisted and probe flights) and D per scenario, the best
// run, the trend, a table of the flights — with no network, fonts or scripts, printable.
#include <string>
#include <string_view>
#include <vector>

#include "core/history/history.hpp"

namespace mixpilot::cli {

// `text` safe inside HTML text and attribute values (& < > " ' escaped).
std::string html_escape(std::string_view text);

// The report of `rows` (one trainee's flights, oldest first). `generated_unix_ms`: when.
std::string progress_html(const std::string& trainee,
                          const std::vector<history::StoredFlight>& rows,
                          std::int64_t generated_unix_ms);

}  // namespace mixpilot::cli
