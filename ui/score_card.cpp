#include "ui/score_card.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double field(const Metrics& m, const char* key) {
  for (const auto& [k, v] : m)
    if (k == key) return v;
  return kNaN;
}

std::string printed(const char* fmt, double v) {
  char text[64];
  std::snprintf(text, sizeof text, fmt, v);
  return text;
}

// The same recording: the same path, or the same file reached another way.
bool same_file(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  if (a == b) return true;
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

}  // namespace

const Headline* headline_of(ModeKind mode, const Metrics& metrics) {
  static constexpr Headline kSkill{"skill", "skill", "/ 100", 1.0, true, "%.1f"};
  static constexpr Headline kHold{"hold_time_s", "balanced at the top", "s", 1.0, true, "%.2f"};
  static constexpr Headline kTracking{"tracking_rms_m", "RMS tracking error", "cm", 100.0, false,
                                      "%.2f"};
  static constexpr Headline kMargin{"min_margin_m", "closest approach beyond the clearance", "cm",
                                    100.0, true, "%.1f"};
  const Headline* h = nullptr;
  switch (mode) {
    case ModeKind::mixed_initiative: h = &kSkill; break;
    case ModeKind::pendubot_swingup: h = &kHold; break;
    case ModeKind::crazyflie_tracking: h = &kTracking; break;
    case ModeKind::obstacle_avoidance: h = &kMargin; break;
  }
  return h && std::isfinite(field(metrics, h->key)) ? h : nullptr;
}

// What each field of every mode's report means (README, Scoring), for the raw fields.
const char* score_field_meaning(const std::string& key) {
  static const std::pair<const char*, const char*> kMeanings[] = {
      {"duration_s", "time flown [s]"},
      {"progress", "share of the reference flown"},
      {"time_in_ball", "share of the time inside the ball B"},
      {"max_deviation_m", "largest distance from the reference [m]"},
      {"rms_deviation_m", "RMS distance from the reference [m]"},
      {"mean_lambda", "mean authority of the pilot (1: all pilot)"},
      {"min_lambda", "least authority of the pilot"},
      {"assistance_dependence", "share of the flight the planner flew: mean of 1 - lambda"},
      {"collisions", "contacts with obstacles, walls or floor"},
      {"min_clearance_m", "closest approach to an obstacle [m]"},
      {"override_rms", "RMS of what the MPC changed in the pilot's tilt [rad]"},
      {"stick_smoothness", "RMS change of the pilot's command per step [rad]"},
      {"rti_median_us", "median RTI time per step [us]"},
      {"rti_p99_us", "99th percentile RTI time [us]"},
      {"deadline_misses", "steps whose control came after their period (real time only)"},
      {"fallbacks", "steps that applied the previous solution's input"},
      {"skill", "the score: progress x quality / (1 + collisions), 0-100"},
      {"input_lost_s", "time the pilot's input was lost: the planner flew [s]"},
      {"safe_hold_s", "time the safe controller flew: the MPC fell behind [s]"},
      {"lost", "1: the vehicle was lost"},
      {"lost_at_s", "when it was lost [s]"},
      {"rtt_s", "round-trip time to the vehicle (remote: the median sample) [s]"},
      {"rtt_estimated_s", "the online round-trip estimate at the end [s]"},
      // Pendubot swing-up (SPEC §5.1).
      {"swingup_time_s", "when both links reached up-up and stayed there [s]"},
      {"hold_time_s", "time balanced at up-up after the swing-up [s]"},
      {"final_angle_norm", "distance of the links from up-up at the end [rad]"},
      {"max_abs_u", "largest shoulder torque applied [N m]"},
      {"velocity_violations", "steps whose joint speeds exceeded their bounds"},
      {"worst_velocity_violation", "largest excess of a joint speed over its bound [rad/s]"},
      {"tracking_rms", "RMS angle error against the swing-up reference [rad]"},
      {"rti_max_us", "longest RTI time of a step [us]"},
      {"nmpc_steps", "steps flown by the NMPC (the others by the LQR)"},
      {"lqr_entry_time_s", "when the LQR first took over near the top [s]"},
      {"lqr_time_s", "time flown by the LQR [s]"},
      {"lqr_entries", "times the LQR took over"},
      {"quantization", "1: angles read through quantizing encoders"},
      // Tracking under delay (SPEC §5.2) and obstacle avoidance (SPEC §5.3).
      {"tracking_rms_m", "RMS distance from the reference [m]"},
      {"max_error_m", "largest distance from the reference [m]"},
      {"final_error_m", "distance from the reference at the end [m]"},
      {"overshoot_m", "how far past the step's target the vehicle went [m]"},
      {"settle_time_s", "when the vehicle last entered 5 cm of the target [s]"},
      {"lqr_median_us", "median LQR time per step [us]"},
      {"lqr_p99_us", "99th percentile LQR time [us]"},
      {"predictor_median_us", "median time of the delay predictor per step [us]"},
      {"max_input_violation", "largest excess of a rotor command over its bounds [krpm]"},
      {"compensation", "1: the state was predicted over the round trip"},
      {"steps", "control steps flown"},
      {"min_distance_m", "closest approach to an obstacle's centre [m]"},
      {"min_margin_m", "closest approach less the clearance d_C [m]"},
      {"min_distance_control_m", "closest approach at the control instants [m]"},
      {"clearance_m", "the clearance d_C the constraint keeps [m]"},
      {"violations", "steps that came closer than d_C"},
      {"form", "0: the LCL constraint, 1: the squared form"},
  };
  for (const auto& [k, v] : kMeanings)
    if (key == k) return v;
  return "";
}

