#pragma once
// A trainee's progress on a scenario from the history's rows (SPEC §10): attempts, skill, D, the
// best run and the trend, as the Progress panel and the HTML report show them.
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/history/history.hpp"
#include "ui/progress.hpp"

namespace mixpilot::cli {

// How many of the newest attempts of one kind a trend is fitted to.
inline constexpr int kTrendAttempts = 10;

// The least-squares slope of `values` against 0, 1, 2, ... (nullopt for fewer than 3 values).
std::optional<double> least_squares_slope(std::span<const double> values);
// The trend of the last kTrendAttempts finite `skills`, said in words ("rising: +1.8 skill per
// attempt over the last 10 assisted flights").
ui::Trend skill_trend(std::span<const double> skills, const char* kind);

// The metric `name` of a row (nullopt when the row has none).
std::optional<double> metric_of(const history::StoredFlight& f, std::string_view name);

// The view of `rows` (one trainee's flights of one scenario, oldest first). With
// `check_recordings`, a recording no longer on this disk is left out (it cannot be replayed).
ui::ProgressView progress_view(const std::vector<history::StoredFlight>& rows,
                               std::string trainee, std::string scenario,
                               bool check_recordings = true);

// The ghost a trainee races by default (SPEC §10): the index in `view` of the flight with the
// highest skill among those whose recording is on this disk and whose scenario's content hash is
// `scenario_hash` (the one flown now); −1 when none. ProgressView::best is the best of all, the
// ones without a recording too.
int best_recorded(const ui::ProgressView& view, const std::string& scenario_hash);

// "YYYY-MM-DD HH:MM" in local time.
std::string local_minutes(std::int64_t unix_ms);

}  // namespace mixpilot::cli
