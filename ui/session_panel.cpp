// The session panel (SPEC §8): what the next flight flies, who flies it and whether it is
// recorded; and the File → Open browser for scenarios and recordings.
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

namespace {

// What the item just drawn does, on hover (every control has one).
void tip(const char* text) {
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
}

bool combo(const char* label, const std::vector<std::string>& items, int current, int& chosen) {
  bool changed = false;
  const char* preview = current >= 0 && current < int(items.size()) ? items[std::size_t(current)].c_str() : "";
  if (ImGui::BeginCombo(label, preview)) {
    for (int i = 0; i < int(items.size()); ++i) {
      if (ImGui::Selectable(items[std::size_t(i)].c_str(), i == current)) {
        chosen = i;
        changed = true;
      }
      // Opened with the keyboard, the list starts on the current choice.
      if (i == current) ImGui::SetItemDefaultFocus();
    }
    ImGui::EndCombo();
  }
  return changed;
}

// The trainee: typed (a new name), or picked from those the history knows (the arrow).
void trainee_field(const RunInfo& run, UiState& ui, float fields, Requests& out) {
  const SessionChoices& c = *run.session;
  const std::vector<std::string>* known = run.history ? &run.history->trainees : nullptr;
  const bool pick = known && !known->empty();
  const float arrow = pick ? ImGui::GetFrameHeight() : 0.0f;
  ImGui::SetNextItemWidth(fields - arrow);
  if (ui.trainee[0] == '\0' && !c.trainee.empty() && !ImGui::IsAnyItemActive())
    std::snprintf(ui.trainee, sizeof ui.trainee, "%s", c.trainee.c_str());
  ImGui::InputTextWithHint(pick ? "##trainee" : "trainee", "your name", ui.trainee,
                           sizeof ui.trainee);
  if (ImGui::IsItemDeactivatedAfterEdit()) out.push_back(SetTrainee{ui.trainee});
  if (ImGui::IsItemHovered() && !ImGui::IsItemActive())
    ImGui::SetTooltip(pick ? "Who flies: type a new name, or pick one the history knows (the "
                             "arrow). Each flight is remembered under it."
                           : "Who flies: each flight is remembered under this name (empty: your "
                             "login name).");
  if (!pick) return;
  ImGui::SameLine(0.0f, 0.0f);
  if (ImGui::BeginCombo("##trainees", nullptr,
                        ImGuiComboFlags_NoPreview | ImGuiComboFlags_PopupAlignLeft)) {
    for (const std::string& name : *known) {
      if (ImGui::Selectable(name.c_str(), name == c.trainee)) {
        std::snprintf(ui.trainee, sizeof ui.trainee, "%s", name.c_str());
        out.push_back(SetTrainee{name});
      }
      if (name == c.trainee) ImGui::SetItemDefaultFocus();  // the keyboard starts on it
    }
    ImGui::EndCombo();
  }
  if (ImGui::IsItemHovered()) ImGui::SetTooltip("Pick a trainee the history knows");
  ImGui::SameLine(0.0f, ImGui::GetStyle().ItemInnerSpacing.x);
  ImGui::TextUnformatted("trainee");
}

// The lesson picker (SPEC §10): the lesson, the trainee's step (its place among the steps, how
// it is flown and judged, the attempts) and the last flight's verdict.
void lesson_section(const SessionChoices& c, float fields, Requests& out) {
  int chosen = -1;
  ImGui::SetNextItemWidth(fields);
  if (combo("lesson", c.lessons, c.lesson, chosen)) out.push_back(PickLesson{chosen});
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
    ImGui::SetTooltip("A course of steps: each a scenario flown with a ceiling on your authority\n"
                      "and pass criteria. Passing a step moves you to the next, with a higher\n"
                      "ceiling: the planner's help fades. Your progress is kept in the history.");
  if (c.lesson <= 0) return;
  const LessonChoice& l = c.lesson_view;
  const ImVec4 pilot = ImGui::ColorConvertU32ToFloat4(colour::kPilot);
  if (!l.error.empty()) {
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s", l.error.c_str());
    return;
  }
  if (l.step < 0) {
    ImGui::TextDisabled("reading the trainee's progress...");
    return;
  }
  // The steps in a row: passed ●, current ▶, to come ○ (their titles on hover), then the
  // trainee's step, how it is flown and judged in one line (in words on hover).
  for (int i = 0; i < int(l.steps.size()); ++i) {
    if (i > 0) ImGui::SameLine(0.0f, ImGui::GetStyle().ItemInnerSpacing.x);
    const char* mark = i < l.step ? "\xE2\x97\x8F" : i == l.step ? "\xE2\x96\xB6" : "\xE2\x97\x8B";
    if (i == l.step)
      ImGui::TextColored(pilot, "%s", mark);
    else
      ImGui::TextUnformatted(mark);
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("%d. %s%s", i + 1, l.steps[std::size_t(i)].c_str(),
                        i < l.step ? " (passed)" : i == l.step ? " (yours now)" : "");
  }
  ImGui::SameLine();
  if (l.step >= int(l.steps.size())) {
    ImGui::TextColored(pilot, "every step passed");
  } else {
    ImGui::TextColored(pilot, "%s", l.heading.c_str());
    ImGui::TextDisabled("%s", l.rule.c_str());
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("%s\npass: %s", l.conditions.c_str(), l.criteria.c_str());
    if (!l.attempts.empty()) {
      if (l.closed)
        ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical),
                           "%s: the step is closed", l.attempts.c_str());
      else
        ImGui::TextDisabled("%s", l.attempts.c_str());
    }
  }
  if (!l.verdict.empty()) {
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(l.verdict_passed ? colour::kPilot
                                                                       : colour::kCaution),
                       "last: %s", l.verdict.c_str());
    for (const std::string& line : l.verdict_lines) ImGui::TextDisabled("  %s", line.c_str());
  }
}

}  // namespace

