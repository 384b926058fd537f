// The instructor's window (SPEC §10): tiles of the stations, one large with its plots, and the
// commands to the selected one. Layout in units of the font and the style, as the app's screen.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iterator>

#include "ui/instructor.hpp"
#include "ui/instructor_hud.hpp"
#include "ui/keys.hpp"
#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

std::vector<std::string> tile_in_force(const StationTile& t) {
  return instructor_in_force(t.in_force, t.state == "paused");
}

const char* to_string(CommandOutcome o) {
  switch (o) {
    case CommandOutcome::waiting_for_station: return "waiting for the station";
    case CommandOutcome::sent: return "sent, waiting for the answer";
    case CommandOutcome::accepted: return "accepted";
    case CommandOutcome::refused: return "refused";
    case CommandOutcome::failed: return "not sent";
    case CommandOutcome::no_answer: return "no answer";
  }
  return "?";
}

namespace {

constexpr ImGuiWindowFlags kPane = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                   ImGuiWindowFlags_NoSavedSettings |
                                   ImGuiWindowFlags_NoBringToFrontOnFocus |
                                   ImGuiWindowFlags_NoBackground;
constexpr double kStripSeconds = 10.0;  // [s] of λ in a tile's strip

ImU32 state_colour(const std::string& s) {
  if (s == "flying") return colour::kMpc;
  if (s == "paused") return colour::kCaution;
  if (s == "ended") return colour::rgb(0xA0, 0xA0, 0xA0);
  return colour::kPilot;  // ready
}

ImU32 outcome_colour(CommandOutcome o) {
  switch (o) {
    case CommandOutcome::accepted: return colour::kMpc;
    case CommandOutcome::refused:
    case CommandOutcome::failed:
    case CommandOutcome::no_answer: return colour::kCritical;
    default: return colour::kCaution;
  }
}

void tooltip(const char* text) {
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text);
}

// A line of `text` in `c`, shortened in its middle to the window's width.
void fitted_text(const std::string& text, ImU32 c) {
  const float room = ImGui::GetContentRegionAvail().x;
  ImGui::PushStyleColor(ImGuiCol_Text, c);
  ImGui::TextUnformatted(elide_middle(text, room).c_str());
  ImGui::PopStyleColor();
}

// The command's outcome in words: "ACCEPTED", "REFUSED: why" (capitals, so it reads without
// its colour).
std::string outcome_words(const CommandRow& r) {
  std::string s;
  switch (r.outcome) {
    case CommandOutcome::accepted: s = "ACCEPTED"; break;
    case CommandOutcome::refused: s = "REFUSED"; break;
    case CommandOutcome::failed: s = "NOT SENT"; break;
    case CommandOutcome::no_answer: s = "NO ANSWER"; break;
    default: s = to_string(r.outcome); break;
  }
  if (!r.why.empty()) s += ": " + r.why;
  return s;
}

// The newest of this window's commands to `t` of one of `kinds`, or nullptr.
const CommandRow* newest_of(const StationTile* t, std::initializer_list<InstructorCommandKind> kinds) {
  if (!t) return nullptr;
  for (auto it = t->commands.rbegin(); it != t->commands.rend(); ++it)
    if (std::find(kinds.begin(), kinds.end(), it->kind) != kinds.end()) return &*it;
  return nullptr;
}

// What became of the newest command of `kinds`: its words, wrapped, in its outcome's colour.
void result_line(const StationTile* t, std::initializer_list<InstructorCommandKind> kinds) {
  const CommandRow* r = newest_of(t, kinds);
  if (!r) return;
  ImGui::PushStyleColor(ImGuiCol_Text, outcome_colour(r->outcome));
  ImGui::TextWrapped("%s %s", r->what.c_str(), outcome_words(*r).c_str());
  ImGui::PopStyleColor();
}

bool ctrl_key(Key k) {
  const ImGuiIO& io = ImGui::GetIO();
  return io.KeyCtrl && !io.KeyAlt && key_pressed(k);
}

// --- The tiles ----------------------------------------------------------------------------------

const Scene& scene_or_default(const StationTile& t) {
  static const Scene kDefault = [] {
    Scene s;
    s.shared_authority = true;
    s.plots = {{"authority λ", {{"lambda", SeriesRole::pilot}}},
               {"deviation [m]", {{"deviation", SeriesRole::applied}}}};
    return s;
  }();
  return t.scene ? *t.scene : kDefault;
}

const History& history_or_empty(const StationTile& t) {
  static const History kEmpty(1);
  return t.history ? *t.history : kEmpty;
}

UiState& arena_state(InstructorUi& ui, const std::string& name) {
  auto [it, made] = ui.arenas.try_emplace(name);
  if (made) it->second.camera = Camera::orbit;
  return it->second;
}

// What is in force at `t` on one line, shortened at its end to the window's width ("" none).
std::string in_force_line(const StationTile& t);