double event_cost(const DebriefEvent& e, const Metrics& m) {
  const double skill = field(m, "skill"), progress = field(m, "progress");
  const double collisions = std::max(0.0, field(m, "collisions"));
  const double T = field(m, "duration_s");
  if (!std::isfinite(skill) || !std::isfinite(progress)) return kNaN;
  // Skill points per unit of quality.
  const double per_quality = 100.0 * progress / (1.0 + (std::isfinite(collisions) ? collisions : 0.0));
  const double share = T > 0.0 ? std::clamp(e.duration() / T, 0.0, 1.0) : 0.0;
  // No event's λ deficit exceeds the whole flight's, D · T (D = 1 − mean λ).
  const double d = field(m, "assistance_dependence");
  const double whole = std::isfinite(d) ? std::clamp(d, 0.0, 1.0) : 1.0;
  switch (e.kind) {
    case DebriefKind::collision:
      return collisions >= 1.0 ? skill / collisions : kNaN;
    case DebriefKind::takeover:
      return per_quality * 0.4 * std::min(std::clamp(1.0 - e.extreme, 0.0, 1.0) * share, whole);
    case DebriefKind::input_lost:
    case DebriefKind::safe_hold:
      return per_quality * 0.4 * std::min(share, whole);
    case DebriefKind::lost:
      return progress > 0.0 ? skill * (1.0 - progress) / progress : kNaN;
    case DebriefKind::near_miss:
    case DebriefKind::fallback:
      return 0.0;
    case DebriefKind::marker:
    case DebriefKind::instructor:
      return kNaN;
  }
  return kNaN;
}