void draw_session_panel(const RunInfo& run, UiState& ui, Requests& out, float max_height) {
  const SessionChoices& c = *run.session;
  // Choices apply to the next flight: fixed while one flies.
  const bool flying = run.state == RunState::flying || run.state == RunState::paused;
  // The start (or restart) button stays in sight under the choices: when they were taller last
  // frame than the panel's height leaves above the button, they go in a region of their own
  // that scrolls.
  const ImGuiStyle& st = ImGui::GetStyle();
  const float top = ImGui::GetCursorPosY();
  const float room = std::max(ImGui::GetFrameHeight(), max_height - top - st.WindowPadding.y -
                                                           ImGui::GetFrameHeightWithSpacing());
  const bool scrolls = ui.session_choices_h > room;
  if (scrolls) ImGui::BeginChild("##choices", ImVec2(0.0f, room));
  ImGui::BeginDisabled(flying);
  // The fields take what their labels leave (the longest label, "scenario", and its gap).
  const float fields = -(ImGui::CalcTextSize("scenario").x + ImGui::GetStyle().ItemInnerSpacing.x);
  ImGui::PushTextWrapPos(0.0f);
  // A lesson chooses the scenario (and the assistance) of each step.
  const bool lesson = c.lesson > 0;
  ImGui::BeginDisabled(lesson);
  ImGui::SetNextItemWidth(fields);
  int chosen = -1;
  if (combo("scenario", c.scenarios, c.scenario, chosen)) out.push_back(PickScenario{chosen});
  tip(lesson ? "The lesson's step sets the scenario (lesson: none to choose one)"
             : "What the next flight flies: a shipped scenario, or a file opened (Ctrl+O)");
  ImGui::EndDisabled();
  if (!c.pilots.empty()) {
    ImGui::SetNextItemWidth(fields);
    if (combo("pilot", c.pilots, c.pilot, chosen)) out.push_back(PickPilot{chosen});
    tip("Who flies: an emulated pilot of the scenario, your gamepad or your keyboard");
  }
  if (run.input && !run.input->pilot.empty()) {
    if (run.input->pilot == "keyboard")
      ImGui::TextDisabled("keys: W/S thrust, A/D yaw, arrows tilt");
    else if (run.input->connected)
      ImGui::TextDisabled("gamepad: %s", run.input->device.c_str());
    else
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCaution), "no gamepad connected");
  }
  if (run.input) {
    if (ImGui::Button("Input settings... (I)")) {
      ui.show_settings = true;
      ui.draft_loaded = false;
    }
    tip("Stick mode, curves, deadzones, input loss and the haptic cue; map a gamepad");
  }
  if (ImGui::Button("Open file... (Ctrl+O)")) ui.open_dialog.open = true;
  tip("Open a scenario (.toml) to fly or a recording (.mcap) to replay");
  if (run.history) {
    same_line_or_wrap(button_width("Progress (H)"));
    if (ImGui::Button("Progress (H)")) ui.show_progress = !ui.show_progress;
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("This trainee's flights of this scenario: skill per attempt, best run, trend");
  }
  trainee_field(run, ui, fields, out);
  if (!c.lessons.empty()) lesson_section(c, fields, out);
  if (c.assist_choosable && !lesson) {
    bool assist = c.assist;
    if (ImGui::Checkbox("assistance", &assist)) out.push_back(SetAssist{assist});
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("On: the planner shares the controls with you, more when you stray.\n"
                        "Off: a probe flight - you fly alone and the score is your own\n"
                        "skill; obstacles, walls and input limits still keep the vehicle safe.");
    if (!c.assist) {
      ImGui::SameLine();
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCaution), "off: probe flight");
    }
  }
  // Fly from here (SPEC §10): the next flight goes on from a recording's moment.
  if (!c.fly_from.empty()) {
    ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kPilot), "%s", c.fly_from.c_str());
    if (ImGui::Button("Fly from the start")) out.push_back(FlyFromStart{});
    if (ImGui::IsItemHovered())
      ImGui::SetTooltip("The scenario from t = 0 instead, as a flight of its own");
  }
  // The ghost (SPEC §10): a recorded flight of this scenario flying along.
  if (!c.ghosts.empty()) {
    ImGui::SetNextItemWidth(fields);
    if (combo("ghost", c.ghosts, c.ghost, chosen)) out.push_back(PickGhost{chosen});
    // What the choice means (its note) on hover, so the panel keeps its height; what went
    // wrong in plain sight.
    const bool note = !c.ghost_note.empty() && !c.ghost_note_is_error;
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled))
      ImGui::SetTooltip("A recorded flight of this scenario flies along as a translucent\n"
                        "lavender vehicle with a dashed trail, in step by time. The HUD says\n"
                        "how far ahead or behind it you are along the reference.%s%s",
                        note ? "\n\n" : "", note ? c.ghost_note.c_str() : "");
    if (c.ghost_note_is_error)
      ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s",
                         c.ghost_note.c_str());
  }
  bool record = c.record;
  if (ImGui::Checkbox("record (Ctrl+R)", &record)) out.push_back(SetRecord{record});
  tip("Record the next flight (MCAP) to replay it, debrief it or race it as a ghost");
  if (c.record && !c.record_to.empty()) ImGui::TextDisabled("to %s", c.record_to.c_str());
  ImGui::PopTextWrapPos();
  ImGui::EndDisabled();
  // Their height (the cursor is past the last item and its spacing; scrolling included).
  ui.session_choices_h = ImGui::GetCursorPosY() - st.ItemSpacing.y - (scrolls ? 0.0f : top);
  if (scrolls) ImGui::EndChild();
  const bool lesson_closed = lesson && (c.lesson_view.closed || c.lesson_view.step < 0 ||
                                        c.lesson_view.step >= int(c.lesson_view.steps.size()));
  if (run.state == RunState::ready) {
    ImGui::BeginDisabled(lesson_closed);
    const std::string start = lesson && !lesson_closed
                                  ? "Start step " + std::to_string(c.lesson_view.step + 1) + " (Space)"
                                  : std::string("Start flight (Space)");
    if (ImGui::Button(start.c_str(), ImVec2(-1, 0))) out.push_back(StartFlight{});
    tip(lesson_closed ? "This step cannot be flown now (see above)" : "Start the flight");
    ui.marks.start_min = ImGui::GetItemRectMin();  // what the tour points at
    ui.marks.start_max = ImGui::GetItemRectMax();
    ImGui::EndDisabled();
  } else if (run.can_restart) {
    const std::string again = !flying && lesson && !c.lesson_view.next.empty()
                                  ? c.lesson_view.next
                                  : std::string(flying ? "Restart (R)" : "Fly again (R)");
    ImGui::BeginDisabled(!flying && lesson_closed);
    if (ImGui::Button(again.c_str(), ImVec2(-1, 0))) out.push_back(RestartFlight{});
    tip("Fly again from the start (a lesson: its step now)");
    ImGui::EndDisabled();
  }
}