// The tile's header: its key, name and state; who flies what; whether it obeys an instructor,
// or (`in_force`, a small tile with no room for more) what the instructor keeps in force there
// when anything is.
void tile_header(const StationTile& t, int index, bool selected, bool in_force = false) {
  char key[16] = "-";  // a station shown large from the list has no key
  if (index >= 0) std::snprintf(key, sizeof key, "%d", index + 1);
  ImGui::PushFont(mono_font());
  ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(selected ? colour::kCaution : colour::kText),
                     "%s", key);
  ImGui::PopFont();
  ImGui::SameLine();
  std::string state = t.state;
  for (char& c : state) c = char(std::toupper(static_cast<unsigned char>(c)));
  if (t.heard_ago > 2.0) {
    char buf[48];
    std::snprintf(buf, sizeof buf, " (silent %.0f s)", t.heard_ago);
    state += buf;
  }
  const float state_w = ImGui::CalcTextSize(state.c_str()).x;
  const float room = ImGui::GetContentRegionAvail().x - state_w - ImGui::GetStyle().ItemSpacing.x;
  ImGui::TextUnformatted(elide_middle(t.name, std::max(1.0f, room)).c_str());
  ImGui::SameLine(ImGui::GetWindowContentRegionMax().x - state_w);
  ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(t.heard_ago > 2.0 ? colour::kCritical
                                                                      : state_colour(t.state)),
                     "%s", state.c_str());
  fitted_text(t.trainee + " · " + t.scenario, colour::kText);
  if (const std::string line = in_force ? in_force_line(t) : std::string(); !line.empty())
    fitted_text(line, colour::kCaution);
  else if (t.accepts_instructor)
    fitted_text("obeys an instructor (" + t.security + ")", colour::rgb(0xB8, 0xB8, 0xB8));
  else
    fitted_text("obeys no instructor: commands refused", colour::kCaution);
}

// The announced figures: the score so far.
void tile_numbers(const StationTile& t) {
  ImGui::PushFont(mono_font());
  // The long form where it fits, else a shorter one: a figure is never cut.
  char a[160], a_short[160], b[160], b_short[160];
  std::snprintf(a, sizeof a, "λ %.2f  mean λ %.2f  in B %.0f %%", t.lambda, t.mean_lambda,
                100.0 * t.time_in_ball);
  std::snprintf(a_short, sizeof a_short, "λ %.2f mean %.2f B %.0f%%", t.lambda, t.mean_lambda,
                100.0 * t.time_in_ball);
  std::snprintf(b, sizeof b, "deviation %.3f m  t %.1f / %.0f s", t.deviation, t.t, t.duration);
  std::snprintf(b_short, sizeof b_short, "dev %.3f m t %.0f/%.0f s", t.deviation, t.t, t.duration);
  const float room = ImGui::GetContentRegionAvail().x;
  fitted_text(ImGui::CalcTextSize(a).x <= room ? a : a_short, colour::kText);
  fitted_text(ImGui::CalcTextSize(b).x <= room ? b : b_short, colour::kText);
  ImGui::PopFont();
}

// Whether a click (not a drag: that orbits the arena) landed in [min, max) of this window.
bool clicked_in(ImVec2 min, ImVec2 max) {
  const ImGuiIO& io = ImGui::GetIO();
  if (!ImGui::IsWindowHovered(ImGuiHoveredFlags_AllowWhenBlockedByActiveItem) ||
      !ImGui::IsMouseReleased(ImGuiMouseButton_Left) || ImGui::IsAnyItemActive())
    return false;
  if (io.MouseDragMaxDistanceSqr[0] > io.MouseDragThreshold * io.MouseDragThreshold) return false;
  return ImGui::IsMouseHoveringRect(min, max);
}

// `text` shortened at its end ("…") to `width`, whole UTF-8 code points cut.
std::string elide_end(const std::string& text, float width);

std::string in_force_line(const StationTile& t) {
  std::string line;
  for (const std::string& item : tile_in_force(t)) line += (line.empty() ? "" : " ") + item;
  return elide_end(line, ImGui::GetContentRegionAvail().x);
}

std::string elide_end(const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) return text;
  std::string s = text;
  while (!s.empty()) {
    do s.pop_back();
    while (!s.empty() && (static_cast<unsigned char>(s.back()) & 0xC0) == 0x80);
    if (!s.empty()) s.pop_back();  // the lead byte of the code point cut (or one ASCII byte)
    if (ImGui::CalcTextSize((s + "\u2026").c_str()).x <= width) break;
  }
  return s + "\u2026";
}

