#include "ui/first_launch.hpp"

#include <algorithm>
#include <cstdio>
#include <iterator>
#include <string>

#include <imgui_internal.h>  // the callout's size in the last frame

#include "ui/panels.hpp"
#include "ui/shortcuts.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

namespace {

constexpr TourStep kTour[] = {
    {TourTarget::authority_bar, "Who flies: the authority bar",
     "The bar is lambda (λ), your share of the controls. Full to the right (PILOT, blue): you "
     "fly alone. Towards the left (PLANNER, orange): the planner flies more. λ falls when the "
     "flight ahead would leave the ball B, and comes back as you do."},
    {TourTarget::ball, "The ball B",
     "The ring around the reference point: where the path says to be now. Stay inside it and "
     "the controls stay yours. The white line is the path, the green one the planner's plan "
     "for the next second, and your trail takes the bar's colours."},
    {TourTarget::sticks, "The sticks",
     "Left: thrust and yaw; right: pitch and roll. The filled dot is your command, the diamond "
     "what the vehicle was given: a line between them is the planner's correction."},
    {TourTarget::start, "Ready",
     "Space starts the flight and pauses it, R flies it again, and a score card ends it. F1 "
     "lists every key and shows this tour again; Tab takes the keyboard into the panels."},
};

void tip(const char* text) {
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
}

// A way in: a wide button with its number, and what it does under it.
bool way_button(const char* label, const char* what, const char* tooltip) {
  const bool pressed = ImGui::Button(label, ImVec2(-1.0f, 0.0f));
  tip(tooltip);
  ImGui::Indent();
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("%s", what);
  ImGui::PopStyleColor();
  ImGui::Unindent();
  ImGui::Spacing();
  return pressed;
}

void choose(WayIn way, UiState& ui, Requests& out) {
  out.push_back(FirstLaunchChoice{way, way == WayIn::course ? ui.course_trainee : ""});
  ui.first_launch = FirstLaunch::tour;
  ui.tour_step = 0;
  enter_panels(ui);  // the tour's buttons take the keyboard
}

void done(UiState& ui, Requests& out) {
  out.emplace_back(std::in_place_type<AppRequest>, FirstLaunchDone{});
  ui.first_launch = FirstLaunch::none;
  ui.keyboard_in_panels = false;
}

bool course_offered(const RunInfo& run) {
  if (!run.session) return false;
  const auto& l = run.session->lessons;
  return std::find(l.begin(), l.end(), "beginner") != l.end();
}

void draw_welcome(const RunInfo& run, UiState& ui, Requests& out, ImVec2 d) {
  const float em = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(0.5f * d.x, 0.5f * d.y), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(34.0f * em, d.x - 2.0f * em), 0.0f), ImGuiCond_Always);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(d.x - 2.0f * em, d.y - 2.0f * em));
  ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: what is behind would show through its text
  ImGui::Begin(kWelcomeWindow, nullptr,
               ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
  ImGui::TextWrapped(
      "You fly a quadrotor with a planner beside you. You share the controls: the authority bar "
      "at the top says how much is yours. Keep near the path and the controls stay yours; "
      "stray, and the planner takes over until you are back. Pick a way in:");
  ImGui::Spacing();
  const unsigned now = kWelcome;
  // Keys while no field takes the typing (the course's name).
  const bool keys = !ImGui::IsAnyItemActive();
  if (way_button("1   Watch the novice fly", "The emulated novice flies the helix; watch the "
                 "bar move as the planner helps it. Nothing to press but Space.",
                 "Fly mi_helix with the emulated novice pilot and the planner's help (key 1)") ||
      (keys && pressed(Action::welcome_watch, now)))
    choose(WayIn::watch, ui, out);
  const std::string pad = found_gamepad(run);
  const std::string fly = pad.empty() ? "2   Fly it yourself with the keyboard"
                                      : "2   Fly it yourself with the gamepad";
  const std::string fly_what =
      pad.empty() ? "No gamepad found: W / S thrust, A / D yaw, the arrows pitch and roll (the "
                    "sticks ramp while a key is held). Plug a gamepad in and it shows here."
                  : "Found: " + pad + ". Left stick: thrust and yaw; right stick: pitch and roll "
                    "(mode 2; I changes it).";
  if (way_button((fly + "###fly").c_str(), fly_what.c_str(),
                 "Fly mi_helix yourself, the planner helping when you stray (key 2)") ||
      (keys && pressed(Action::welcome_fly, now)))
    choose(WayIn::fly, ui, out);
  const bool course = course_offered(run);
  ImGui::BeginDisabled(!course);
  const bool start_course = way_button(
      "3   Start the beginner course",
      course ? "Short steps from a hover to the helix, each passed on its score; the planner's "
               "help fades as you pass them. Your progress is kept under your name:"
             : "The course keeps your progress in the history, which is off (--history off).",
      "The beginner course: lesson steps with pass criteria and a fading ceiling on the "
      "planner's help (key 3)");
  ImGui::Indent();
  ImGui::SetNextItemWidth(std::min(16.0f * em, ImGui::GetContentRegionAvail().x));
  ImGui::InputTextWithHint("##course_trainee", "your name", ui.course_trainee,
                           sizeof ui.course_trainee);
  tip("Who takes the course: the history keeps each step's attempts under this name (empty: "
      "your login name). Enter types, Space or 3 starts.");
  ImGui::Unindent();
  ImGui::EndDisabled();
  if (course && (start_course || (keys && pressed(Action::welcome_course, now))))
    choose(WayIn::course, ui, out);
  ImGui::Separator();
  if (ImGui::Button("Not now (Esc)") || (keys && pressed(Action::leave, now)))
    done(ui, out);
  tip("Close the welcome; it does not come back (F1 shows it again)");
  same_line_or_wrap(ImGui::CalcTextSize("F1: every key, and this again").x);
  ImGui::AlignTextToFramePadding();
  ImGui::TextDisabled("F1: every key, and this again");
  ImGui::TextDisabled("Keys: 1 2 3 pick; Up / Down and Space; Esc not now");
  ImGui::End();
  if (pressed(Action::help, now)) ui.show_help = !ui.show_help;
}

