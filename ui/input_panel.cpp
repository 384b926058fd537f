// The input settings panel and the input-loss banner (SPEC §6).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <string>

#include "input/keyboard.hpp"
#include "ui/panels.hpp"
#include "ui/theme.hpp"

namespace mixpilot::ui {

namespace {

// What the item just drawn does, on hover (every control has one).
void tip(const char* text) {
  if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) ImGui::SetTooltip("%s", text);
}

// One axis's response: raw stick (x) → shaped output (y), both in [-1, 1], with the live stick
// as a dot on the curve.
void axis_curve(const char* id, const input::AxisSettings& a, double live, ImVec2 size) {
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImVec2 min = ImGui::GetCursorScreenPos();
  const ImVec2 max(min.x + size.x, min.y + size.y);
  ImGui::InvisibleButton(id, size);
  tip("The axis's response: the stick (across) to the command (up), with the stick now as a dot");
  dl->AddRectFilled(min, max, colour::kBackground);
  const auto px = [&](double x, double y) {
    return ImVec2(float(min.x + (x + 1) * 0.5 * size.x), float(max.y - (y + 1) * 0.5 * size.y));
  };
  dl->AddLine(px(-1, 0), px(1, 0), colour::kGrid, scaled(1.0f));
  dl->AddLine(px(0, -1), px(0, 1), colour::kGrid, scaled(1.0f));
  constexpr int kPoints = 48;
  for (int i = 0; i <= kPoints; ++i) dl->PathLineTo(px(-1 + 2.0 * i / kPoints, input::shape(-1 + 2.0 * i / kPoints, a)));
  dl->PathStroke(colour::kPilot, 0, scaled(2.0f));
  const double x = std::clamp(live, -1.0, 1.0);
  dl->AddCircleFilled(px(x, input::shape(x, a)), scaled(4.0f), colour::kCaution);
}

// A slider or combo `field` wide with its label after it.
float labelled_width(const char* label, float field) {
  return field + ImGui::GetStyle().ItemInnerSpacing.x + ImGui::CalcTextSize(label, nullptr, true).x;
}

bool slider(const char* label, double& v, double lo, double hi, const char* format,
            const char* what) {
  float f = float(v);
  const bool changed =
      ImGui::SliderFloat(label, &f, float(lo), float(hi), format, ImGuiSliderFlags_AlwaysClamp);
  tip(what);
  if (!changed) return false;
  v = double(f);
  return true;
}

}  // namespace

unsigned held_flight_keys() {
  const ImGuiIO& io = ImGui::GetIO();
  if (io.WantCaptureKeyboard || io.KeyCtrl) return 0;
  unsigned keys = 0;
  for (int k = 0; k < int(input::Key::count); ++k)
    if (key_down(kFlightKeys[k])) keys |= 1u << k;
  return keys;
}