// What is in force at the station over the top of its arena [min, max) (its own window, drawn
// over the tile's, which mouse clicks pass through to), as the trainee's HUD says it, on a
// translucent backing: the items packed into lines of the arena's width; where the arena has
// fewer lines than that takes, the last line holds the rest, shortened at its end.
void in_force_overlay(const StationTile& t, ImVec2 min, ImVec2 max) {
  const std::vector<std::string> items = tile_in_force(t);
  if (items.empty()) return;
  const ImGuiStyle& st = ImGui::GetStyle();
  const ImVec2 pad(scaled(4.0f), scaled(2.0f));  // a thin backing: the arena keeps its room
  const float width = max.x - min.x - 2.0f * st.ItemSpacing.x;
  const float inner = width - 2.0f * pad.x;
  const float line = ImGui::GetTextLineHeightWithSpacing();
  const int most = int((max.y - min.y - 2.0f * st.ItemSpacing.y - 2.0f * pad.y +
                        st.ItemSpacing.y) / line);
  if (most < 1 || inner < 4.0f * ImGui::GetFontSize()) return;
  std::vector<std::string> lines;
  for (const std::string& item : items) {
    if (!lines.empty() && ImGui::CalcTextSize((lines.back() + " " + item).c_str()).x <= inner)
      lines.back() += " " + item;
    else
      lines.push_back(item);
  }
  if (int(lines.size()) > most) {
    for (std::size_t i = std::size_t(most); i < lines.size(); ++i)
      lines[std::size_t(most) - 1] += " " + lines[i];
    lines.resize(std::size_t(most));
  }
  ImGui::SetNextWindowPos(ImVec2(min.x + st.ItemSpacing.x, min.y + st.ItemSpacing.y));
  ImGui::SetNextWindowSize(ImVec2(width, 0.0f));
  ImGui::SetNextWindowBgAlpha(0.7f);
  const std::string name = "##in force " + t.name;
  ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, pad);
  ImGui::Begin(name.c_str(), nullptr,
               ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                   ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                   ImGuiWindowFlags_NoInputs | ImGuiWindowFlags_NoNav |
                   ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::PushStyleColor(ImGuiCol_Text, colour::kCaution);
  for (const std::string& l : lines) ImGui::TextUnformatted(elide_end(l, inner).c_str());
  ImGui::PopStyleColor();
  ImGui::End();
  ImGui::PopStyleVar();
}

// One station's tile in [min, max): header, arena, λ strip, numbers; `large` adds the plots to
// the right of the arena. A click selects it (and shows it large).
void tile(const StationTile& t, int index, ImVec2 min, ImVec2 max, bool large, InstructorUi& ui) {
  const std::string name = "##tile " + t.name;
  ImGui::SetNextWindowPos(min);
  ImGui::SetNextWindowSize(ImVec2(max.x - min.x, max.y - min.y));
  ImGui::Begin(name.c_str(), nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  const bool selected = t.name == ui.selected;
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->AddRect(ImVec2(min.x + 1, min.y + 1), ImVec2(max.x - 1, max.y - 1),
              selected ? colour::kCaution : colour::rgb(0x40, 0x44, 0x4C), scaled(4.0f), 0,
              scaled(selected ? 2.5f : 1.0f));
  tile_header(t, index, selected);
  const ImGuiStyle& st = ImGui::GetStyle();
  const float line = ImGui::GetTextLineHeightWithSpacing();
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  const float bottom = ImGui::GetWindowPos().y + ImGui::GetWindowContentRegionMax().y;
  const float strip_h = 2.0f * ImGui::GetTextLineHeight();
  const float numbers_h = 2.0f * line;
  const float arena_bottom = bottom - numbers_h - strip_h - 2.0f * st.ItemSpacing.y;
  const float arena_right = large ? at.x + 0.6f * (right - at.x) : right;
  const Scene& sc = scene_or_default(t);
  const History& h = history_or_empty(t);
  UiState& cam = arena_state(ui, t.name);
  if (arena_bottom - at.y > 2.0f * line) {
    draw_arena(sc, h, cam, at, ImVec2(arena_right, arena_bottom), at, ImVec2(0, 0), ImVec2(0, 0),
               false);
    if (!t.scene_note.empty()) {
      dl->AddText(ImVec2(at.x + st.WindowPadding.x, at.y + st.WindowPadding.y / 2),
                  colour::rgb(0xB8, 0xB8, 0xB8), elide_middle(t.scene_note, arena_right - at.x - 2 * st.WindowPadding.x).c_str());
    }
    if (!t.telemetry) {
      const char* none = "no telemetry heard yet";
      const ImVec2 ts = ImGui::CalcTextSize(none);
      dl->AddText(ImVec2(0.5f * (at.x + arena_right - ts.x), 0.5f * (at.y + arena_bottom - ts.y)),
                  colour::kText, none);
    }
  }
  if (large) {
    ImGui::SetCursorScreenPos(ImVec2(arena_right + st.ItemSpacing.x, at.y));
    const std::string plots = "##plots " + t.name;
    ImGui::BeginChild(plots.c_str(), ImVec2(right - arena_right - st.ItemSpacing.x,
                                            arena_bottom - at.y), false);
    draw_plots(sc, h, cam);
    ImGui::EndChild();
  }
  const ImVec2 strip_min(at.x, arena_bottom + st.ItemSpacing.y);
  draw_lambda_strip(h, kStripSeconds, strip_min, ImVec2(right, strip_min.y + strip_h));
  ImGui::SetCursorScreenPos(ImVec2(at.x, strip_min.y + strip_h + st.ItemSpacing.y));
  tile_numbers(t);
  if (!large && clicked_in(min, max)) {
    ui.selected = t.name;
    ui.large = true;
  }
  ImGui::End();
  // (Not over the list or the help, which would come under it.)
  if (arena_bottom - at.y > 2.0f * line && !ui.show_list && !ui.show_help)
    in_force_overlay(t, at, ImVec2(arena_right, arena_bottom));
}

// A small tile (the others while one is large): header and strip, a click selects it.
void mini_tile(const StationTile& t, int index, ImVec2 min, ImVec2 max, InstructorUi& ui) {
  const std::string name = "##mini " + t.name;
  ImGui::SetNextWindowPos(min);
  ImGui::SetNextWindowSize(ImVec2(max.x - min.x, max.y - min.y));
  ImGui::Begin(name.c_str(), nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  ImGui::GetWindowDrawList()->AddRect(ImVec2(min.x + 1, min.y + 1), ImVec2(max.x - 1, max.y - 1),
                                      colour::rgb(0x40, 0x44, 0x4C), scaled(4.0f), 0,
                                      scaled(1.0f));
  tile_header(t, index, false, true);
  const ImVec2 at = ImGui::GetCursorScreenPos();
  const float right = ImGui::GetWindowPos().x + ImGui::GetWindowContentRegionMax().x;
  const float bottom = ImGui::GetWindowPos().y + ImGui::GetWindowContentRegionMax().y;
  if (bottom - at.y > ImGui::GetTextLineHeight())
    draw_lambda_strip(history_or_empty(t), kStripSeconds, at, ImVec2(right, bottom));
  if (clicked_in(min, max)) {
    ui.selected = t.name;
    ui.large = true;
  }
  ImGui::End();
}

// The list of every station, to pick the four the tiles show (more than four announced): a
// window over the display's centre (S, or the top bar's button).
void station_list(const InstructorView& v, InstructorUi& ui, ImVec2 display) {
  const float margin = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(34.0f * margin, display.x - 2 * margin),
                                  std::min(float(v.stations.size() + 3) * ImGui::GetFrameHeightWithSpacing(),
                                           display.y - 2 * margin)));
  ImGui::Begin("Stations (S)", &ui.show_list,
               ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize);
  ImGui::TextUnformatted("Tick the four the tiles show");
  const std::vector<const StationTile*> shown = shown_tiles(v, ui);
  // Columns at fixed offsets (no table: each row's checkbox keeps an id of this window's).
  const float em = ImGui::GetFontSize();
  const float cols[] = {ImGui::GetFrameHeight() + ImGui::GetStyle().ItemSpacing.x, 9 * em, 20 * em,
                        27 * em};
  for (const StationTile& t : v.stations) {
    bool on = std::find(shown.begin(), shown.end(), &t) != shown.end();
    const std::string id = "##show " + t.name;
    if (ImGui::Checkbox(id.c_str(), &on)) {
      std::vector<std::string> names;
      for (const StationTile* s : shown)
        if (s != &t) names.push_back(s->name);
      if (on) {
        if (int(names.size()) >= kMaxTiles) names.erase(names.begin());
        names.push_back(t.name);
      }
      ui.shown = names;
    }
    tooltip("Show this station as a tile (at most four; ticking a fifth drops the first)");
    const float room = ImGui::GetWindowContentRegionMax().x;
    const auto column = [&](int i, const std::string& text, ImU32 c) {
      const float x = cols[i];
      const float next = i + 1 < int(std::size(cols)) ? cols[i + 1] : room;
      if (x + em > room) return;
      ImGui::SameLine(x);
      ImGui::PushStyleColor(ImGuiCol_Text, c);
      ImGui::TextUnformatted(elide_middle(text, std::min(next, room) - x - em / 2).c_str());
      ImGui::PopStyleColor();
    };
    column(0, t.name, colour::kText);
    column(1, t.trainee, colour::kText);
    column(2, t.state, state_colour(t.state));
    char l[32];
    std::snprintf(l, sizeof l, "λ %.2f", t.lambda);
    column(3, l, colour::kText);
  }
  ImGui::End();
}