// The rectangle the step points at (empty: not on screen).
bool target_rect(const TourMarks& m, TourTarget t, ImVec2& min, ImVec2& max) {
  switch (t) {
    case TourTarget::authority_bar: min = m.bar_min, max = m.bar_max; break;
    case TourTarget::ball:
      min = ImVec2(m.ball_centre.x - m.ball_radius, m.ball_centre.y - m.ball_radius);
      max = ImVec2(m.ball_centre.x + m.ball_radius, m.ball_centre.y + m.ball_radius);
      break;
    case TourTarget::sticks: min = m.sticks_min, max = m.sticks_max; break;
    case TourTarget::start: min = m.start_min, max = m.start_max; break;
  }
  return max.x > min.x && max.y > min.y;
}

void draw_tour(UiState& ui, Requests& out, ImVec2 d) {
  const int steps = int(std::size(kTour));
  ui.tour_step = std::clamp(ui.tour_step, 0, steps - 1);
  const TourStep& step = kTour[std::size_t(ui.tour_step)];
  const float em = ImGui::GetFontSize(), gap = 1.2f * em;
  ImVec2 tmin, tmax;
  const bool pointed = target_rect(ui.marks, step.target, tmin, tmax);
  // The callout beside what it points at: below it where it fits, else above, else to its right
  // or left; in the display's centre when the target is not on screen.
  const float w = std::min(24.0f * em, d.x - 2.0f * em);
  const ImGuiWindow* last = ImGui::FindWindowByName(kTourWindow);
  const float h = last && last->Size.y > 0 ? last->Size.y : 10.0f * em;
  ImVec2 pos(0.5f * (d.x - w), 0.5f * (d.y - h));
  if (pointed) {
    const float cx = std::clamp(0.5f * (tmin.x + tmax.x) - 0.5f * w, em, d.x - em - w);
    const float cy = std::clamp(0.5f * (tmin.y + tmax.y) - 0.5f * h, em, d.y - em - h);
    if (tmax.y + gap + h <= d.y - em) pos = ImVec2(cx, tmax.y + gap);
    else if (tmin.y - gap - h >= em) pos = ImVec2(cx, tmin.y - gap - h);
    else if (tmax.x + gap + w <= d.x - em) pos = ImVec2(tmax.x + gap, cy);
    else if (tmin.x - gap - w >= em) pos = ImVec2(tmin.x - gap - w, cy);
  }
  ImGui::SetNextWindowPos(pos, ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(w, 0.0f), ImGuiCond_Always);
  ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: what is behind would show through its text
  ImGui::Begin(kTourWindow, nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoMove);
  ImGui::BringWindowToDisplayFront(ImGui::GetCurrentWindow());
  ImGui::PushStyleColor(ImGuiCol_Text, colour::kPilot);
  ImGui::Text("%d/%d  %s", ui.tour_step + 1, steps, step.title);
  ImGui::PopStyleColor();
  ImGui::TextWrapped("%s", step.text);
  if (!pointed) ImGui::TextDisabled("(Not on screen yet: it shows once the flight starts.)");
  ImGui::Spacing();
  const bool last_step = ui.tour_step + 1 == steps;
  ImGui::BeginDisabled(ui.tour_step == 0);
  if (ImGui::Button("Back")) ui.tour_step -= 1;
  tip("The previous callout");
  ImGui::EndDisabled();
  same_line_or_wrap(button_width(last_step ? "Start the flight (Space)" : "Next (Space)"));
  // One id for both labels: the keyboard's focus stays on it from step to step.
  // Space presses the button the keyboard is on; with none (the mouse was used), Next.
  const bool space = pressed(Action::start_pause, kAlways) && GImGui->NavId == 0;
  if (ImGui::Button(last_step ? "Start the flight (Space)###next" : "Next (Space)###next") ||
      space) {
    if (last_step) {
      out.emplace_back(std::in_place_type<LiveRequest>, StartFlight{});
      done(ui, out);
    } else {
      ui.tour_step += 1;
    }
  }
  tip(last_step ? "End the tour and start the flight" : "The next callout");
  ImGui::SetItemDefaultFocus();
  same_line_or_wrap(button_width("Skip the tour (Esc)"));
  if (ImGui::Button("Skip the tour (Esc)") ||
      (pressed(Action::leave, kAlways) && ui.first_launch == FirstLaunch::tour))
    done(ui, out);
  tip("End the tour here; it does not come back (F1 shows it again)");
  const ImVec2 cmin = ImGui::GetWindowPos();
  const ImVec2 cmax(cmin.x + ImGui::GetWindowWidth(), cmin.y + ImGui::GetWindowHeight());
  ImGui::End();
  if (!pointed) return;
  // What it points at, outlined over everything, and a leader from the callout to it.
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const float m = scaled(4.0f), t = scaled(3.0f);
  if (step.target == TourTarget::ball)
    dl->AddCircle(ImVec2(0.5f * (tmin.x + tmax.x), 0.5f * (tmin.y + tmax.y)),
                  0.5f * (tmax.x - tmin.x) + m, colour::kCaution, 48, t);
  else
    dl->AddRect(ImVec2(tmin.x - m, tmin.y - m), ImVec2(tmax.x + m, tmax.y + m), colour::kCaution,
                m, 0, t);
  const ImVec2 from(std::clamp(0.5f * (tmin.x + tmax.x), cmin.x, cmax.x),
                    cmin.y >= tmax.y ? cmin.y : cmax.y <= tmin.y ? cmax.y : 0.5f * (cmin.y + cmax.y));
  const ImVec2 to(std::clamp(from.x, tmin.x - m, tmax.x + m),
                  from.y >= tmax.y ? tmax.y + m : from.y <= tmin.y ? tmin.y - m : from.y);
  dl->AddLine(from, to, colour::kCaution, scaled(2.0f));
}

}  // namespace

std::span<const TourStep> tour_steps() { return kTour; }

std::string found_gamepad(const RunInfo& run) {
  if (!run.input) return "";
  const InputInfo& in = *run.input;
  for (const InputDevice& dev : in.devices)
    if (dev.mapped && dev.instance == in.active) return dev.name;
  for (const InputDevice& dev : in.devices)
    if (dev.mapped) return dev.name;
  return "";
}

void show_welcome(UiState& ui) {
  ui.first_launch = FirstLaunch::welcome;
  ui.tour_step = 0;
  ui.show_help = false;
  enter_panels(ui);
}

void draw_first_launch(const RunInfo& run, UiState& ui, Requests& out, ImVec2 display) {
  if (ui.first_launch == FirstLaunch::welcome) draw_welcome(run, ui, out, display);
  else if (ui.first_launch == FirstLaunch::tour) draw_tour(ui, out, display);
}

}  // namespace mixpilot::ui