void draw_input_settings(const RunInfo& run, UiState& ui, Requests& out) {
  if (!ui.show_settings || !run.input || !run.input->settings) return;
  const InputInfo& in = *run.input;
  if (!ui.draft_loaded) {
    ui.draft = *in.settings;
    ui.draft_loaded = true;
  }
  input::InputSettings& s = ui.draft;
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  const float em = ImGui::GetFontSize(), margin = em;
  ImGui::SetNextWindowPos(ImVec2(d.x * 0.5f, d.y * 0.5f), ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
  // Its width is fixed, its height always fits what it holds (devices come and go), within the
  // display (it scrolls there).
  ImGui::SetNextWindowSize(ImVec2(std::min(scaled(760), d.x - 2 * margin), 0), ImGuiCond_Always);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(d.x - 2 * margin, d.y - 2 * margin));
  ImGui::SetNextWindowBgAlpha(0.98f);
  bool open = true;
  if (!ImGui::Begin("Input settings (I)", &open, ImGuiWindowFlags_NoSavedSettings |
                                                     ImGuiWindowFlags_NoCollapse)) {
    ImGui::End();
    ui.show_settings = open;
    return;
  }
  if (!in.note.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, colour::kCaution);
    ImGui::PushTextWrapPos(0);
    ImGui::TextUnformatted(in.note.c_str());
    ImGui::PopTextWrapPos();
    ImGui::PopStyleColor();
  }
  // The device: the gamepad in use, the others SDL sees, a mapping for those it does not know.
  if (in.pilot == "keyboard")
    ImGui::TextUnformatted("Keyboard: W/S thrust, A/D yaw, arrows pitch and roll (keys ramp).");
  else
    ImGui::Text("Gamepad: %s", in.connected ? in.device.c_str() : "none connected");
  if (in.devices.empty()) {
    ImGui::TextDisabled("SDL sees no joystick. Plug one in: it shows here at once.");
  }
  for (const InputDevice& dev : in.devices) {
    // Labels carry the device's name as their id ("Map it...##name"), so tests can find them.
    if (dev.mapped) {
      ImGui::BeginDisabled(dev.instance == in.active);
      const std::string use = (dev.instance == in.active ? "selected##" : "Select##") + dev.name;
      if (ImGui::Button(use.c_str())) out.push_back(UseGamepad{dev.instance});
      tip("Fly the gamepad flights with this one");
      ImGui::EndDisabled();
    } else {
      if (ImGui::Button(("Map it...##" + dev.name).c_str())) out.push_back(MapGamepad{dev.instance});
      tip("Teach SDL this joystick: move each stick as asked, then save the mapping");
    }
    ImGui::SameLine();
    ImGui::TextWrapped("%s%s", dev.name.c_str(), dev.mapped ? "" : "  (SDL has no mapping for it)");
  }
  if (!in.message.empty()) ImGui::TextWrapped("%s", in.message.c_str());
  ImGui::Separator();

  const char* modes[] = {"Mode 1 (left: pitch + yaw, right: thrust + roll)",
                         "Mode 2 (left: thrust + yaw, right: pitch + roll)",
                         "Mode 3 (left: pitch + roll, right: thrust + yaw)",
                         "Mode 4 (left: thrust + roll, right: pitch + yaw)"};
  int mode = s.mode - 1;
  ImGui::SetNextItemWidth(std::min(28.0f * em, ImGui::GetContentRegionAvail().x -
                                                   labelled_width("stick mode", 0.0f)));
  if (ImGui::Combo("stick mode", &mode, modes, 4)) s.mode = mode + 1;
  tip("Which stick moves what (mode 2 is the common one)");
  const float wide = 13.0f * em, narrow = 10.5f * em;
  ImGui::SetNextItemWidth(wide);
  slider("max tilt [deg]", s.max_tilt_deg, 5, 60, "%.0f",
         "The roll and pitch a full stick asks for");
  same_line_or_wrap(labelled_width("thrust range (x hover)", wide));
  ImGui::SetNextItemWidth(wide);
  slider("thrust range (x hover)", s.thrust_range, 0.05, 1, "%.2f",
         "How far a full thrust stick moves the rotors from hover (a share of hover)");

  // Each axis: its shaping and its curve with the live stick.
  const input::Controls raw = input::assign(in.live, s.mode);
  const std::pair<const char*, input::AxisSettings*> axes[] = {
      {"roll", &s.roll}, {"pitch", &s.pitch}, {"thrust", &s.thrust}, {"yaw", &s.yaw}};
  const double live[] = {raw.roll, raw.pitch, raw.thrust, raw.yaw};
  if (ImGui::BeginTable("axes", 4, ImGuiTableFlags_SizingStretchSame)) {
    for (int i = 0; i < 4; ++i) {
      ImGui::TableNextColumn();
      input::AxisSettings& a = *axes[i].second;
      ImGui::PushID(i);
      ImGui::Text("%s  %+.2f", axes[i].first, input::shape(live[i], a));
      const float w = ImGui::GetContentRegionAvail().x;
      axis_curve("curve", a, live[i], ImVec2(w, w * 0.75f));
      const float field = -labelled_width("deadzone", 0.0f);  // the longest label's room
      ImGui::SetNextItemWidth(field);
      slider("deadzone", a.deadzone, 0, 0.5, "%.2f", "Stick travel around the centre that does nothing");
      ImGui::SetNextItemWidth(field);
      slider("expo", a.expo, 0, 1, "%.2f", "Softer near the centre, full at the end (0: linear)");
      ImGui::SetNextItemWidth(field);
      slider("rate", a.rate, 0.1, 2, "%.2f", "A factor on the whole axis");
      ImGui::Checkbox("invert", &a.invert);
      tip("The axis the other way round");
      ImGui::PopID();
    }
    ImGui::EndTable();
  }
  ImGui::Separator();
  ImGui::SetNextItemWidth(narrow);
  slider("input timeout [s]", s.input_timeout_s, 0.02, 1, "%.2f",
         "A device silent this long is lost: the planner flies until it is back");
  same_line_or_wrap(labelled_width("return time [s]", narrow));
  ImGui::SetNextItemWidth(narrow);
  slider("return time [s]", s.return_time_s, 0, 5, "%.1f",
         "How long the controls take to come back to you after a loss");
  ImGui::Checkbox("haptic cue", &s.haptic.enabled);
  tip("The gamepad rumbles as the planner takes over");
  ImGui::BeginDisabled(!s.haptic.enabled);
  same_line_or_wrap(labelled_width("below lambda", narrow));
  ImGui::SetNextItemWidth(narrow);
  slider("below lambda", s.haptic.threshold, 0.05, 1, "%.2f",
         "The rumble starts when your authority λ falls below this");
  same_line_or_wrap(labelled_width("strength", narrow));
  ImGui::SetNextItemWidth(narrow);
  slider("strength", s.haptic.strength, 0, 1, "%.2f", "The strongest rumble");
  ImGui::EndDisabled();
  ImGui::Separator();
  ImGui::TextDisabled("Changes apply from the next flight.");
  if (ImGui::Button("Apply")) out.push_back(ApplySettings{s, false});
  tip("Use these settings from the next flight on (not saved)");
  ImGui::SameLine();
  if (ImGui::Button("Save")) out.push_back(ApplySettings{s, true});
  tip("Use these settings and keep them for the next start");
  ImGui::SameLine();
  if (ImGui::Button("Defaults")) s = input::InputSettings{};
  tip("Put back the default settings here (Apply or Save to use them)");
  // Where Save writes: after the buttons, wrapping where the path is long.
  const std::string to = "Save writes to " + in.settings_path;
  same_line_or_wrap(std::min(ImGui::CalcTextSize(to.c_str()).x, 12.0f * em));
  ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
  ImGui::TextWrapped("%s", to.c_str());
  ImGui::PopStyleColor();
  ImGui::End();
  if (!open) {
    ui.show_settings = false;
    ui.draft_loaded = false;
  }
}