namespace {

std::string cost_words(DebriefKind k, double cost) {
  if (!std::isfinite(cost)) return "";
  if (k == DebriefKind::near_miss || k == DebriefKind::fallback) return "no points";
  const char* how = k == DebriefKind::collision ? ""
                    : k == DebriefKind::lost    ? "about "
                                                : "up to ";
  char text[48];
  std::snprintf(text, sizeof text, "%s−%.1f skill", how, cost);
  return text;
}

// The events that cost the most (notes never), costliest first; those without a cost by
// severity, then the longest first.
void costly_events(const FlightOutcome& o, ScoreCard& c) {
  if (!o.events_ready) {
    c.events_note = "listed once the whole flight has loaded";
    return;
  }
  std::vector<CardEvent> all;
  for (std::size_t i = 0; i < o.events.size(); ++i) {
    const DebriefRow& r = o.events[i];
    if (log_level(r.kind) <= LogLevel::info) continue;
    CardEvent e;
    e.index = int(i);
    e.kind = r.kind;
    e.t = r.t;
    e.end = r.end;
    e.what = r.text;
    if (o.mode == ModeKind::mixed_initiative) e.cost = event_cost(r.event, o.metrics);
    e.cost_text = cost_words(r.kind, e.cost);
    all.push_back(std::move(e));
  }
  const auto rank = [](const CardEvent& a, const CardEvent& b) {
    const double ca = std::isfinite(a.cost) ? a.cost : -1.0, cb = std::isfinite(b.cost) ? b.cost : -1.0;
    if (ca != cb) return ca > cb;
    if (log_level(a.kind) != log_level(b.kind)) return log_level(a.kind) > log_level(b.kind);
    if (a.end - a.t != b.end - b.t) return a.end - a.t > b.end - b.t;
    return a.t < b.t;
  };
  std::stable_sort(all.begin(), all.end(), rank);
  if (all.size() > kCostlyEvents) all.resize(kCostlyEvents);
  c.costly = std::move(all);
  if (c.costly.empty())
    c.events_note = "nothing to debrief: no takeover, near miss, collision, input loss or fallback";
}

// The change since the trainee's last flight of this kind (assisted or probe) of the scenario and
// against their best before it.
void compare(const FlightOutcome& o, const Headline& h, double value, ScoreCard& c) {
  const char* kind = o.mode != ModeKind::mixed_initiative ? "" : o.probe ? "probe " : "assisted ";
  if (!o.history) {
    c.comparison = Comparison::no_history;
    c.note = "no change shown: this window keeps no history (--history off)";
    return;
  }
  const ProgressView& v = o.history->progress;
  if (!o.history->loaded || v.trainee.empty()) {
    c.comparison = Comparison::reading;
    c.note = "reading the history...";
    return;
  }
  if (!v.error.empty()) {
    c.comparison = Comparison::no_history;
    c.note = "no change shown: the history could not be read (" + v.error + ")";
    return;
  }
  if (v.trainee != o.trainee || v.scenario != o.scenario) {
    c.comparison = Comparison::none;
    c.note = "no change shown: the history shown now is " + v.trainee + "'s of " + v.scenario;
    return;
  }
  int at = -1;
  for (std::size_t i = 0; i < v.flights.size() && at < 0; ++i) {
    const ProgressFlight& f = v.flights[i];
    if (o.replay ? same_file(f.recording, o.recording)
                 : o.started_unix_ms > 0 && f.started_unix_ms == o.started_unix_ms)
      at = int(i);
  }
  if (at < 0) {
    if (o.replay) {
      c.comparison = Comparison::none;
      c.note = "no change shown: this recording is not among " + o.trainee + "'s flights of " +
               o.scenario + " in the history";
    } else {
      c.comparison = Comparison::reading;
      c.note = "writing this flight into the history...";
    }
    return;
  }
  double last = kNaN, best = kNaN;
  int other_kind = 0;
  for (int i = 0; i < at; ++i) {
    const ProgressFlight& f = v.flights[std::size_t(i)];
    if (f.probe != o.probe) {
      ++other_kind;
      continue;
    }
    const double x = field(f.metrics, h.key);
    if (!std::isfinite(x)) continue;
    last = x;
    if (!std::isfinite(best) || (h.higher_is_better ? x > best : x < best)) best = x;
  }
  if (!std::isfinite(last)) {
    c.comparison = Comparison::first;
    c.note = "your first " + std::string(kind) + "flight of " + o.scenario +
             ": nothing to compare with yet";
    if (other_kind > 0)
      c.note += " (" + std::to_string(other_kind) + (o.probe ? " assisted" : " probe") +
                " flight" + (other_kind == 1 ? "" : "s") + " before it: " +
                std::string(o.probe ? "a probe is compared with probes"
                                 : "assisted flights with assisted ones") +
                ")";
    return;
  }
  c.comparison = Comparison::compared;
  const double sign = h.higher_is_better ? 1.0 : -1.0;
  c.since_last = sign * (value - last) * h.scale;
  c.against_best = sign * (value - best) * h.scale;
  c.new_best = c.against_best > 0.0;
  const auto shown = [&](double x) { return printed(h.format, x * h.scale); };
  const auto delta = [&](double d) {
    const double raw = d * sign;  // the shown value's own change
    std::string s = printed(h.format, std::abs(raw));
    return (raw > 0 ? "+" : raw < 0 ? "−" : "±") + s;
  };
  const auto verdict = [](double d) { return d > 0 ? "better" : d < 0 ? "worse" : "the same"; };
  c.last_text = delta(c.since_last) + " since your last " + kind + "flight (" + shown(last) +
                "): " + verdict(c.since_last);
  if (c.new_best)
    c.best_text = "a new best: " + delta(c.against_best) + " on your best before (" + shown(best) + ")";
  else if (c.against_best == 0.0)
    c.best_text = "equals your best (" + shown(best) + ")";
  else
    c.best_text = delta(c.against_best) + " from your best (" + shown(best) + ")";
}

std::string percent(double share) { return printed("%.0f %%", 100.0 * share); }

void dependence(const FlightOutcome& o, ScoreCard& c) {
  if (o.mode != ModeKind::mixed_initiative) return;
  const double d = field(o.metrics, "assistance_dependence");
  if (!std::isfinite(d)) return;
  if (o.probe) {
    c.dependence = "a probe flight: the planner did not assist, the skill is your own (D = 0)";
    return;
  }
  const char* words = d < 0.1           ? "you flew almost all of it yourself"
                      : d < kLeaning    ? "you flew most of it yourself"
                      : d < 0.5         ? "the planner helped a lot"
                                        : "the planner flew most of it";
  char text[200];
  std::snprintf(text, sizeof text,
                "assistance dependence D = %.2f: the planner flew %s of the flight; %s", d,
                percent(d).c_str(), words);
  c.dependence = text;
}

// The first rule that applies (the top of score_card.hpp).
void suggest(const FlightOutcome& o, ScoreCard& c) {
  // 1. A lesson step.
  if (o.lesson && !o.lesson->verdict.empty()) {
    if (o.lesson->verdict_passed) {
      c.suggestion = "Next lesson step" + (o.lesson->next.empty() ? "" : ": " + o.lesson->next);
      c.suggestion_why = "you passed " + o.lesson->heading;
    } else {
      c.suggestion = o.lesson->next.empty() ? "Try the step again" : o.lesson->next;
      c.suggestion_why = o.lesson->verdict;
    }
    return;
  }
  // 2. The vehicle was lost.
  if (field(o.metrics, "lost") >= 1.0) {
    c.suggestion = "Fly it again, and keep the vehicle in the arena";
    c.suggestion_why = "the vehicle was lost at " + printed("%.1f s", field(o.metrics, "lost_at_s")) +
                       ": the flight ended there";
    return;
  }
  if (o.mode != ModeKind::mixed_initiative) {
    c.suggestion = "Nothing to practise: the thesis's controller flew";
    c.suggestion_why = "compare it with another scenario or other settings (mixpilot sweep)";
    return;
  }
  // 3. One kind of event dominates what the events cost.
  double total = 0.0, kinds[kDebriefKindCount] = {};
  int counts[kDebriefKindCount] = {};
  for (const DebriefRow& r : o.events) {
    const double cost = event_cost(r.event, o.metrics);
    if (!std::isfinite(cost)) continue;
    total += cost;
    kinds[int(r.kind)] += cost;
    ++counts[int(r.kind)];
  }
  int top = 0;
  for (int k = 1; k < kDebriefKindCount; ++k)
    if (kinds[k] > kinds[top]) top = k;
  if (kinds[top] >= kDominantCost && kinds[top] >= 0.5 * total) {
    const int n = counts[top];
    char why[200];
    const char* practise = "";
    switch (DebriefKind(top)) {
      case DebriefKind::collision:
        practise = "Practise keeping clear: fly it again watching the obstacles and walls";
        std::snprintf(why, sizeof why, "%d collision%s cost %.1f skill: the score is divided by "
                      "1 + collisions", n, n == 1 ? "" : "s", kinds[top]);
        break;
      case DebriefKind::takeover:
        practise = "Practise staying inside the ball B, so the planner need not take over";
        std::snprintf(why, sizeof why, "the planner took over %d time%s, up to %.1f skill", n,
                      n == 1 ? "" : "s", kinds[top]);
        break;
      case DebriefKind::input_lost:
        practise = "Check the gamepad: its cable, its batteries, its distance";
        std::snprintf(why, sizeof why, "your input was lost %d time%s, up to %.1f skill", n,
                      n == 1 ? "" : "s", kinds[top]);
        break;
      default:
        practise = "Close other programs: this machine fell behind";
        std::snprintf(why, sizeof why, "the safe controller flew %d time%s, up to %.1f skill", n,
                      n == 1 ? "" : "s", kinds[top]);
        break;
    }
    c.suggestion = practise;
    c.suggestion_why = why;
    return;
  }
  const double skill = field(o.metrics, "skill");
  const double d = field(o.metrics, "assistance_dependence");
  // 4. Good, but leaning on the planner.
  if (!o.probe && skill >= kGoodSkill && d >= kLeaning) {
    c.suggestion = "Try a probe flight: switch Assist off in the session panel";
    c.suggestion_why = "your skill is good (" + printed("%.1f", skill) + ") but the planner flew " +
                       percent(d) + " of the flight: a probe shows your own skill";
    return;
  }
  // 5. Below the bar: the part of the skill that lost the most.
  if (skill < kGoodSkill) {
    const double progress = field(o.metrics, "progress"), in_ball = field(o.metrics, "time_in_ball");
    const double lambda = field(o.metrics, "mean_lambda"), over = field(o.metrics, "override_rms");
    const double quality = 0.4 * in_ball + 0.4 * lambda + 0.2 * std::exp(-over / 0.1);
    const double losses[] = {0.4 * (1.0 - in_ball) * progress, 0.4 * (1.0 - lambda) * progress,
                             0.2 * (1.0 - std::exp(-over / 0.1)) * progress,
                             (1.0 - progress) * quality};
    const int worst = int(std::max_element(std::begin(losses), std::end(losses)) - std::begin(losses));
    switch (worst) {
      case 0:
        c.suggestion = "Practise staying inside the ball B";
        c.suggestion_why = "you were inside it " + percent(in_ball) + " of the time: that cost the most";
        break;
      case 1:
        c.suggestion = "Practise keeping the authority: fly so the planner need not correct you";
        c.suggestion_why = "your mean λ was " + printed("%.2f", lambda) + ": the planner held the rest";
        break;
      case 2:
        c.suggestion = "Practise smoother sticks";
        c.suggestion_why = "the MPC corrected your tilt by " + printed("%.3f", over) +
                           " rad RMS: that cost the most";
        break;
      default:
        c.suggestion = "Practise keeping up with the reference";
        c.suggestion_why = "you reached " + percent(progress) + " of it: that cost the most";
        break;
    }
    return;
  }
  // 6. Good and flown mostly alone.
  const bool probed = o.history && o.history->progress.probes > 0 &&
                      o.history->progress.scenario == o.scenario;
  if (!o.probe && !probed) {
    c.suggestion = "Try a probe flight: switch Assist off in the session panel";
    c.suggestion_why = "a probe shows your own skill on " + o.scenario + "; you have flown none yet";
  } else {
    c.suggestion = "Move on: a harder scenario, or the next step of a lesson";
    c.suggestion_why = "skill " + printed("%.1f", skill) + " with the planner flying " + percent(d) +
                       " of it";
  }
}

}  // namespace

