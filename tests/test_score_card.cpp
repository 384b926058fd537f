// The score card (ui/score_card.hpp) and the palette that must read without colour
// (colour::kMustTellApart): the card's comparison with the history, its costly events and its
// suggestion from synthetic outcomes; the palette in greyscale and for red–green colour
// blindness; and two, then three flights of one scenario flown through the app (headless, an
// isolated history) whose cards show the change since the last flight and against the best.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/flight.hpp"
#include "app/flight_rig.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "core/history/history.hpp"
#include "ui/panels.hpp"
#include "ui/score_card.hpp"
#include "ui/theme.hpp"

#include "app_window_test.hpp"
#include "record_flight.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

namespace mixpilot {
namespace {

// ---- Colour vision ------------------------------------------------------------------------

using Rgb = std::array<double, 3>;  // linear RGB, 0 … 1

double linear(unsigned c8) {
  const double c = c8 / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}
Rgb linear_rgb(ImU32 c) { return {linear(c & 0xFF), linear((c >> 8) & 0xFF), linear((c >> 16) & 0xFF)}; }

// Relative luminance (WCAG 2.1, Rec. 709 primaries): what a greyscale rendering keeps.
double luminance(const Rgb& c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// WCAG 2.1 contrast ratio (L1 + 0.05) / (L2 + 0.05), L1 the lighter.
double contrast(double a, double b) { return (std::max(a, b) + 0.05) / (std::min(a, b) + 0.05); }

// Machado, Oliveira & Fernandes 2009, severity 1.0, on linear RGB (clamped to the gamut).
using Matrix = std::array<std::array<double, 3>, 3>;
constexpr Matrix kProtanopia{{{0.152286, 1.052583, -0.204868},
                              {0.114503, 0.786281, 0.099216},
                              {-0.003882, -0.048116, 1.051998}}};
constexpr Matrix kDeuteranopia{{{0.367322, 0.860646, -0.227968},
                                {0.280085, 0.672501, 0.047413},
                                {-0.011820, 0.042940, 0.968881}}};
Rgb simulate(const Matrix& m, const Rgb& c) {
  Rgb out{};
  for (int i = 0; i < 3; ++i)
    out[std::size_t(i)] = std::clamp(m[std::size_t(i)][0] * c[0] + m[std::size_t(i)][1] * c[1] +
                                         m[std::size_t(i)][2] * c[2],
                                     0.0, 1.0);
  return out;
}

struct Vision {
  const char* name;
  double (*luma)(ImU32);
};
const Vision kVisions[] = {
    {"normal vision", [](ImU32 c) { return luminance(linear_rgb(c)); }},
    // Greyscale keeps the luminance: the same ratio as normal vision, named for what it checks.
    {"greyscale", [](ImU32 c) {
       const double y = luminance(linear_rgb(c));
       return luminance(Rgb{y, y, y});
     }},
    {"protanopia", [](ImU32 c) { return luminance(simulate(kProtanopia, linear_rgb(c))); }},
    {"deuteranopia", [](ImU32 c) { return luminance(simulate(kDeuteranopia, linear_rgb(c))); }},
};

// The least contrast of a pair over the four visions, and the vision it is least in.
double least_contrast(ImU32 a, ImU32 b, const char** where = nullptr) {
  double least = 1e9;
  for (const Vision& v : kVisions) {
    const double r = contrast(v.luma(a), v.luma(b));
    if (r < least) {
      least = r;
      if (where) *where = v.name;
    }
  }
  return least;
}

// Every pair the screen tells apart by colour keeps a luminance contrast of 3:1 (WCAG 2.1 SC
// 1.4.11, graphical objects) in normal vision, greyscale, protanopia and deuteranopia: lightness
// is the one cue all four keep. The event marks use the colours of those pairs, one per
// severity; the kinds have distinct shapes. The check itself fails the palette it replaced (the
// Okabe–Ito sky blue and orange are equally light: 1.02:1).
TEST(ScoreCard, PaletteReadsInGreyscaleAndForRedGreenColourBlindness) {
  // The simulation keeps white white and black black (rows sum to 1).
  for (const Matrix* m : {&kProtanopia, &kDeuteranopia}) {
    const Rgb w = simulate(*m, Rgb{1, 1, 1});
    for (double x : w) EXPECT_NEAR(x, 1.0, 1e-3);
  }
  // A red and a green of one lightness (to 3 %) are told apart in normal vision only.
  const ImU32 red = ui::colour::rgb(0xE0, 0x40, 0x40), green = ui::colour::rgb(0x40, 0x9A, 0x40);
  EXPECT_LT(contrast(luminance(simulate(kDeuteranopia, linear_rgb(red))),
                     luminance(simulate(kDeuteranopia, linear_rgb(green)))),
            1.5);
  // The palette before: the authority bar's shares as light as each other.
  const char* where = nullptr;
  EXPECT_LT(least_contrast(ui::colour::rgb(0x56, 0xB4, 0xE9), ui::colour::rgb(0xE6, 0x9F, 0x00), &where),
            1.1);
  EXPECT_LT(least_contrast(ui::colour::rgb(0xF0, 0xE4, 0x42), ui::colour::rgb(0xD5, 0x5E, 0x00)),
            ui::colour::kLeastContrast)
      << "the old warning yellow and error vermilion";

  for (const ui::colour::Apart& p : ui::colour::kMustTellApart) {
    const double c = least_contrast(p.a, p.b, &where);
    EXPECT_GE(c, ui::colour::kLeastContrast) << p.where << ": " << c << ":1 in " << where;
    std::printf("  %-90s %5.2f:1 (least: %s)\n", p.where, c, where);
  }
  // The events' colours are those of the pairs: warnings, errors, notes.
  for (int k = 0; k < kDebriefKindCount; ++k) {
    const DebriefKind kind = DebriefKind(k);
    const ImU32 c = ui::event_colour(kind);
    const LogLevel level = log_level(kind);
    EXPECT_EQ(c, level == LogLevel::warn    ? ui::colour::kCaution
                 : level >= LogLevel::error ? ui::colour::kCritical
                                            : ui::colour::kNote)
        << to_string(kind);
  }
  // The trail's colour runs between the bar's two shares, lighter as λ rises in every vision:
  // λ reads from its lightness.
  EXPECT_EQ(ui::authority_colour(0.0), ui::colour::kPlannerFill);
  EXPECT_EQ(ui::authority_colour(1.0), ui::colour::kPilot);
  for (const Vision& v : kVisions)
    for (int i = 1; i <= 100; ++i)
      EXPECT_GT(v.luma(ui::authority_colour(0.01 * i)), v.luma(ui::authority_colour(0.01 * (i - 1))))
          << v.name << " at λ " << 0.01 * i;
}

// ---- The card from synthetic outcomes -----------------------------------------------------

// The score fields of a mixed-initiative flight whose skill follows core/modes/score.cpp.
Metrics mi_metrics(double progress, double in_ball, double lambda, double override_rms,
                   int collisions, double duration = 30.0) {
  const double quality = 0.4 * in_ball + 0.4 * lambda + 0.2 * std::exp(-override_rms / 0.1);
  const double skill = 100.0 * progress * quality / (1.0 + collisions);
  return {{"duration_s", duration},        {"progress", progress},
          {"time_in_ball", in_ball},       {"mean_lambda", lambda},
          {"assistance_dependence", 1.0 - lambda}, {"collisions", double(collisions)},
          {"override_rms", override_rms},  {"skill", skill}};
}

double field(const Metrics& m, const char* key) {
  for (const auto& [k, v] : m)
    if (k == key) return v;
  return NAN;
}

ui::DebriefRow row(DebriefKind kind, double t, double end, double extreme = 0.0) {
  DebriefEvent e;
  e.kind = kind;
  e.start = t;
  e.end = end;
  e.extreme = extreme;
  return ui::DebriefRow{t, end, kind, to_string(kind), e};
}

// What an event cost, in skill points, against the skill formula itself.
TEST(ScoreCard, EventCostsFollowTheSkillFormula) {
  // Collisions: one fewer gives back exactly its cost.
  const Metrics two = mi_metrics(0.9, 0.8, 0.7, 0.05, 2), one = mi_metrics(0.9, 0.8, 0.7, 0.05, 1);
  const double collision = ui::event_cost(row(DebriefKind::collision, 3, 3.2).event, two);
  EXPECT_NEAR(collision, field(one, "skill") - field(two, "skill"), 1e-9);
  // A takeover of 3 s down to λ 0.2 in a 30 s flight: at most its λ deficit through mean λ's
  // weight; had λ been 1 over it, mean λ would have been higher by at most 0.8 · 3 / 30.
  const Metrics m = mi_metrics(1.0, 0.9, 0.8, 0.02, 0);
  const double takeover = ui::event_cost(row(DebriefKind::takeover, 5, 8, 0.2).event, m);
  const Metrics better = mi_metrics(1.0, 0.9, 0.8 + 0.8 * 3.0 / 30.0, 0.02, 0);
  EXPECT_NEAR(takeover, field(better, "skill") - field(m, "skill"), 1e-9);
  // Input lost: λ held at 0 for its span.
  EXPECT_NEAR(ui::event_cost(row(DebriefKind::input_lost, 1, 4).event, m), 100 * 0.4 * 3.0 / 30.0, 1e-9);
  // Near misses and fallbacks cost no point; notes are no cost.
  EXPECT_EQ(ui::event_cost(row(DebriefKind::near_miss, 1, 2).event, m), 0.0);
  EXPECT_EQ(ui::event_cost(row(DebriefKind::fallback, 1, 2).event, m), 0.0);
  EXPECT_TRUE(std::isnan(ui::event_cost(row(DebriefKind::marker, 1, 1).event, m)));
  // A lost vehicle: the rest of the reference at this quality.
  Metrics lost = mi_metrics(0.5, 0.9, 0.8, 0.02, 0);
  EXPECT_NEAR(ui::event_cost(row(DebriefKind::lost, 10, 10).event, lost),
              field(mi_metrics(1.0, 0.9, 0.8, 0.02, 0), "skill") - field(lost, "skill"), 1e-9);
}

ui::HistoryView history_of(const std::vector<std::pair<double, bool>>& flights, std::int64_t this_start) {
  ui::HistoryView h;
  h.loaded = true;
  h.progress.trainee = "Ada";
  h.progress.scenario = "mi_helix";
  std::int64_t start = 1'000;
  for (const auto& [skill, probe] : flights) {
    ui::ProgressFlight f;
    f.skill = skill;
    f.probe = probe;
    f.started_unix_ms = start++;
    f.metrics = {{"skill", skill}};
    (probe ? h.progress.probes : h.progress.assisted)++;
    h.progress.flights.push_back(f);
  }
  h.progress.flights.back().started_unix_ms = this_start;
  return h;
}

ui::FlightOutcome outcome(const Metrics& m) {
  ui::FlightOutcome o;
  o.metrics = m;
  o.trainee = "Ada";
  o.scenario = "mi_helix";
  o.started_unix_ms = 42;
  o.events_ready = true;
  return o;
}

// The comparison: with the history, the first flight, a flight not yet written, no history, a
// probe compared with probes only; the costliest events; the suggestion's rules in order.
TEST(ScoreCard, ComparesWithTheHistoryAndSuggestsByItsRules) {
  const Metrics good = mi_metrics(1.0, 0.95, 0.70, 0.02, 0);  // skill ≈ 85, D 0.30
  ui::FlightOutcome o = outcome(good);
  const double skill = field(good, "skill");
  // Assisted flights 50, 90, 60 before this one (the last one in the list is this flight).
  ui::HistoryView h = history_of({{50, false}, {90, false}, {30, true}, {60, false}, {skill, false}}, 42);
  o.history = &h;
  ui::ScoreCard c = ui::score_card_of(o);
  char shown[16];
  std::snprintf(shown, sizeof shown, "%.1f", skill);
  EXPECT_EQ(c.score, shown);
  EXPECT_EQ(c.score_unit, "/ 100");
  ASSERT_EQ(c.comparison, ui::Comparison::compared) << c.note;
  EXPECT_NEAR(c.since_last, skill - 60, 1e-9);
  EXPECT_NEAR(c.against_best, skill - 90, 1e-9);
  EXPECT_FALSE(c.new_best);
  EXPECT_NE(c.last_text.find("since your last assisted flight (60.0)"), std::string::npos) << c.last_text;
  EXPECT_NE(c.best_text.find("from your best (90.0)"), std::string::npos) << c.best_text;
  EXPECT_NE(c.dependence.find("D = 0.30"), std::string::npos) << c.dependence;
  // Rule 4: a good skill leaning on the planner → a probe.
  EXPECT_NE(c.suggestion.find("probe flight"), std::string::npos) << c.suggestion;

  // Not yet in the history: being written; a first flight; no history at all.
  ui::HistoryView before = history_of({{50, false}}, 7);
  o.history = &before;
  EXPECT_EQ(ui::score_card_of(o).comparison, ui::Comparison::reading);
  ui::HistoryView first = history_of({{30, true}, {skill, false}}, 42);
  o.history = &first;
  c = ui::score_card_of(o);
  EXPECT_EQ(c.comparison, ui::Comparison::first);
  EXPECT_NE(c.note.find("your first assisted flight of mi_helix"), std::string::npos) << c.note;
  o.history = nullptr;
  c = ui::score_card_of(o);
  EXPECT_EQ(c.comparison, ui::Comparison::no_history);
  EXPECT_NE(c.note.find("--history off"), std::string::npos) << c.note;

  // A probe is compared with the probe before it, not the assisted flights.
  ui::FlightOutcome p = outcome(mi_metrics(1.0, 0.9, 1.0, 0.05, 0));
  p.probe = true;
  ui::HistoryView probes = history_of({{70, false}, {40, true}, {80, false}, {0, true}}, 42);
  p.history = &probes;
  c = ui::score_card_of(p);
  ASSERT_EQ(c.comparison, ui::Comparison::compared);
  EXPECT_NEAR(c.since_last, field(p.metrics, "skill") - 40, 1e-9);
  EXPECT_TRUE(c.new_best);

  // The costliest events first, notes never, at most three.
  ui::FlightOutcome e = outcome(mi_metrics(0.9, 0.6, 0.6, 0.05, 1));
  e.events = {row(DebriefKind::takeover, 2, 3, 0.3), row(DebriefKind::marker, 4, 4),
              row(DebriefKind::collision, 6, 6.2), row(DebriefKind::near_miss, 8, 9),
              row(DebriefKind::fallback, 10, 10.1), row(DebriefKind::takeover, 12, 20, 0.1)};
  c = ui::score_card_of(e);
  ASSERT_EQ(c.costly.size(), 3u);
  EXPECT_EQ(c.costly[0].kind, DebriefKind::collision);
  EXPECT_EQ(c.costly[0].index, 2);
  EXPECT_EQ(c.costly[1].index, 5);  // the long takeover
  EXPECT_EQ(c.costly[2].index, 0);
  EXPECT_NE(c.costly[1].cost_text.find("up to −"), std::string::npos) << c.costly[1].cost_text;
  // Rule 3: the collision cost more than half of it all.
  EXPECT_NE(c.suggestion.find("keeping clear"), std::string::npos) << c.suggestion;

  // Rule 1 before all: a lesson step passed.
  ui::LessonChoice lesson;
  lesson.verdict = "PASSED";
  lesson.verdict_passed = true;
  lesson.heading = "step 2 of 5: A gentle climb";
  lesson.next = "Next: step 3 (R)";
  e.lesson = &lesson;
  EXPECT_NE(ui::score_card_of(e).suggestion.find("Next lesson step"), std::string::npos);
  e.lesson = nullptr;

  // Rule 5: below the bar, the term that lost the most (time in B here).
  c = ui::score_card_of(outcome(mi_metrics(1.0, 0.2, 0.9, 0.02, 0)));  // skill 60.4
  EXPECT_NE(c.suggestion.find("inside the ball B"), std::string::npos) << c.suggestion;
  EXPECT_NE(c.suggestion_why.find("20 %"), std::string::npos) << c.suggestion_why;

  // Another mode: its own headline, no cost, no λ.
  ui::FlightOutcome t;
  t.mode = ModeKind::crazyflie_tracking;
  t.metrics = {{"tracking_rms_m", 0.0123}, {"fallbacks", 0}};
  t.events_ready = true;
  c = ui::score_card_of(t);
  EXPECT_TRUE(c.has_score);
  EXPECT_EQ(c.score, "1.23");
  EXPECT_EQ(c.score_unit, "cm");
  EXPECT_TRUE(c.dependence.empty());
  EXPECT_NE(c.suggestion.find("controller flew"), std::string::npos) << c.suggestion;
}

// Every mode's card puts a score of its own first, from a flight of its shipped scenario: a
// number, a unit, what it means; the suggestion and the raw fields whatever the mode.
TEST(ScoreCard, EveryModeHasAHeadline) {
  const std::pair<const char*, const char*> flights[] = {
      {"mi_helix.toml", "novice"},
      {"pendubot_swingup.toml", ""},
      {"tracking_smooth_step.toml", ""},
      {"obstacles_cluttered.toml", ""},
  };
  for (const auto& [file, pilot] : flights) {
    SCOPED_TRACE(file);
    cli::FlyOptions o;
    o.scenario_path = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + file;
    if (*pilot) o.pilot = pilot;
    o.duration = 3.0;
    std::string error;
    int status = 0;
    auto rig = cli::FlightRig::assemble(o, error, status);
    ASSERT_TRUE(rig) << error;
    rig->start();
    while (rig->step()) {
    }
    ui::FlightOutcome out;
    out.mode = rig->mode().kind();
    out.metrics = rig->metrics();
    out.events_ready = true;
    const ui::ScoreCard c = ui::score_card_of(out);
    ASSERT_TRUE(c.has_score) << to_string(out.mode);
    EXPECT_NE(c.score, "");
    EXPECT_NE(c.score_unit, "");
    EXPECT_STRNE(c.score_meaning.c_str(), "");
    EXPECT_EQ(c.comparison, ui::Comparison::no_history);
    EXPECT_FALSE(c.suggestion.empty());
    EXPECT_EQ(c.raw.size(), out.metrics.size());
    EXPECT_EQ(c.dependence.empty(), out.mode != ModeKind::mixed_initiative);
  }
}

// ---- Flights through the app --------------------------------------------------------------

std::string scenario(const char* name) {
  return std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/" + name;
}

void save_shot(const cli::Offscreen& screen, const std::string& name) {
  const char* dir = std::getenv("MIXPILOT_SHOT_DIR");
  if (!dir || !*dir) return;
  std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << screen.png();
}

class ScoreCardApp : public test::AppWindowTest {
 protected:
  // The history and the recordings in a folder of this test's own.
  static void fresh_home(const std::string& name) {
    const auto home = test::fresh_path("score_card", name);
    std::filesystem::create_directories(home);
    setenv("XDG_CONFIG_HOME", (home / "config").c_str(), 1);
    setenv("XDG_DATA_HOME", (home / "data").c_str(), 1);
  }
  void fly_three(float scale);
};

// Three flights of mi_helix by one trainee through the app (a pilot picked, Space), the history
// in a folder of the test's own: the first card says it is the first flight; the second shows
// the change since the first and against the best, as the history's rows give them; the third
// against the better of the two. The card stays inside the display with nothing cut. Saved as
// score_card_N_<percent>.png with MIXPILOT_SHOT_DIR.
void ScoreCardApp::fly_three(float scale) {
  const std::string at = scale > 1.0f ? "_150" : "_100";
  fresh_home("home" + at);
  std::string error;
  if (!screen_.open(1280, 720, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
  cli::FlyOptions o;
  o.scenario_path = scenario("mi_helix.toml");
  o.duration = 4.0;
  // The novice first, then the experienced pilot, then the reckless one: three skills apart.
  const char* pilots[] = {"novice", "experienced", "reckless"};
  o.pilot = pilots[0];
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.act(ui::LiveRequest{ui::SetTrainee{"Ada"}});
  frame(app);
  std::vector<double> skills;
  for (int flight = 0; flight < 3; ++flight) {
    SCOPED_TRACE("flight " + std::to_string(flight + 1) + at);
    if (flight > 0) {  // the next flight, READY: its pilot picked in the session panel
      const ui::SessionChoices& c = *app.run_info().session;
      const auto it = std::find(c.pilots.begin(), c.pilots.end(), pilots[flight]);
      ASSERT_NE(it, c.pilots.end()) << pilots[flight];
      app.act(ui::LiveRequest{ui::PickPilot{int(it - c.pilots.begin())}});
      frame(app);
      ASSERT_EQ(app.run_info().state, ui::RunState::ready);
      EXPECT_EQ(app.run_info().card, nullptr) << "a card before the flight";
    }
    key(app, ui::Key::space);  // Start
    ASSERT_TRUE(app.live()->started());
    until_over(app);
    ASSERT_TRUE(app.over());
    // The card, once the flight is in the history.
    ASSERT_TRUE(frames_until(app, [&] {
      const ui::ScoreCard* c = app.run_info().card;
      return c && c->comparison != ui::Comparison::reading;
    })) << (app.run_info().card ? app.run_info().card->note : "no card");
    frame(app);
    frame(app);
    const ui::ScoreCard& c = *app.run_info().card;
    const double skill = field(app.run_info().metrics, "skill");
    ASSERT_TRUE(std::isfinite(skill));
    char shown[16];
    std::snprintf(shown, sizeof shown, "%.1f", skill);
    EXPECT_EQ(c.score, shown);
    EXPECT_FALSE(c.dependence.empty());
    EXPECT_FALSE(c.suggestion.empty());
    if (flight == 0) {
      EXPECT_EQ(c.comparison, ui::Comparison::first) << c.note;
      EXPECT_NE(c.note.find("first assisted flight of mi_helix"), std::string::npos) << c.note;
    } else {
      ASSERT_EQ(c.comparison, ui::Comparison::compared) << c.note;
      const double best = *std::max_element(skills.begin(), skills.end());
      EXPECT_NEAR(c.since_last, skill - skills.back(), 1e-9);
      EXPECT_NEAR(c.against_best, skill - best, 1e-9);
      EXPECT_EQ(c.new_best, skill > best);
      EXPECT_NE(c.last_text.find(" since your last assisted flight ("), std::string::npos);
    }
    // What the window shows: the card, inside the display, nothing cut.
    const ImGuiWindow* w = ImGui::FindWindowByName("Score card");
    ASSERT_TRUE(w && w->Active);
    for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
    save_shot(screen_, "score_card_" + std::to_string(flight + 1) + at);
    skills.push_back(skill);
  }
  std::printf("  skills %.1f, %.1f, %.1f\n", skills[0], skills[1], skills[2]);
}

TEST_F(ScoreCardApp, TheSecondFlightShowsTheChangeSinceTheFirstAndTheBest) { fly_three(1.0f); }
TEST_F(ScoreCardApp, TheCardOfThreeFlightsAt150Percent) { fly_three(1.5f); }

// A replay's card: its costly events are the replay's debrief events, and a click on one puts
// the playhead at its start (selected, as in the Debrief panel).
TEST_F(ScoreCardApp, AReplaysCostlyEventJumpsThereWhenClicked) {
  fresh_home("replay");
  std::string error;
  if (!screen_.open(1280, 720, error)) GTEST_SKIP() << "no EGL device: " << error;
  // The reckless pilot's flight: the planner takes over.
  cli::FlyOptions fly;
  fly.scenario_path = scenario("mi_helix.toml");
  fly.pilot = "reckless";
  fly.duration = 6.0;
  const std::string path = test::fresh_path("score_card", "reckless.mcap").string();
  ASSERT_TRUE(test::record_flight(fly, path));

  cli::FlyOptions o;
  o.replay = true;
  o.pilot = path;
  cli::Trainer app(o);
  ASSERT_TRUE(app.open_replay(path, error)) << error;
  app.load_replay();
  app.seek(1e9);  // the end: the card shows
  ASSERT_TRUE(frames_until(app, [&] { return app.run_info().card != nullptr; }));
  frame(app);
  const ui::ScoreCard& c = *app.run_info().card;
  ASSERT_FALSE(c.costly.empty()) << c.events_note;
  // Not flown by the trainee shown: nothing to compare, said why.
  EXPECT_NE(c.comparison, ui::Comparison::compared);
  EXPECT_FALSE(c.note.empty());
  const ui::CardEvent& e = c.costly.front();
  const ui::ReplayInfo& r = *app.run_info().replay;
  ASSERT_LT(std::size_t(e.index), r.events.size());
  EXPECT_EQ(r.events[std::size_t(e.index)].kind, e.kind);
  EXPECT_NE(r.selected, e.index);
  // The row's item: "##costly" under the event's index in the card's window.
  ImGuiWindow* w = ImGui::FindWindowByName("Score card");
  ASSERT_TRUE(w && w->Active);
  const ImGuiID id = ImHashStr("##costly", 0, ImHashData(&e.index, sizeof e.index, w->ID));
  std::optional<ImVec2> at;
  for (float y = w->Rect().Min.y + 2; y < w->Rect().Max.y && !at; y += 4)
    for (float x = w->Rect().Min.x + 20; x < w->Rect().Max.x && !at; x += 40) {
      ImGui::GetIO().MousePos = ImVec2(x, y);
      screen_.layout([&] { app.build_frame(0.0); }, 1e-4f);
      if (GImGui->HoveredId == id) at = ImVec2(x, y);
    }
  ASSERT_TRUE(at) << "the costliest event's row is not on the card";
  click(app, *at);
  EXPECT_EQ(app.run_info().replay->selected, e.index);
  EXPECT_NEAR(app.run_info().replay->t, e.t, 1e-9);
  EXPECT_NEAR(app.shown_time(), e.t, 0.011);
}

}  // namespace
}  // namespace mixpilot
