#include "input/mapping_wizard.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/base/input_file.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/mapping.hpp"
#include "input/settings.hpp"

namespace mixpilot::input {

namespace {

constexpr float kMoved = 0.5f;     // of the full range [-1, 1]: a control was moved
constexpr float kReleased = 0.25f;  // back this close to rest: let go

// The SDL stick axis ("leftx", "righty", ...) that carries `control` in `mode`.
std::string stick_axis(int mode, double Controls::*control) {
  Controls c;
  c.*control = 1.0;
  const StickAxes s = unassign(c, mode);
  if (s.left_x != 0) return "leftx";
  if (s.left_y != 0) return "lefty";
  if (s.right_x != 0) return "rightx";
  return "righty";
}

// "a3", "b0", "h0": an SDL input. (Built by appending: g++ 12 warns falsely on
// "literal" + std::string.)
std::string input(char kind, int index) {
  std::string s(1, kind);
  s += std::to_string(index);
  return s;
}

std::string which_stick(const std::string& axis) {
  return axis.starts_with("left") ? "left" : "right";
}

// The raw input a binding reads ("a1~" → "a1", "+a2" → "a2").
std::string input_of(std::string source) {
  if (!source.empty() && (source.front() == '+' || source.front() == '-')) source = source.substr(1);
  if (!source.empty() && source.back() == '~') source.pop_back();
  return source;
}

}  // namespace

MappingWizard::MappingWizard(int stick_mode, std::string guid, std::string name)
    : guid_(std::move(guid)), name_(std::move(name)) {
  // SDL names no comma inside a field: the device name loses them.
  std::replace(name_.begin(), name_.end(), ',', ' ');
  const std::string mode = " (Mode " + std::to_string(stick_mode) + ": the ";
  const auto stick = [&](const char* what, double Controls::*c, const char* direction, Want want) {
    const std::string axis = stick_axis(stick_mode, c);
    steps_.push_back({axis,
                      std::string("Push the ") + what + " stick " + direction + mode +
                          which_stick(axis) + " stick), then let it go back",
                      want, false});
  };
  stick("thrust", &Controls::thrust, "up", Want::stick_up);
  stick("yaw", &Controls::yaw, "right", Want::stick_right);
  stick("pitch", &Controls::pitch, "up (forward)", Want::stick_up);
  stick("roll", &Controls::roll, "right", Want::stick_right);
  const auto button = [&](const char* target, const char* what) {
    steps_.push_back({target, std::string("Press ") + what, Want::button, true});
  };
  button("a", "the bottom face button (A / cross)");
  button("b", "the right face button (B / circle)");
  button("x", "the left face button (X / square)");
  button("y", "the top face button (Y / triangle)");
  button("back", "Back / Select / Share");
  button("start", "Start / Options");
  button("leftshoulder", "the left shoulder button (L1 / LB)");
  button("rightshoulder", "the right shoulder button (R1 / RB)");
  steps_.push_back({"lefttrigger", "Pull the left trigger (L2 / LT)", Want::trigger, true});
  steps_.push_back({"righttrigger", "Pull the right trigger (R2 / RT)", Want::trigger, true});
  sources_.assign(steps_.size(), "");
}

bool MappingWizard::at_rest(const RawJoystick& raw) const {
  for (int a = 0; a < std::min(raw.num_axes, rest_.num_axes); ++a)
    if (std::abs(raw.axes[std::size_t(a)] - rest_.axes[std::size_t(a)]) > kReleased) return false;
  for (int b = 0; b < std::min(raw.num_buttons, rest_.num_buttons); ++b)
    if (raw.buttons[std::size_t(b)] != rest_.buttons[std::size_t(b)]) return false;
  for (int h = 0; h < std::min(raw.num_hats, rest_.num_hats); ++h)
    if (raw.hats[std::size_t(h)] != rest_.hats[std::size_t(h)]) return false;
  return true;
}

std::string MappingWizard::detect(const RawJoystick& raw, const Step& step) const {
  // The axis that moved most from rest.
  int axis = -1;
  float delta = 0;
  for (int a = 0; a < std::min(raw.num_axes, rest_.num_axes); ++a) {
    const float d = raw.axes[std::size_t(a)] - rest_.axes[std::size_t(a)];
    if (std::abs(d) > kMoved && std::abs(d) > std::abs(delta)) axis = a, delta = d;
  }
  const std::string a = axis >= 0 ? input('a', axis) : "";
  switch (step.want) {
    case Want::stick_up:  // SDL's y points down: an axis that grows upward is inverted
      return axis < 0 ? "" : delta < 0 ? a : a + "~";
    case Want::stick_right:
      return axis < 0 ? "" : delta > 0 ? a : a + "~";
    case Want::trigger:
      if (axis >= 0) {
        // A trigger resting at one end spans the whole axis; one resting mid-way, its half.
        const float rest = rest_.axes[std::size_t(axis)];
        if (rest < -0.5f) return a;
        if (rest > 0.5f) return a + "~";
        return std::string(1, delta > 0 ? '+' : '-').append(a);
      }
      [[fallthrough]];
    case Want::button:
      for (int b = 0; b < std::min(raw.num_buttons, rest_.num_buttons); ++b)
        if (raw.buttons[std::size_t(b)] && !rest_.buttons[std::size_t(b)])
          return input('b', b);
      for (int h = 0; h < std::min(raw.num_hats, rest_.num_hats); ++h) {
        const std::uint8_t v = raw.hats[std::size_t(h)];
        if (v != rest_.hats[std::size_t(h)] && (v == 1 || v == 2 || v == 4 || v == 8))
          return input('h', h).append(".").append(std::to_string(v));
      }
      return "";
  }
  return "";
}

void MappingWizard::feed(const RawJoystick& raw) {
  if (!have_rest_) {
    rest_ = raw;
    have_rest_ = true;
    return;
  }
  if (waiting_release_) {
    if (!at_rest(raw)) return;
    waiting_release_ = false;
    hint_.clear();
    advance();
    return;
  }
  if (done()) return;
  const std::string source = detect(raw, steps_[current_]);
  if (source.empty()) return;
  for (std::size_t i = 0; i < current_; ++i) {
    if (!sources_[i].empty() && input_of(sources_[i]) == input_of(source)) {
      hint_ = "That is already " + steps_[i].target + ": let go and try another control.";
      return;
    }
  }
  sources_[current_] = source;
  waiting_release_ = true;
  hint_ = "Got " + steps_[current_].target + " = " + source + ": let go.";
}

void MappingWizard::advance() {
  if (current_ < steps_.size()) ++current_;
}

bool MappingWizard::skip() {
  if (done() || !steps_[current_].optional) return false;
  sources_[current_].clear();
  waiting_release_ = false;
  hint_.clear();
  advance();
  return true;
}

void MappingWizard::back() {
  waiting_release_ = false;
  hint_.clear();
  if (current_ > 0) --current_;
  sources_[current_].clear();
}

std::vector<std::string> MappingWizard::bindings() const {
  std::vector<std::string> out;
  for (std::size_t i = 0; i < steps_.size(); ++i)
    if (!sources_[i].empty()) out.push_back(steps_[i].target + ":" + sources_[i]);
  return out;
}

std::string MappingWizard::mapping() const {
  for (std::size_t i = 0; i < steps_.size(); ++i)
    if (!steps_[i].optional && sources_[i].empty()) return "";
  std::string line = guid_ + "," + name_ + ",";
  for (const std::string& b : bindings()) line += b + ",";
  return line + "platform:Linux,";
}

bool save_mapping(const std::string& path, const std::string& line, std::string& error) {
  const std::string guid = line.substr(0, line.find(','));
  // The mappings already there are kept; the file is read as every input is (a FIFO or a
  // device put there must not block the window).
  std::string text;
  struct stat st {};
  if (!path.empty() && ::lstat(path.c_str(), &st) == 0 &&
      !read_input_file(path, kMaxTextFileBytes, text, error))
    return false;
  std::string kept;
  std::istringstream in(normalize_text(text));
  for (std::string l; std::getline(in, l);)
    if (!l.starts_with(guid + ",")) kept += l + "\n";
  return save_user_file(path, kept + line + "\n", error);
}

}  // namespace mixpilot::input