ScoreCard score_card_of(const FlightOutcome& o) {
  ScoreCard c;
  c.raw = o.metrics;
  if (const Headline* h = headline_of(o.mode, o.metrics)) {
    const double value = field(o.metrics, h->key);
    c.has_score = true;
    c.score_name = h->name;
    c.score = printed(h->format, value * h->scale);
    c.score_unit = h->unit;
    c.score_meaning = score_field_meaning(h->key);
    compare(o, *h, value, c);
  } else {
    c.comparison = Comparison::none;
    c.note = "no score to compare: this flight's report has no headline field";
  }
  dependence(o, c);
  costly_events(o, c);
  suggest(o, c);
  return c;
}

void draw_score_card(const ScoreCard& c, bool replay, bool& open, ImVec2 display, Requests& out) {
  const ImGuiStyle& st = ImGui::GetStyle();
  const float em = ImGui::GetFontSize(), margin = em;
  const float width = std::min(34.0f * em, display.x - 2.0f * margin);
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0),
                                      ImVec2(width, std::max(1.0f, display.y - 2.0f * margin)));
  // Opaque: the plots' and the HUD's text behind it would show through the theme's panels.
  ImGui::SetNextWindowBgAlpha(1.0f);
  ImGui::Begin("Score card", &open,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove);
  ImGui::PushTextWrapPos(0.0f);
  const ImVec4 dim = st.Colors[ImGuiCol_TextDisabled];

  // The score, large, and what it is.
  if (c.has_score) {
    ImGui::TextColored(dim, "%s", c.score_name.c_str());
    ImFont* large = large_font();
    const ImVec2 at = ImGui::GetCursorScreenPos();
    if (large) ImGui::PushFont(large);
    else ImGui::SetWindowFontScale(kLargeFactor);
    ImGui::TextUnformatted(c.score.c_str());
    const ImVec2 number = ImGui::GetItemRectSize();
    if (large) ImGui::PopFont();
    else ImGui::SetWindowFontScale(1.0f);
    // The unit after the number, on its baseline (within the number's line).
    ImGui::GetWindowDrawList()->AddText(
        ImVec2(at.x + number.x + 0.4f * em, at.y + number.y - ImGui::GetTextLineHeight() - scaled(3)),
        colour::kText, c.score_unit.c_str());
    ImGui::TextColored(dim, "%s", c.score_meaning.c_str());
  }
  // The change since the last flight and against the best: an arrow's shape and a sign, not
  // colour alone.
  ImGui::Spacing();
  // Two lines whatever the comparison says: the card keeps its height when the history's answer
  // comes (ImGui fits a window to what it held the frame before).
  const float compare_y = ImGui::GetCursorPosY();
  if (c.comparison == Comparison::compared) {
    const auto line = [](double change, const std::string& text) {
      ImGui::TextUnformatted(change > 0 ? "▲" : change < 0 ? "▼" : "=");
      ImGui::SameLine();
      ImGui::TextUnformatted(text.c_str());
    };
    line(c.since_last, c.last_text);
    line(c.against_best, c.best_text);
  } else {
    ImGui::TextUnformatted(c.note.c_str());
  }
  const float two_lines = 2.0f * ImGui::GetTextLineHeightWithSpacing();
  if (ImGui::GetCursorPosY() + st.ItemSpacing.y < compare_y + two_lines)
    ImGui::Dummy(ImVec2(0.0f, compare_y + two_lines - ImGui::GetCursorPosY() - st.ItemSpacing.y));
  if (!c.dependence.empty()) {
    ImGui::Spacing();
    ImGui::TextUnformatted(c.dependence.c_str());
  }

  // The events that cost the most.
  ImGui::Separator();
  ImGui::TextColored(dim, "%s", "What cost the most");
  if (c.costly.empty()) {
    ImGui::TextUnformatted(c.events_note.c_str());
  } else {
    const float mark_w = 1.2f * em;
    const float time_w = ImGui::CalcTextSize("000.0 s").x + st.ItemInnerSpacing.x;
    const float row_w = ImGui::GetContentRegionAvail().x;
    const float words_w = std::max(4.0f * em, row_w - mark_w - time_w);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    for (const CardEvent& e : c.costly) {
      const std::string words = e.cost_text.empty() ? e.what : e.what + "  (" + e.cost_text + ")";
      const float h = ImGui::GetFont()->CalcTextSizeA(em, FLT_MAX, words_w, words.c_str()).y;
      const ImVec2 p = ImGui::GetCursorScreenPos();
      ImGui::PushID(e.index);
      if (ImGui::Selectable("##costly", false, replay ? 0 : ImGuiSelectableFlags_Disabled,
                            ImVec2(row_w, h)) &&
          replay)
        out.emplace_back(std::in_place_type<ReplayRequest>, SelectEvent{e.index});
      if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
        if (replay)
          ImGui::SetTooltip("%s, %.2f to %.2f s: click to jump there (End comes back to this card)",
                            to_string(e.kind), e.t, e.end);
        else
          ImGui::SetTooltip("%s, %.2f to %.2f s: in a replay of the recording a click jumps there", to_string(e.kind),
                            e.t, e.end);
      }
      ImGui::PopID();
      draw_event_mark(dl, ImVec2(p.x + 0.5f * mark_w, p.y + 0.5f * ImGui::GetTextLineHeight()),
                      0.3f * em, e.kind);
      char time[24];
      std::snprintf(time, sizeof time, "%.1f s", e.t);
      const float tw = ImGui::CalcTextSize(time).x;
      dl->AddText(ImVec2(p.x + mark_w + time_w - st.ItemInnerSpacing.x - tw, p.y), colour::kText, time);
      dl->AddText(ImGui::GetFont(), em, ImVec2(p.x + mark_w + time_w, p.y), colour::kText,
                  words.c_str(), nullptr, words_w);
    }
  }

  // The suggestion.
  ImGui::Separator();
  ImGui::TextColored(dim, "%s", "Next");
  ImGui::TextUnformatted(c.suggestion.c_str());
  ImGui::TextColored(dim, "%s", c.suggestion_why.c_str());

  // The raw fields, one click away.
  ImGui::Separator();
  char header[64];
  std::snprintf(header, sizeof header, "All %zu score fields###fields", c.raw.size());
  const bool fields = ImGui::CollapsingHeader(header);
  if (ImGui::IsItemHovered())
    ImGui::SetTooltip("every field of the flight's report with what it means (mixpilot fly --report "
                      "writes them as JSON)");
  ImGui::PopTextWrapPos();
  if (fields) {
    float key_w = 0.0f;
    for (const auto& [key, value] : c.raw) key_w = std::max(key_w, ImGui::CalcTextSize(key.c_str()).x);
    ImGui::PushFont(mono_font());
    const float value_w = ImGui::CalcTextSize("-0.0000e+00").x;
    ImGui::PopFont();
    const float meaning_w = std::max(6.0f * em, ImGui::GetContentRegionAvail().x - key_w - value_w -
                                                    6.0f * st.CellPadding.x - st.ScrollbarSize);
    if (ImGui::BeginTable("##score", 3, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
      ImGui::TableSetupColumn("key", ImGuiTableColumnFlags_WidthFixed, key_w);
      ImGui::TableSetupColumn("value", ImGuiTableColumnFlags_WidthFixed, value_w);
      ImGui::TableSetupColumn("meaning", ImGuiTableColumnFlags_WidthFixed, meaning_w);
      for (const auto& [key, value] : c.raw) {
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        ImGui::TextUnformatted(key.c_str());
        ImGui::TableNextColumn();
        ImGui::PushFont(mono_font());
        ImGui::Text("%10.4g", value);
        ImGui::PopFont();
        ImGui::TableNextColumn();
        ImGui::PushStyleColor(ImGuiCol_Text, dim);
        ImGui::TextWrapped("%s", score_field_meaning(key));
        ImGui::PopStyleColor();
      }
      ImGui::EndTable();
    }
  }
  ImGui::End();
}

}  // namespace mixpilot::ui
