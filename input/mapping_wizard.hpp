#pragma once
// A mapping for a joystick SDL does not know (SPEC §6). The wizard asks for one control at a
// time ("push the thrust stick up"), sees which raw axis, button or hat moved, and builds the
// SDL GameController mapping line (`GUID,name,leftx:a0,lefty:a1~,...,platform:Linux,`) that
// the user's mappings file keeps. It is pure logic: the app feeds it the raw joystick each
// frame (Gamepad::watch()), so tests drive it with made-up readings as well as with SDL.
//
// The rest position is the reading when the wizard starts (triggers may rest at −1). A control
// counts when it moves more than half its range from rest; the next step waits until every
// input is back near rest. SDL's y axes point down, so "up" on a raw axis that grows when
// pushed up is bound inverted (`a1~`).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace mixpilot::input {

// A joystick as SDL's Joystick API reports it (axes scaled to [-1, 1]).
struct RawJoystick {
  static constexpr int kMaxAxes = 16, kMaxButtons = 32, kMaxHats = 4;
  std::int32_t instance = -1;  // SDL instance id (-1: none open)
  int num_axes = 0, num_buttons = 0, num_hats = 0;
  std::array<float, kMaxAxes> axes{};
  std::array<bool, kMaxButtons> buttons{};
  std::array<std::uint8_t, kMaxHats> hats{};  // SDL_HAT_* bits
};

class MappingWizard {
 public:
  enum class Want { stick_up, stick_right, button, trigger };
  struct Step {
    std::string target;  // SDL's name: "lefty", "a", "lefttrigger", ...
    std::string prompt;  // what the user is asked to do
    Want want;
    bool optional;       // may be skipped (buttons and triggers)
  };

  // `stick_mode` 1-4 names the sticks by what they fly; `guid` and `name` as SDL reports them.
  MappingWizard(int stick_mode, std::string guid, std::string name);

  const std::vector<Step>& steps() const { return steps_; }
  std::size_t current() const { return current_; }  // == steps().size() when done
  bool done() const { return current_ >= steps_.size(); }
  const std::string& guid() const { return guid_; }
  // A line for the user while a step waits: "let go of the stick", "already bound to ...".
  const std::string& hint() const { return hint_; }

  // One reading of the raw joystick (any rate; the first one is the rest position).
  void feed(const RawJoystick& raw);
  // Skips an optional step (no binding); false for a required one.
  bool skip();
  // Goes back one step and forgets its binding.
  void back();

  // The bindings so far, "target:source" in step order.
  std::vector<std::string> bindings() const;
  // The SDL mapping line; empty until every required step has a binding.
  std::string mapping() const;

 private:
  std::string detect(const RawJoystick& raw, const Step& step) const;  // "" nothing yet
  bool at_rest(const RawJoystick& raw) const;
  void advance();

  std::vector<Step> steps_;
  std::vector<std::string> sources_;  // per step: "a1~", "b0", "h0.1", "" (skipped / not yet)
  std::size_t current_ = 0;
  std::string guid_, name_, hint_;
  RawJoystick rest_;
  bool have_rest_ = false;
  bool waiting_release_ = false;
};

// Writes `line` into the mappings file at `path` (replacing a line for the same GUID, keeping
// the others), atomically. The folder is created when missing.
[[nodiscard]] bool save_mapping(const std::string& path, const std::string& line,
                                std::string& error);

}  // namespace mixpilot::input
