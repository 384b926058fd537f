#include "app/input_controller.hpp"

#include <cstdio>

#include "input/mapping.hpp"

namespace mixpilot::cli {

InputController::InputController(const std::string& settings_path, StatusLine& status)
    : status_(status),
      settings_path_(settings_path.empty() ? input::default_settings_path() : settings_path) {
  settings_ = load_input_settings(settings_path_, info_.note);
  if (!info_.note.empty())
    status_.say(settings_path_.empty()  // no home folder: the note says so
                    ? info_.note
                    : settings_path_ +
                          " has errors: the default input settings are used (I shows them)",
                true);
}

std::shared_ptr<input::Gamepad> InputController::gamepad(std::string& error) {
  if (gamepad_) return gamepad_;
  auto g = std::make_shared<input::Gamepad>();
  input::Gamepad::Options go;
  go.preferred = settings_.gamepad;
  go.mappings_file = input::user_mappings_path();
  if (!g->start(go, error)) return nullptr;
  if (!g->mappings_note().empty()) {
    std::fprintf(stderr, "mixpilot: %s\n", g->mappings_note().c_str());
    status_.say(go.mappings_file + " was left out (see the terminal); SDL's built-in mappings apply",
                true);
  }
  return gamepad_ = std::move(g);
}

void InputController::update(const Devices* d, bool waiting, bool panel_shown, bool mapping) {
  info_.pilot = d ? (d->keyboard ? "keyboard" : "gamepad") : "";
  info_.waiting = waiting;
  info_.settings = &settings_;
  info_.settings_path = settings_path_;
  if (d && d->keyboard) {
    info_.connected = true;
    info_.device = "keyboard";
  }
  // The settings panel lists SDL's joysticks, whatever flies.
  if (!gamepad_ && panel_shown && !gamepad_failed_) {
    std::string error;
    if (!gamepad(error)) {  // said once; SDL is not asked again every frame
      info_.message = error;
      gamepad_failed_ = true;
    }
  }
  if (!gamepad_) return;
  if (!d || !d->keyboard) {
    info_.connected = gamepad_->connected();
    info_.device = gamepad_->active_name();
    info_.live = gamepad_->latest_for_ui().sticks;
  }
  info_.devices.clear();
  info_.active = -1;
  for (const input::GamepadInfo& g : gamepad_->devices()) {
    info_.devices.push_back({g.instance, g.name, g.controller});
    if (g.controller && g.name == gamepad_->active_name()) info_.active = g.instance;
  }
  if (!mapping) {
    std::string error;
    if (gamepad_->mapping_status(error) < 0) info_.message = error;
  }
}

bool InputController::handle(const ui::InputRequest& r) {
  return std::visit(
      ui::overloaded{
          [&](const ui::ApplySettings& a) {
            settings_ = a.settings;
            if (a.save) {
              std::string error;
              if (input::save_settings(settings_path_, settings_, error)) {
                info_.note.clear();
                status_.say("input settings saved to " + settings_path_);
              } else {
                status_.say(error, true);
              }
            }
            return true;
          },
          [&](const ui::UseGamepad& u) {
            if (gamepad_) gamepad_->choose(u.instance);
            return false;
          },
      },
      r);
}

}  // namespace mixpilot::cli