// --- The commands -------------------------------------------------------------------------------

void section(const char* title) {
  ImGui::Spacing();
  ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kPilot), "%s", title);
}

void command_pane(const InstructorView& v, InstructorUi& ui, ImVec2 min, ImVec2 max,
                  std::vector<InstructorRequest>& out) {
  ImGui::SetNextWindowPos(min);
  ImGui::SetNextWindowSize(ImVec2(max.x - min.x, max.y - min.y));
  ImGui::Begin("##commands", nullptr, kPane & ~ImGuiWindowFlags_NoScrollbar);
  const StationTile* target = nullptr;
  for (const StationTile& t : v.stations)
    if (t.name == ui.selected) target = &t;
  ImGui::PushTextWrapPos(0.0f);
  if (!target) {
    ImGui::TextUnformatted("Commands: no station selected (click a tile, or 1-4).");
    ImGui::PopTextWrapPos();
    ImGui::End();
    return;
  }
  // The station: picked here too (keyboard: Tab to it, arrows).
  ImGui::AlignTextToFramePadding();
  ImGui::TextUnformatted("Commands to");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(ImGui::GetContentRegionAvail().x);
  if (ImGui::BeginCombo("##target", target->name.c_str())) {
    for (const StationTile& t : v.stations) {
      if (ImGui::Selectable(t.name.c_str(), &t == target)) ui.selected = t.name;
      if (&t == target) ImGui::SetItemDefaultFocus();  // the keyboard starts on it
    }
    ImGui::EndCombo();
  }
  tooltip("The station these commands go to (also: click its tile, or keys 1-4)");
  if (!target->accepts_instructor)
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCaution),
                       "%s obeys no instructor: it will refuse these commands.",
                       target->name.c_str());
  if (!v.can_command)
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical),
                       "Watching only: this window cannot send commands (see the top bar).");

  float label_w = 0.0f;
  for (const char* l : {"floor", "ceiling", "force N", "for s", "delay", "lost", "text"})
    label_w = std::max(label_w, ImGui::CalcTextSize(l).x);
  const float field_w = std::max(4.0f * ImGui::GetFontSize(),
                                 ImGui::GetContentRegionAvail().x - label_w -
                                     ImGui::GetStyle().ItemInnerSpacing.x);
  CommandDraft& d = ui.draft;
  const auto send = [&](InstructorCommand c) { out.push_back({target->name, c}); };
  const auto button = [&](const char* label, const char* tip) {
    const bool pressed = ImGui::Button(label);
    tooltip(tip);
    return pressed;
  };

  section("Authority: bounds on λ");
  ImGui::SetNextItemWidth(field_w);
  if (ImGui::SliderFloat("floor", &d.floor, 0.0f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp))
    d.ceiling = std::max(d.ceiling, d.floor);
  tooltip("λ never below it: the pilot keeps at least this share (0: no floor). "
          "Ctrl+click or Tab to type a value; arrows step it.");
  ImGui::SetNextItemWidth(field_w);
  if (ImGui::SliderFloat("ceiling", &d.ceiling, 0.0f, 1.0f, "%.2f", ImGuiSliderFlags_AlwaysClamp))
    d.floor = std::min(d.floor, d.ceiling);
  tooltip("λ never above it: the planner keeps at least 1 − ceiling (1: no ceiling). "
          "Ctrl+click or Tab to type a value; arrows step it.");
  if (button("Apply bounds (Ctrl+B)",
             "Send the floor and the ceiling: from the station's next step on, "
             "λ_applied = min(max(λ, floor), ceiling)") ||
      ctrl_key(Key::b)) {
    InstructorCommand c;
    c.kind = InstructorCommandKind::bounds;
    c.bounds = {d.floor, d.ceiling};
    send(c);
  }
  result_line(target, {InstructorCommandKind::bounds});

  section("Gust");
  ImGui::SetNextItemWidth(field_w);
  ImGui::InputFloat3("force N", d.force, "%.1f");
  tooltip("The gust's force in newtons, world frame (x, y, z); at most 20 N");
  ImGui::SetNextItemWidth(field_w);
  ImGui::SliderFloat("for s", &d.gust_s, 0.1f, 10.0f, "%.1f s", ImGuiSliderFlags_AlwaysClamp);
  tooltip("How long the gust acts, in seconds (at most 10)");
  const double force = std::sqrt(double(d.force[0]) * d.force[0] + double(d.force[1]) * d.force[1] +
                                 double(d.force[2]) * d.force[2]);
  if (force > 20.0)
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCaution),
                       "%.1f N: over 20 N, the station will refuse it", force);
  if (button("Gust (Ctrl+G)", "Push the vehicle with this force for this long") ||
      ctrl_key(Key::g)) {
    InstructorCommand c;
    c.kind = InstructorCommandKind::gust;
    c.force = Eigen::Vector3d(d.force[0], d.force[1], d.force[2]);
    c.duration = d.gust_s;
    send(c);
  }
  result_line(target, {InstructorCommandKind::gust});

  section("Extra delay");
  ImGui::SetNextItemWidth(field_w);
  ImGui::SliderFloat("delay", &d.delay_s, 0.0f, 0.5f, "%.2f s", ImGuiSliderFlags_AlwaysClamp);
  tooltip("Round-trip delay added between controller and vehicle, 0 to 0.5 s (0 removes it)");
  if (button("Apply delay (Ctrl+D)", "Send the extra delay") || ctrl_key(Key::d)) {
    InstructorCommand c;
    c.kind = InstructorCommandKind::extra_delay;
    c.delay = d.delay_s;
    send(c);
  }
  result_line(target, {InstructorCommandKind::extra_delay});

  section("Input loss");
  ImGui::SetNextItemWidth(field_w);
  ImGui::SliderFloat("lost", &d.loss_s, 0.1f, 10.0f, "%.1f s", ImGuiSliderFlags_AlwaysClamp);
  tooltip("How long the pilot's input is lost (at most 10 s): the planner flies meanwhile");
  if (button("Cut input (Ctrl+L)", "Simulate losing the pilot's input for this long") ||
      ctrl_key(Key::l)) {
    InstructorCommand c;
    c.kind = InstructorCommandKind::input_loss;
    c.duration = d.loss_s;
    send(c);
  }
  result_line(target, {InstructorCommandKind::input_loss});

  section("Marker");
  ImGui::SetNextItemWidth(field_w);
  const bool entered = ImGui::InputTextWithHint("text", "what to look at in the debrief",
                                                d.marker, sizeof d.marker,
                                                ImGuiInputTextFlags_EnterReturnsTrue);
  tooltip("A note in the station's debrief at this moment (1 to 95 bytes); Enter sends it");
  if (button("Mark (Ctrl+M)", "Drop a marker with this text into the flight's debrief") ||
      ctrl_key(Key::m) || entered) {
    InstructorCommand c;
    c.kind = InstructorCommandKind::marker;
    c.text.assign(d.marker);
    send(c);
  }
  result_line(target, {InstructorCommandKind::marker});

  section("The flight");
  const std::pair<InstructorCommandKind, std::pair<const char*, const char*>> flight[] = {
      {InstructorCommandKind::pause, {"Pause (Ctrl+P)", "Freeze the station's flight"}},
      {InstructorCommandKind::resume, {"Resume (Ctrl+R)", "Let a paused flight fly on"}},
      {InstructorCommandKind::end, {"End (Ctrl+E)", "End the station's flight now (it is scored)"}}};
  const Key flight_keys[] = {Key::p, Key::r, Key::e};
  for (int i = 0; i < 3; ++i) {
    if (i > 0) same_line_or_wrap(button_width(flight[i].second.first));
    if (button(flight[i].second.first, flight[i].second.second) || ctrl_key(flight_keys[i])) {
      InstructorCommand c;
      c.kind = flight[i].first;
      send(c);
    }
  }
  result_line(target, {InstructorCommandKind::pause, InstructorCommandKind::resume,
                       InstructorCommandKind::end});

  section("This window's commands to it");
  if (target->commands.empty()) ImGui::TextDisabled("none yet");
  int shown = 0;
  for (auto it = target->commands.rbegin(); it != target->commands.rend() && shown < 5; ++it, ++shown) {
    ImGui::PushStyleColor(ImGuiCol_Text, outcome_colour(it->outcome));
    ImGui::TextWrapped("%.0f s ago: %s %s", it->age, it->what.c_str(), outcome_words(*it).c_str());
    ImGui::PopStyleColor();
  }
  section("Its announced results (every instructor)");
  ImGui::Text("%llu accepted, %llu refused", (unsigned long long)target->accepted,
              (unsigned long long)target->refused);
  if (!target->last_refusal.empty()) ImGui::TextWrapped("newest refused: %s", target->last_refusal.c_str());
  for (auto it = target->announced.rbegin(); it != target->announced.rend(); ++it)
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(it->accepted ? colour::kMpc : colour::kCritical),
                       "%s #%llu: %s", it->issuer.c_str(), (unsigned long long)it->sequence,
                       it->result.c_str());
  ImGui::PopTextWrapPos();
  ImGui::End();
}

