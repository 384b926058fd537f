#include "app/progress_html.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "app/progress.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot::cli {

std::string html_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

namespace {

// Okabe–Ito, as in the window (UI.md §9).
constexpr const char* kAssisted = "#009E73";
constexpr const char* kProbe = "#0072B2";  // the darker blue: readable on white paper
constexpr const char* kDependence = "#E69F00";

std::string fmt(const char* format, double v) {
  char text[64];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

// Skill per attempt (0–100, left axis), assisted and probe flights, D (0–1, right axis).
std::string svg_of(const ui::ProgressView& v) {
  constexpr double W = 720, H = 260, L = 44, R = 44, T = 14, B = 34;
  const int n = int(v.flights.size());
  const auto x = [&](int i) { return n == 1 ? L + 0.5 * (W - L - R) : L + i * (W - L - R) / (n - 1); };
  const auto y = [&](double skill) { return H - B - std::clamp(skill, 0.0, 100.0) / 100.0 * (H - T - B); };
  std::string s = "<svg class=\"curve\" viewBox=\"0 0 720 260\" role=\"img\" aria-label=\"skill per attempt\" "
                  "xmlns=\"http://www.w3.org/2000/svg\">\n";
  for (int g = 0; g <= 4; ++g) {
    const double yy = y(25.0 * g);
    s += "<line x1=\"" + fmt("%.1f", L) + "\" x2=\"" + fmt("%.1f", W - R) + "\" y1=\"" + fmt("%.1f", yy) +
         "\" y2=\"" + fmt("%.1f", yy) + "\" class=\"grid\"/>";
    s += "<text x=\"" + fmt("%.1f", L - 6) + "\" y=\"" + fmt("%.1f", yy + 4) + "\" class=\"axis\" text-anchor=\"end\">" +
         std::to_string(25 * g) + "</text>";
    if (v.has_dependence)
      s += "<text x=\"" + fmt("%.1f", W - R + 6) + "\" y=\"" + fmt("%.1f", yy + 4) + "\" class=\"axis d\">" +
           fmt("%.2g", 0.25 * g) + "</text>";
  }
  s += "\n<text x=\"" + fmt("%.1f", 0.5 * W) + "\" y=\"" + fmt("%.1f", H - 6) +
       "\" class=\"axis\" text-anchor=\"middle\">attempt (oldest left)</text>\n";
  // Attempt numbers under the axis: at most ~12 labels.
  const int every = std::max(1, (n + 11) / 12);
  for (int i = 0; i < n; i += every)
    s += "<text x=\"" + fmt("%.1f", x(i)) + "\" y=\"" + fmt("%.1f", H - B + 14) +
         "\" class=\"axis\" text-anchor=\"middle\">" + std::to_string(i + 1) + "</text>";
  if (v.has_dependence) {
    std::string pts;
    for (int i = 0; i < n; ++i)
      if (std::isfinite(v.flights[std::size_t(i)].dependence))
        pts += fmt("%.1f", x(i)) + "," + fmt("%.1f", y(100.0 * v.flights[std::size_t(i)].dependence)) + " ";
    s += "\n<polyline class=\"series\" points=\"" + pts + "\" stroke=\"" + kDependence +
         "\" stroke-dasharray=\"6 4\"/>";
  }
  for (const bool probe : {false, true}) {
    const char* c = probe ? kProbe : kAssisted;
    std::string pts, marks;
    for (int i = 0; i < n; ++i) {
      const ui::ProgressFlight& f = v.flights[std::size_t(i)];
      if (f.probe != probe || !std::isfinite(f.skill)) continue;
      const double px = x(i), py = y(f.skill);
      pts += fmt("%.1f", px) + "," + fmt("%.1f", py) + " ";
      const std::string tip = "<title>attempt " + std::to_string(f.attempt) + " (" +
                              (probe ? "probe" : "assisted") + "), " + html_escape(f.when) +
                              ": skill " + fmt("%.1f", f.skill) + "</title>";
      if (probe)
        marks += "<path d=\"M" + fmt("%.1f", px) + " " + fmt("%.1f", py - 5) + " l5 5 l-5 5 l-5 -5 z\" fill=\"" +
                 c + "\">" + tip + "</path>";
      else
        marks += "<circle cx=\"" + fmt("%.1f", px) + "\" cy=\"" + fmt("%.1f", py) + "\" r=\"4\" fill=\"" + c +
                 "\">" + tip + "</circle>";
    }
    if (!pts.empty())
      s += "\n<polyline class=\"series\" points=\"" + pts + "\" stroke=\"" + c + "\"/>" + marks;
  }
  if (v.best >= 0)
    s += "\n<circle cx=\"" + fmt("%.1f", x(v.best)) + "\" cy=\"" +
         fmt("%.1f", y(v.flights[std::size_t(v.best)].skill)) +
         "\" r=\"9\" fill=\"none\" stroke=\"#222\" stroke-width=\"1.5\"><title>best run</title></circle>";
  s += "\n</svg>\n";
  return s;
}

std::string section_of(const ui::ProgressView& v) {
  std::string s = "<section>\n<h2>" + html_escape(v.scenario) + "</h2>\n<p>" +
                  std::to_string(v.flights.size()) + " flight" + (v.flights.size() == 1 ? "" : "s") +
                  ": " + std::to_string(v.assisted) + " assisted, " + std::to_string(v.probes) +
                  " probe" + (v.probes == 1 ? "" : "s") + " (unassisted).";
  if (v.best >= 0) {
    const ui::ProgressFlight& b = v.flights[std::size_t(v.best)];
    s += " <strong>Best run:</strong> skill " + fmt("%.1f", b.skill) + ", attempt " +
         std::to_string(b.attempt) + " (" + (b.probe ? "probe" : "assisted") + "), " +
         html_escape(b.when) + ".";
  }
  s += "</p>\n<p><strong>Trend</strong> (assisted): " + html_escape(v.assisted_trend.words) + ".";
  if (v.probes > 0) s += " <strong>Trend</strong> (probe): " + html_escape(v.probe_trend.words) + ".";
  s += "</p>\n<p class=\"legend\"><span style=\"color:" + std::string(kAssisted) +
       "\">&#9679; assisted</span> <span style=\"color:" + kProbe +
       "\">&#9670; probe (unassisted)</span>";
  if (v.has_dependence)
    s += " <span style=\"color:" + std::string(kDependence) +
         "\">- - - D: share of the flight the planner flew (right axis)</span>";
  s += " &#9711; best run</p>\n" + svg_of(v);
  s += "<table>\n<thead><tr><th>#</th><th>when</th><th>kind</th><th>skill</th>";
  if (v.has_dependence) s += "<th>D</th>";
  s += "<th>time [s]</th><th>ended</th><th>recording</th></tr></thead>\n<tbody>\n";
  for (const ui::ProgressFlight& f : v.flights) {
    s += "<tr" + std::string(f.attempt - 1 == v.best ? " class=\"best\"" : "") + "><td>" +
         std::to_string(f.attempt) + "</td><td>" + html_escape(f.when) + "</td><td>" +
         (f.probe ? "probe" : "assisted") + "</td><td class=\"n\">" +
         (std::isfinite(f.skill) ? fmt("%.1f", f.skill) : "&ndash;") + "</td>";
    if (v.has_dependence)
      s += "<td class=\"n\">" + (std::isfinite(f.dependence) ? fmt("%.2f", f.dependence) : "&ndash;") + "</td>";
    s += "<td class=\"n\">" + fmt("%.1f", f.duration_s) + "</td><td>" + html_escape(f.ended) +
         "</td><td class=\"path\">" + (f.recording.empty() ? "&ndash;" : html_escape(f.recording)) +
         "</td></tr>\n";
  }
  s += "</tbody>\n</table>\n</section>\n";
  return s;
}

constexpr const char* kStyle = R"(<style>
body { font-family: "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; color: #222;
       max-width: 60rem; margin: 2rem auto; padding: 0 1rem; line-height: 1.4; }
h1 { font-size: 1.6rem; margin-bottom: 0.2rem; }
h2 { font-size: 1.25rem; border-bottom: 1px solid #ccc; padding-bottom: 0.2rem; margin-top: 2rem; }
.meta, .legend { color: #555; font-size: 0.9rem; }
.legend span { margin-right: 1rem; }
svg.curve { width: 100%; height: auto; max-width: 720px; display: block; }
svg .grid { stroke: #ddd; stroke-width: 1; }
svg .axis { font-size: 11px; fill: #555; }
svg .axis.d { fill: #b07800; }
svg .series { fill: none; stroke-width: 2; }
table { border-collapse: collapse; font-size: 0.85rem; margin-top: 0.6rem; width: 100%; }
th, td { text-align: left; padding: 0.15rem 0.5rem; border-bottom: 1px solid #e4e4e4; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
td.path { word-break: break-all; color: #555; font-size: 0.75rem; }
tr.best td { font-weight: bold; }
@media print {
  body { margin: 0; max-width: none; font-size: 10pt; }
  section { break-inside: avoid-page; }
  table { page-break-inside: auto; }
  tr { break-inside: avoid; }
  a { color: inherit; text-decoration: none; }
}
</style>
)";

}  // namespace

std::string progress_html(const std::string& trainee,
                          const std::vector<history::StoredFlight>& rows,
                          std::int64_t generated_unix_ms) {
  // Per scenario, in the order first flown.
  std::vector<std::string> order;
  std::map<std::string, std::vector<history::StoredFlight>> by;
  for (const history::StoredFlight& r : rows) {
    auto& list = by[r.scenario];
    if (list.empty()) order.push_back(r.scenario);
    list.push_back(r);
  }
  const std::string name = html_escape(trainee);
  std::string s = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                  "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
                  "<title>mixpilot progress: " + name + "</title>\n" + kStyle + "</head>\n<body>\n";
  s += "<h1>Progress report: " + name + "</h1>\n<p class=\"meta\">" + std::to_string(rows.size()) +
       " flight" + (rows.size() == 1 ? "" : "s");
  if (!rows.empty())
    s += " from " + html_escape(local_minutes(rows.front().started_unix_ms)) + " to " +
         html_escape(local_minutes(rows.back().started_unix_ms));
  s += ". Written " + html_escape(local_minutes(generated_unix_ms)) + " by " +
       html_escape(version()) + ".</p>\n<p class=\"meta\">Skill is the flight's score: progress &times; "
       "quality / (1 + collisions), 0&ndash;100. An <em>assisted</em> flight shares control with "
       "the planner; a <em>probe</em> flight is unassisted, so its skill is the pilot's own. "
       "D, the assistance dependence, is the share of the flight the planner flew (0 none, 1 all "
       "of it): a learning pilot's skill rises and D falls. The trend is a least-squares line "
       "through the last " + std::to_string(kTrendAttempts) + " attempts.</p>\n";
  if (rows.empty()) s += "<p>No flights of this trainee in the history.</p>\n";
  for (const std::string& scenario : order)
    s += section_of(progress_view(by[scenario], trainee, scenario, false));
  s += "</body>\n</html>\n";
  return s;
}

}  // namespace mixpilot::cli
