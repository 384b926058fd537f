#pragma once
// The input settings and the gamepad (SPEC §6): the settings the next device flight flies with
// (the user's input.toml, changed by the settings panel's Apply and Save), and SDL's gamepad
// support, started when a flight or the panel first needs it and shared with every flight that
// flies it. Each frame it tells the screen what is connected (ui::InputInfo).
#include <memory>
#include <string>

#include "app/flight.hpp"
#include "app/status_line.hpp"
#include "input/gamepad.hpp"
#include "input/settings.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

class InputController {
 public:
  // `settings_path`: --input-settings ("": the user's input.toml). A broken file gives the
  // defaults, and `status` says so.
  InputController(const std::string& settings_path, StatusLine& status);

  const input::InputSettings& settings() const { return settings_; }
  // SDL's gamepads, started on first use; nullptr with the reason.
  [[nodiscard]] std::shared_ptr<input::Gamepad> gamepad(std::string& error);
  // A flight started its own (a script's virtual pad plugged before SDL's pads are listed):
  // that one is the app's from now on.
  void adopt(std::shared_ptr<input::Gamepad> pad) { gamepad_ = std::move(pad); }
  input::Gamepad* started() const { return gamepad_.get(); }  // nullptr: not yet started

  // Once a frame, what the screen shows of the input: `devices`, the live flight's person's
  // devices (nullptr: none flies); `waiting`, it waits for its gamepad; `panel_shown`, the
  // settings panel is open (it lists SDL's joysticks, so SDL starts); `mapping`, the mapping
  // wizard runs (it reads the mapping status itself).
  void update(const Devices* devices, bool waiting, bool panel_shown, bool mapping);
  // Apply / Save and Select. True when the settings changed: the next flight flies with them.
  [[nodiscard]] bool handle(const ui::InputRequest& r);

  const ui::InputInfo& info() const { return info_; }
  ui::InputInfo& info() { return info_; }  // the wizard's view and its messages go in it

 private:
  StatusLine& status_;
  input::InputSettings settings_;
  std::string settings_path_;
  std::shared_ptr<input::Gamepad> gamepad_;
  bool gamepad_failed_ = false;  // SDL could not start its gamepad support
  ui::InputInfo info_;
};

}  // namespace mixpilot::cli