void help_sheet(InstructorUi& ui, ImVec2 display) {
  const float margin = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always,
                          ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(std::max(1.0f, display.x - 2 * margin),
                                                           std::max(1.0f, display.y - 2 * margin)));
  ImGui::Begin("Keyboard and mouse (F1)", &ui.show_help,
               ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoMove);
  static const char* const kKeys[][2] = {
      {"1  2  3  4", "select that tile's station and show it large"},
      {"Esc", "back to the tiles side by side (the selection stays)"},
      {"click a tile", "the same as its number; drag its arena to orbit, wheel zooms"},
      {"Tab, arrows", "move between the controls; Space or Enter presses a button"},
      {"Ctrl+B", "apply the authority bounds (floor and ceiling)"},
      {"Ctrl+G", "a gust"},
      {"Ctrl+D", "apply the extra delay"},
      {"Ctrl+L", "cut the pilot's input"},
      {"Ctrl+M", "drop the marker"},
      {"Ctrl+P  Ctrl+R  Ctrl+E", "pause / resume / end the station's flight"},
      {"P", "pause / resume the large station's plots"},
      {"S", "more than four stations: the list that picks the four the tiles show"},
      {"F1", "this sheet"},
  };
  if (ImGui::BeginTable("##keys", 2, ImGuiTableFlags_RowBg | ImGuiTableFlags_SizingFixedFit)) {
    for (const auto& k : kKeys) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::PushFont(mono_font());
      ImGui::TextUnformatted(k[0]);
      ImGui::PopFont();
      ImGui::TableNextColumn();
      ImGui::TextUnformatted(k[1]);
    }
    ImGui::EndTable();
  }
  ImGui::End();
}

