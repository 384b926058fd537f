#pragma once
// The mapping wizard (SPEC §6): a joystick SDL has no mapping for becomes a gamepad. Map it...
// in the settings panel starts it on that device; the user moves each stick as prompted (the
// wizard reads the raw device every frame), skips or goes back, and Save writes the SDL line
// into the user's mappings and hands it to SDL at once. It lives while the panel maps one
// device; the gamepad it reads is the input controller's.
#include <optional>
#include <string>

#include "input/gamepad.hpp"
#include "input/mapping_wizard.hpp"
#include "ui/requests.hpp"
#include "ui/screen.hpp"

namespace mixpilot::cli {

class WizardController {
 public:
  bool running() const { return wizard_.has_value(); }

  // Acts on the wizard's buttons with SDL's gamepads `pad`; a new wizard maps for the stick
  // mode `stick_mode`. What it did, for the panel, goes in `message`.
  void handle(const ui::WizardRequest& r, input::Gamepad& pad, int stick_mode,
              std::string& message);
  // Once a frame: feeds the wizard the device's newest raw reading and fills the panel's view
  // of it (reset while no wizard runs, or SDL's gamepads are not started: `pad` nullptr).
  void update(input::Gamepad* pad, std::optional<ui::WizardView>& view);

 private:
  std::optional<input::MappingWizard> wizard_;
  std::string device_;        // the name of the joystick being mapped
  input::RawJoystick raw_;    // the newest raw reading (the view points at it)
};

}  // namespace mixpilot::cli