void draw_mapping_wizard(const RunInfo& run, Requests& out) {
  if (!run.input || !run.input->wizard) return;
  const WizardView& w = *run.input->wizard;
  const ImVec2 d = ImGui::GetIO().DisplaySize;
  const float margin = ImGui::GetFontSize();
  ImGui::SetNextWindowPos(ImVec2(d.x * 0.5f, d.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
  ImGui::SetNextWindowSize(ImVec2(std::min(scaled(640), d.x - 2 * margin), 0), ImGuiCond_Always);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0, 0), ImVec2(d.x - 2 * margin, d.y - 2 * margin));
  ImGui::SetNextWindowBgAlpha(0.98f);
  ImGui::SetNextWindowFocus();
  ImGui::Begin("Map a gamepad", nullptr,
               ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("%s", w.device.c_str());
  ImGui::ProgressBar(float(w.step) / float(std::max<std::size_t>(1, w.steps)), ImVec2(-1, 0),
                     w.done ? "done" : "");
  ImGui::Spacing();
  if (w.done) {
    ImGui::TextWrapped("Every control is bound. Save writes this SDL mapping into your mappings "
                       "and uses the pad at once:");
  } else {
    ImGui::SetWindowFontScale(1.3f);
    ImGui::PushStyleColor(ImGuiCol_Text, colour::kPilot);
    ImGui::TextWrapped("%zu/%zu  %s", w.step + 1, w.steps, w.prompt.c_str());
    ImGui::PopStyleColor();
    ImGui::SetWindowFontScale(1.0f);
  }
  ImGui::TextDisabled("%s", w.hint.empty() ? " " : w.hint.c_str());
  // What the device reports, raw: axes as bars, pressed buttons, hats.
  if (const input::RawJoystick* r = w.raw; r && r->instance >= 0) {
    const float bar_w = 9.5f * ImGui::GetFontSize();
    for (int a = 0; a < r->num_axes; ++a) {
      char label[24];
      std::snprintf(label, sizeof label, "a%d %+.2f", a, double(r->axes[std::size_t(a)]));
      if (a > 0) same_line_or_wrap(bar_w);
      ImGui::ProgressBar(0.5f * (r->axes[std::size_t(a)] + 1.0f), ImVec2(bar_w, 0), label);
    }
    std::string pressed;
    for (int b = 0; b < r->num_buttons; ++b)
      if (r->buttons[std::size_t(b)]) pressed += " b" + std::to_string(b);
    for (int h = 0; h < r->num_hats; ++h)
      if (r->hats[std::size_t(h)]) pressed += " h" + std::to_string(h) + "." + std::to_string(r->hats[std::size_t(h)]);
    ImGui::Text("pressed:%s", pressed.empty() ? " none" : pressed.c_str());
  } else {
    ImGui::TextDisabled("(waiting for the device)");
  }
  ImGui::Separator();
  std::string bound;
  for (const std::string& b : w.bindings) bound += b + "  ";
  ImGui::TextWrapped("bound: %s", bound.empty() ? "nothing yet" : bound.c_str());
  if (!w.mapping.empty() && w.done) ImGui::TextWrapped("%s", w.mapping.c_str());
  ImGui::BeginDisabled(w.done || !w.optional);
  if (ImGui::Button("Skip")) out.push_back(WizardSkip{});
  tip("Leave this control unbound (only the optional ones)");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(w.step == 0);
  if (ImGui::Button("Back")) out.push_back(WizardBack{});
  tip("Bind the previous control again");
  ImGui::EndDisabled();
  ImGui::SameLine();
  ImGui::BeginDisabled(w.mapping.empty());
  if (ImGui::Button("Save")) out.push_back(WizardSave{});
  tip("Write the mapping into your mappings and use the pad at once");
  ImGui::EndDisabled();
  ImGui::SameLine();
  const bool cancel = ImGui::Button("Cancel");
  tip("Stop mapping; nothing is written (Esc)");
  if (cancel || key_pressed(Key::escape)) out.push_back(WizardCancel{});
  ImGui::End();
}

void draw_input_banner(const History& h, const RunInfo& run, ImVec2 min, ImVec2 max) {
  const bool waiting = run.input && run.input->waiting;
  const InputState state = h.empty() ? InputState::ok : h.newest().pilot.input;
  if (!waiting && state == InputState::ok) return;
  char text[160];
  ImU32 c = colour::kCritical;
  switch (state) {
    case InputState::lost:
      // The instructor's simulated loss (SPEC §10) needs no reconnecting: it ends by itself.
      if (h.newest().instructor.input_loss_left > 0.0)
        std::snprintf(text, sizeof text, "INPUT LOST (the instructor's, %.1f s left): the planner "
                      "flies.", h.newest().instructor.input_loss_left);
      else
        std::snprintf(text, sizeof text, "INPUT LOST: the planner flies. Reconnect the %s.",
                      run.input && !run.input->pilot.empty() ? run.input->pilot.c_str() : "device");
      break;
    case InputState::recentre:
      std::snprintf(text, sizeof text, "The %s is back: centre the sticks to take control.",
                    run.input && !run.input->pilot.empty() ? run.input->pilot.c_str() : "device");
      c = colour::kCaution;
      break;
    case InputState::returning:
      std::snprintf(text, sizeof text, "Control returning to the pilot: %.0f %%",
                    100.0 * h.newest().pilot.authority);
      c = colour::kCaution;
      break;
    default:
      std::snprintf(text, sizeof text,
                    "Connect a gamepad to start (or pick the keyboard as the pilot).");
      c = colour::kCaution;
      break;
  }
  // Larger than the text around it where the view is wide; wrapped where it is narrow.
  ImDrawList* dl = ImGui::GetForegroundDrawList();
  const ImVec2 pad(scaled(16), scaled(10));
  const float room = std::max(1.0f, max.x - min.x - 2 * pad.x - 2 * ImGui::GetFontSize());
  const float scale = std::clamp(room / std::max(ImGui::CalcTextSize(text).x, 1.0f), 1.0f, 1.4f);
  const float size_px = ImGui::GetFontSize() * scale;
  const ImVec2 ts = ImGui::GetFont()->CalcTextSizeA(size_px, FLT_MAX, room, text);
  const ImVec2 size(ts.x + 2 * pad.x, ts.y + 2 * pad.y);
  const ImVec2 p(0.5f * (min.x + max.x - size.x), min.y + 0.42f * (max.y - min.y));
  dl->AddRectFilled(p, ImVec2(p.x + size.x, p.y + size.y), colour::rgb(0x10, 0x10, 0x10, 230), scaled(6.0f));
  dl->AddRect(p, ImVec2(p.x + size.x, p.y + size.y), c, scaled(6.0f), 0, scaled(2.5f));
  dl->AddText(ImGui::GetFont(), size_px, ImVec2(p.x + pad.x, p.y + pad.y), c, text, nullptr, room);
}

}  // namespace mixpilot::ui