void keys(const InstructorView& v, InstructorUi& ui) {
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantTextInput || io.KeyCtrl || io.KeyAlt) return;
  const std::vector<const StationTile*> shown = shown_tiles(v, ui);
  for (int i = 0; i < int(shown.size()); ++i)
    if (key_pressed(Key(int(Key::digit1) + i))) {
      ui.selected = shown[std::size_t(i)]->name;
      ui.large = true;
    }
  if (key_pressed(Key::escape)) {
    if (ui.show_help) ui.show_help = false;
    else if (ui.show_list) ui.show_list = false;
    else ui.large = false;
  }
  if (key_pressed(Key::s) && v.stations.size() > std::size_t(kMaxTiles)) ui.show_list = !ui.show_list;
  if (key_pressed(Key::f1)) ui.show_help = !ui.show_help;
  if (key_pressed(Key::p) && ui.large && !ui.selected.empty()) {
    for (const StationTile* t : shown)
      if (t->name == ui.selected && t->history)
        set_plots_paused(arena_state(ui, t->name), *t->history,
                         !arena_state(ui, t->name).plots_paused);
  }
}

}  // namespace

std::vector<const StationTile*> shown_tiles(const InstructorView& v, const InstructorUi& ui) {
  std::vector<const StationTile*> out;
  for (const std::string& name : ui.shown)
    for (const StationTile& t : v.stations)
      if (t.name == name && int(out.size()) < kMaxTiles) out.push_back(&t);
  for (const StationTile& t : v.stations)
    if (int(out.size()) < kMaxTiles && std::find(out.begin(), out.end(), &t) == out.end())
      out.push_back(&t);
  // In name order (the stations' order), so a tile keeps its place and its key.
  std::sort(out.begin(), out.end(), [](const StationTile* a, const StationTile* b) {
    return a->name < b->name;
  });
  return out;
}