void list_folder(OpenDialog& d) {
  d.entries.clear();
  d.error.clear();
  std::error_code ec;
  std::vector<std::string> folders, files;
  for (std::filesystem::directory_iterator it(d.folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.empty() || name[0] == '.') continue;
    std::error_code e2;
    if (it->is_directory(e2)) folders.push_back(name + "/");
    else if (name.ends_with(".toml") || name.ends_with(".mcap")) files.push_back(name);
  }
  if (ec) d.error = d.folder + ": " + ec.message();
  std::sort(folders.begin(), folders.end());
  std::sort(files.begin(), files.end());
  d.entries = std::move(folders);
  d.entries.insert(d.entries.end(), files.begin(), files.end());
}

void draw_open_dialog(UiState& ui, Requests& out) {
  OpenDialog& d = ui.open_dialog;
  if (d.open && !ImGui::IsPopupOpen("Open a scenario or a recording")) {
    if (d.folder.empty()) {
      std::error_code ec;
      d.folder = std::filesystem::current_path(ec).string();
    }
    list_folder(d);
    ImGui::OpenPopup("Open a scenario or a recording");
  }
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float margin = ImGui::GetFontSize();
  ImGui::SetNextWindowSize(ImVec2(std::min(scaled(640), display.x - 2 * margin),
                                  std::min(scaled(440), display.y - 2 * margin)));
  ImGui::SetNextWindowPos(ImVec2(0.5f * display.x, 0.5f * display.y), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  if (!ImGui::BeginPopupModal("Open a scenario or a recording", &d.open,
                              ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoMove))
    return;
  ImGui::TextDisabled("a scenario (.toml) to fly, or a recording (.mcap) to replay");
  // The folder, elided in its middle to leave room for "up" (the whole path on hover).
  const float up_w = ImGui::CalcTextSize("up").x + 2 * ImGui::GetStyle().FramePadding.x +
                     ImGui::GetStyle().ItemSpacing.x;
  const std::string folder = elide_middle(d.folder, ImGui::GetContentRegionAvail().x - up_w);
  ImGui::TextUnformatted(folder.c_str());
  if (folder != d.folder && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", d.folder.c_str());
  ImGui::SameLine();
  const bool up = ImGui::SmallButton("up");
  tip("The folder above");
  if (up) {
    d.folder = std::filesystem::path(d.folder).parent_path().string();
    list_folder(d);
  }
  const float footer = ImGui::GetFrameHeightWithSpacing() * 2.2f;
  ImGui::BeginChild("##entries", ImVec2(0, -footer), true);
  if (!d.error.empty()) ImGui::TextColored(ImGui::ColorConvertU32ToFloat4(colour::kCritical), "%s", d.error.c_str());
  std::string enter, open;  // a folder to enter, a file to open
  for (const std::string& e : d.entries) {
    const bool picked = ImGui::Selectable(e.c_str(), false, ImGuiSelectableFlags_AllowDoubleClick);
    tip(e.ends_with("/") ? "Open this folder" : "Pick this file; a double click opens it");
    if (picked) {
      const std::string full = (std::filesystem::path(d.folder) / e).string();
      if (e.ends_with("/")) {
        enter = (std::filesystem::path(d.folder) / e.substr(0, e.size() - 1)).string();
      } else {
        std::snprintf(d.path, sizeof d.path, "%s", full.c_str());
        if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) open = full;
      }
    }
  }
  ImGui::EndChild();
  if (!enter.empty()) {
    d.folder = enter;
    list_folder(d);
  }
  const float button_w = std::max(button_width("Open"), button_width("Cancel"));
  ImGui::SetNextItemWidth(-2 * (button_w + ImGui::GetStyle().ItemSpacing.x));
  const bool typed = ImGui::InputText("##path", d.path, sizeof d.path, ImGuiInputTextFlags_EnterReturnsTrue);
  tip("The file to open: picked above, or typed (Enter opens it)");
  ImGui::SameLine();
  const bool open_pressed = ImGui::Button("Open", ImVec2(button_w, 0));
  tip("Fly the scenario or replay the recording");
  if ((open_pressed || typed) && d.path[0] != '\0') open = d.path;
  ImGui::SameLine();
  const bool cancel = ImGui::Button("Cancel", ImVec2(button_w, 0));
  tip("Close without opening anything (Esc)");
  if (cancel || key_pressed(Key::escape)) d.open = false;
  if (!open.empty()) {
    out.push_back(OpenFile{std::move(open)});
    d.open = false;
  }
  if (!d.open) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
}

}  // namespace mixpilot::ui
