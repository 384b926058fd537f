#include "app/progress.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>

namespace mixpilot::cli {

std::optional<double> least_squares_slope(std::span<const double> v) {
  const std::size_t n = v.size();
  if (n < 3) return std::nullopt;
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += double(i);
    my += v[i];
  }
  mx /= double(n);
  my /= double(n);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (double(i) - mx) * (v[i] - my);
    sxx += (double(i) - mx) * (double(i) - mx);
  }
  return sxy / sxx;
}

ui::Trend skill_trend(std::span<const double> skills, const char* kind) {
  ui::Trend t;
  std::vector<double> last;
  for (double s : skills)
    if (std::isfinite(s)) last.push_back(s);
  if (last.size() > std::size_t(kTrendAttempts))
    last.erase(last.begin(), last.end() - kTrendAttempts);
  t.over = int(last.size());
  const auto slope = least_squares_slope(last);
  char text[160];
  if (!slope) {
    std::snprintf(text, sizeof text, "no trend yet: %d %s flight%s (3 make one)", t.over, kind,
                  t.over == 1 ? "" : "s");
    t.words = text;
    return t;
  }
  t.slope = *slope;
  // Half a skill point per attempt is within a run's scatter: steady.
  const char* verdict = *slope >= 0.5 ? "rising" : *slope <= -0.5 ? "falling" : "steady";
  std::snprintf(text, sizeof text, "%s: %+.1f skill per attempt over the last %d %s flights",
                verdict, *slope, t.over, kind);
  t.words = text;
  return t;
}

std::optional<double> metric_of(const history::StoredFlight& f, std::string_view name) {
  for (const auto& [k, v] : f.metrics)
    if (k == name) return v;
  return std::nullopt;
}

std::string local_minutes(std::int64_t unix_ms) {
  const std::time_t t = std::time_t(unix_ms / 1000);
  std::tm tm{};
  localtime_r(&t, &tm);
  char text[32];
  return std::strftime(text, sizeof text, "%Y-%m-%d %H:%M", &tm) ? text : "";
}

ui::ProgressView progress_view(const std::vector<history::StoredFlight>& rows,
                               std::string trainee, std::string scenario,
                               bool check_recordings) {
  ui::ProgressView v;
  v.trainee = std::move(trainee);
  v.scenario = std::move(scenario);
  v.flights.reserve(rows.size());
  std::vector<double> assisted, probes;
  for (const history::StoredFlight& r : rows) {
    ui::ProgressFlight f;
    f.attempt = int(v.flights.size()) + 1;
    f.probe = r.probe;
    f.skill = metric_of(r, "skill").value_or(ui::kNoValue);
    // A probe's D is 0 by construction (λ pinned to 1), not a sign of less reliance: D's curve
    // and column are the assisted flights'.
    if (!f.probe) f.dependence = metric_of(r, "assistance_dependence").value_or(ui::kNoValue);
    f.duration_s = r.duration_s;
    f.started_unix_ms = r.started_unix_ms;
    f.metrics = r.metrics;
    f.when = local_minutes(r.started_unix_ms);
    f.ended = history::to_string(r.ended);
    f.from_step = r.parent_step;
    f.scenario_hash = r.scenario_hash;
    std::error_code ec;
    if (!r.recording_path.empty() &&
        (!check_recordings || std::filesystem::is_regular_file(r.recording_path, ec)))
      f.recording = r.recording_path;
    if (std::isfinite(f.dependence)) v.has_dependence = true;
    (f.probe ? probes : assisted).push_back(f.skill);
    ++(f.probe ? v.probes : v.assisted);
    if (std::isfinite(f.skill) &&
        (v.best < 0 || f.skill > v.flights[std::size_t(v.best)].skill))
      v.best = int(v.flights.size());
    v.flights.push_back(std::move(f));
  }
  v.assisted_trend = skill_trend(assisted, "assisted");
  v.probe_trend = skill_trend(probes, "probe");
  return v;
}

int best_recorded(const ui::ProgressView& v, const std::string& scenario_hash) {
  int best = -1;
  for (std::size_t i = 0; i < v.flights.size(); ++i) {
    const ui::ProgressFlight& f = v.flights[i];
    if (f.recording.empty() || f.scenario_hash != scenario_hash || !std::isfinite(f.skill))
      continue;
    if (best < 0 || f.skill > v.flights[std::size_t(best)].skill) best = int(i);
  }
  return best;
}

}  // namespace mixpilot::cli