void draw_lambda_strip(const History& h, double seconds, ImVec2 min, ImVec2 max) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  dl->PushClipRect(min, max, true);
  dl->AddRectFilled(min, max, colour::kBackground);
  const float w = max.x - min.x, ht = max.y - min.y;
  if (h.empty() || w <= 0 || ht <= 0) {
    dl->AddText(ImVec2(min.x + scaled(4), min.y + 0.5f * (ht - ImGui::GetTextLineHeight())),
                colour::rgb(0xA0, 0xA0, 0xA0), "no λ heard yet");
    dl->PopClipRect();
    return;
  }
  const double t1 = h.newest().t, t0 = t1 - seconds;
  const auto x_of = [&](double t) { return float(min.x + (t - t0) / seconds * w); };
  const auto y_of = [&](double l) { return float(max.y - std::clamp(l, 0.0, 1.0) * ht); };
  const std::size_t first = h.first_at_or_after(t0);
  const float x_first = x_of(h[first].t);
  // The planner's share: the strip's orange, hatched (greyscale tells it from the pilot's).
  dl->AddRectFilled(ImVec2(x_first, min.y), max, colour::kPlannerFill);
  const float step = scaled(6.0f);
  dl->PushClipRect(ImVec2(x_first, min.y), max, true);
  for (float x = x_first - ht; x < max.x; x += step)
    dl->AddLine(ImVec2(x, max.y), ImVec2(x + ht, min.y), colour::rgb(0x40, 0x2C, 0x00, 150),
                scaled(1.5f));
  dl->PopClipRect();
  // The pilot's share λ from the bottom, column by column.
  for (std::size_t i = first; i < h.size(); ++i) {
    const float xa = x_of(h[i].t);
    const float xb = i + 1 < h.size() ? x_of(h[i + 1].t) : max.x;
    dl->AddRectFilled(ImVec2(xa, y_of(h[i].lambda)), ImVec2(std::max(xb, xa + 1.0f), max.y),
                      colour::kPilot);
  }
  for (std::size_t i = first + 1; i < h.size(); ++i)
    dl->AddLine(ImVec2(x_of(h[i - 1].t), y_of(h[i - 1].lambda)), ImVec2(x_of(h[i].t), y_of(h[i].lambda)),
                colour::kText, scaled(1.5f));
  // The instructor's bounds while they held: λ stays under the ceiling, over the floor.
  for (std::size_t i = first; i < h.size(); ++i) {
    const AuthorityBounds& b = h[i].instructor.bounds;
    const float xa = x_of(h[i].t);
    const float xb = std::max(i + 1 < h.size() ? x_of(h[i + 1].t) : max.x, xa + 1.0f);
    if (b.ceiling < 1.0)
      dl->AddLine(ImVec2(xa, y_of(b.ceiling)), ImVec2(xb, y_of(b.ceiling)), colour::kCaution,
                  scaled(2.0f));
    if (b.floor > 0.0)
      dl->AddLine(ImVec2(xa, y_of(b.floor)), ImVec2(xb, y_of(b.floor)), colour::kCaution,
                  scaled(2.0f));
  }
  // 0.5, and the names of the shares on a dark backing.
  const float mid = y_of(0.5);
  for (float x = min.x; x < max.x; x += scaled(8.0f))
    dl->AddLine(ImVec2(x, mid), ImVec2(x + scaled(4.0f), mid), colour::rgb(0xEE, 0xEE, 0xEE, 160),
                scaled(1.0f));
  const auto label = [&](const char* text, ImVec2 at, ImU32 c) {
    const ImVec2 s = ImGui::CalcTextSize(text);
    dl->AddRectFilled(ImVec2(at.x - scaled(2), at.y), ImVec2(at.x + s.x + scaled(2), at.y + s.y),
                      colour::rgb(0x10, 0x12, 0x15, 200), scaled(2.0f));
    dl->AddText(at, c, text);
  };
  if (ht >= 2.0f * ImGui::GetTextLineHeight() - 1.0f) {
    label("planner", ImVec2(min.x + scaled(3), min.y), colour::kPlanner);
    label("pilot λ", ImVec2(min.x + scaled(3), max.y - ImGui::GetTextLineHeight()), colour::kPilot);
  }
  dl->PopClipRect();
  dl->AddRect(min, max, colour::rgb(0x60, 0x66, 0x70), 0.0f, 0, scaled(1.0f));
}

void draw_instructor(const InstructorView& v, InstructorUi& ui,
                     std::vector<InstructorRequest>& out) {
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  const ImGuiStyle& st = ImGui::GetStyle();
  const std::vector<const StationTile*> shown = shown_tiles(v, ui);
  if (ui.selected.empty() && !shown.empty()) ui.selected = shown.front()->name;
  bool selected_exists = false;
  for (const StationTile& t : v.stations) selected_exists |= t.name == ui.selected;
  if (!selected_exists && !shown.empty()) ui.selected = shown.front()->name;

  // The top bar: domain, identity, the stations heard, the status.
  const float top = ImGui::GetFrameHeight() + 2.0f * st.WindowPadding.y;
  ImGui::SetNextWindowPos(ImVec2(0, 0));
  ImGui::SetNextWindowSize(ImVec2(d.x, top));
  ImGui::Begin("##top", nullptr, kPane | ImGuiWindowFlags_NoScrollbar);
  {
    char head[256];
    std::snprintf(head, sizeof head, "Instructor · domain %u · %zu station%s · as %s · %s",
                  unsigned(v.domain), v.stations.size(), v.stations.size() == 1 ? "" : "s",
                  v.issuer.c_str(), v.security.c_str());
    std::string line = head;
    if (!v.status.empty()) line += " · " + v.status;
    const char* help = "F1 keys";
    const char* list = "Stations (S)";
    const bool many = v.stations.size() > std::size_t(kMaxTiles);
    const float help_w = ImGui::CalcTextSize(help).x;
    const float list_w = many ? button_width(list) + st.ItemSpacing.x : 0.0f;
    ImGui::AlignTextToFramePadding();
    fitted_text(elide_middle(line, ImGui::GetContentRegionAvail().x - help_w - list_w -
                                       2 * st.ItemSpacing.x),
                v.status_is_error ? colour::kCritical : colour::kText);
    if (many) {
      ImGui::SameLine(ImGui::GetWindowContentRegionMax().x - help_w - list_w);
      if (ImGui::Button(list)) ui.show_list = !ui.show_list;
      tooltip("More than four stations: pick the four the tiles show");
    }
    ImGui::SameLine(ImGui::GetWindowContentRegionMax().x - help_w);
    ImGui::TextDisabled("%s", help);
  }
  ImGui::End();

  const float commands_w = std::clamp(22.0f * ImGui::GetFontSize(), 0.25f * d.x, 0.4f * d.x);
  const float main_r = d.x - commands_w;
  command_pane(v, ui, ImVec2(main_r, top), ImVec2(d.x, d.y), out);

  const float main_b = d.y;
  if (shown.empty()) {
    ImGui::SetNextWindowPos(ImVec2(0, top));
    ImGui::SetNextWindowSize(ImVec2(main_r, main_b - top));
    ImGui::Begin("##empty", nullptr, kPane);
    ImGui::PushTextWrapPos(0.0f);
    ImGui::TextWrapped("Listening on DDS domain %u for stations: every `mixpilot fly --publish` "
                       "on this domain appears here.", unsigned(v.domain));
    ImGui::PopTextWrapPos();
    ImGui::End();
  } else if (ui.large) {
    // The selected station large; the others in a row of small tiles under it.
    const StationTile* big = nullptr;
    int big_index = 0;
    for (int i = 0; i < int(shown.size()); ++i)
      if (shown[std::size_t(i)]->name == ui.selected) {
        big = shown[std::size_t(i)];
        big_index = i;
      }
    if (!big) {  // selected through the list or the combo, not among the tiles
      for (const StationTile& t : v.stations)
        if (t.name == ui.selected) big = &t;
      big_index = -1;
    }
    const int others = int(shown.size()) - (big_index >= 0 ? 1 : 0);
    const float mini_h = others > 0 ? 3.0f * ImGui::GetTextLineHeightWithSpacing() +
                                          2.0f * ImGui::GetTextLineHeight() +
                                          2.0f * st.WindowPadding.y
                                    : 0.0f;
    tile(*big, big_index, ImVec2(0, top), ImVec2(main_r, main_b - mini_h), true, ui);
    const float mini_w = others > 0 ? main_r / float(others) : 0.0f;
    int k = 0;
    for (int i = 0; i < int(shown.size()); ++i) {
      if (i == big_index) continue;
      mini_tile(*shown[std::size_t(i)], i, ImVec2(mini_w * float(k), main_b - mini_h),
                ImVec2(mini_w * float(k + 1), main_b), ui);
      ++k;
    }
  } else {
    // Side by side: one row for one or two stations, two rows of two for three or four.
    const int n = int(shown.size());
    const int cols = n <= 2 ? n : 2, rows = n <= 2 ? 1 : 2;
    const float w = main_r / float(cols), ht = (main_b - top) / float(rows);
    for (int i = 0; i < n; ++i) {
      const float x = w * float(i % cols), y = top + ht * float(i / cols);
      tile(*shown[std::size_t(i)], i, ImVec2(x, y), ImVec2(x + w, y + ht), false, ui);
    }
  }
  if (ui.show_list && v.stations.size() > std::size_t(kMaxTiles)) station_list(v, ui, d);
  if (ui.show_help) help_sheet(ui, d);
  keys(v, ui);
}

}  // namespace mixpilot::ui
