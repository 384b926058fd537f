#include "input/virtual_gamepad.hpp"

#include <SDL2/SDL.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "core/base/input_file.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/source.hpp"

namespace mixpilot::input {

namespace {

SDL_Joystick* as_joystick(void* p) { return static_cast<SDL_Joystick*>(p); }

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r");
  const auto e = s.find_last_not_of(" \t\r");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

bool number(const std::string& cell, double& v) {
  const char* begin = cell.c_str();
  char* end = nullptr;
  v = std::strtod(begin, &end);
  return !cell.empty() && end == begin + cell.size() && std::isfinite(v);
}

}  // namespace

std::optional<std::vector<ScriptRow>> parse_script(const std::string& text,
                                                   const std::string& name,
                                                   std::string& error) {
  std::vector<ScriptRow> rows;
  // Any editor's line ends and byte-order mark read as written.
  std::istringstream in(normalize_text(text));
  std::string line;
  int n = 0;
  const auto fail = [&](const std::string& what) {
    error = name + ':' + std::to_string(n) + ": " + what;
    return std::nullopt;
  };
  while (std::getline(in, line)) {
    ++n;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    line = trim(line);
    if (line.empty()) continue;
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(trim(c));
    if (rows.empty() && cells[0] == "t") continue;  // the header
    ScriptRow r;
    // Bounded: a script's times become nanoseconds on the steady clock (int64), and nothing
    // flies longer than a day.
    if (!number(cells[0], r.t) || r.t < 0 || r.t > kMaxScriptSeconds)
      return fail("expected a time in seconds from 0 to " + std::to_string(int(kMaxScriptSeconds)) +
                  " first, got \"" + printable(cells[0]) + "\"");
    if (!rows.empty() && r.t < rows.back().t)
      return fail("time " + printable(cells[0]) + " is earlier than the row before");
    if (cells.size() == 2 && (cells[1] == "unplug" || cells[1] == "plug")) {
      r.kind = cells[1] == "unplug" ? ScriptRow::unplug : ScriptRow::plug;
    } else if (cells.size() == 5 || cells.size() == 7) {
      for (std::size_t i = 1; i < cells.size(); ++i) {
        double v = 0;
        const bool trigger = i >= 5;
        if (!number(cells[i], v) || v < (trigger ? 0.0 : -1.0) || v > 1.0)
          return fail("column " + std::to_string(i + 1) + ": expected a number in " +
                      (trigger ? "[0, 1]" : "[-1, 1]") + ", got \"" + printable(cells[i]) + "\"");
        r.values[i - 1] = float(v);
      }
    } else {
      return fail("expected t,left_x,left_y,right_x,right_y[,left_trigger,right_trigger] or "
                  "t,unplug or t,plug, got " + std::to_string(cells.size()) + " columns");
    }
    rows.push_back(r);
  }
  if (rows.empty()) {
    n = 0;
    return fail("no rows (expected t,left_x,left_y,right_x,right_y lines)");
  }
  return rows;
}

std::optional<std::vector<ScriptRow>> load_script(const std::string& path, std::string& error) {
  std::string text;
  if (!read_text_file(path, text, error)) return std::nullopt;
  return parse_script(text, path, error);
}

VirtualGamepad::~VirtualGamepad() {
  stop();
  unplug();
  if (sdl_started_) SDL_QuitSubSystem(SDL_INIT_JOYSTICK);
}

int VirtualGamepad::rumble_callback(void* self, std::uint16_t low, std::uint16_t) {
  auto* v = static_cast<VirtualGamepad*>(self);
  std::lock_guard<std::mutex> lock(v->mutex_);
  v->rumbles_.push_back({steady_ns(), double(low) / 65535.0});
  return 0;
}

bool VirtualGamepad::plug(std::string& error) {
  if (joystick_) return true;
  if (!sdl_started_) {
    if (SDL_InitSubSystem(SDL_INIT_JOYSTICK) != 0) {
      error = std::string("virtual gamepad: SDL cannot start its joystick support (") +
              SDL_GetError() + ")";
      return false;
    }
    sdl_started_ = true;
  }
  SDL_VirtualJoystickDesc desc{};
  desc.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
  desc.type = SDL_JOYSTICK_TYPE_GAMECONTROLLER;
  desc.naxes = SDL_CONTROLLER_AXIS_MAX;
  desc.nbuttons = SDL_CONTROLLER_BUTTON_MAX;
  desc.axis_mask = (1u << SDL_CONTROLLER_AXIS_MAX) - 1;
  desc.button_mask = (1u << SDL_CONTROLLER_BUTTON_MAX) - 1;
  desc.name = "mixpilot virtual gamepad";
  desc.userdata = this;
  desc.Rumble = &VirtualGamepad::rumble_callback;
  const int index = SDL_JoystickAttachVirtualEx(&desc);
  if (index < 0) {
    error = std::string("virtual gamepad: SDL cannot attach it (") + SDL_GetError() + ")";
    return false;
  }
  SDL_Joystick* j = SDL_JoystickOpen(index);
  if (!j) {
    error = std::string("virtual gamepad: SDL cannot open it (") + SDL_GetError() + ")";
    SDL_JoystickDetachVirtual(index);
    return false;
  }
  joystick_ = j;
  device_index_ = index;
  // Centred sticks, released triggers.
  for (int a = 0; a < SDL_CONTROLLER_AXIS_MAX; ++a) set_axis(a, 0.0);
  return true;
}

void VirtualGamepad::unplug() {
  if (!joystick_) return;
  const SDL_JoystickID id = SDL_JoystickInstanceID(as_joystick(joystick_));
  SDL_JoystickClose(as_joystick(joystick_));
  joystick_ = nullptr;
  // Device indices shift as devices come and go: find ours by its instance id.
  for (int i = 0; i < SDL_NumJoysticks(); ++i) {
    if (SDL_JoystickGetDeviceInstanceID(i) == id) {
      SDL_JoystickDetachVirtual(i);
      break;
    }
  }
  device_index_ = -1;
}

void VirtualGamepad::set_axis(int axis, double v) {
  if (!joystick_) return;
  const bool trigger = axis == SDL_CONTROLLER_AXIS_TRIGGERLEFT ||
                       axis == SDL_CONTROLLER_AXIS_TRIGGERRIGHT;
  // A trigger's joystick axis spans the whole range: -32768 is released (SDL's mapping).
  const double raw = trigger ? -32768.0 + std::clamp(v, 0.0, 1.0) * 65535.0
                             : std::clamp(v, -1.0, 1.0) * 32767.0;
  SDL_JoystickSetVirtualAxis(as_joystick(joystick_), axis, Sint16(std::lround(raw)));
}

void VirtualGamepad::play(std::vector<ScriptRow> rows, std::int64_t start_ns) {
  stop();
  stop_ = false;
  done_ = false;
  player_ = std::thread([this, rows = std::move(rows), start_ns] {
    using clock = std::chrono::steady_clock;
    for (std::size_t i = 0; i < rows.size() && !stop_.load(); ++i) {
      const ScriptRow& r = rows[i];
      const auto due = clock::time_point(std::chrono::nanoseconds(start_ns + std::int64_t(r.t * 1e9)));
      // Short sleeps, so stop() is honoured promptly.
      while (!stop_.load() && clock::now() < due)
        std::this_thread::sleep_until(std::min(due, clock::now() + std::chrono::milliseconds(50)));
      if (stop_.load()) break;
      std::string error;
      switch (r.kind) {
        case ScriptRow::unplug: unplug(); break;
        case ScriptRow::plug: (void)plug(error); break;
        case ScriptRow::axes:
          for (int a = 0; a < SDL_CONTROLLER_AXIS_MAX; ++a) set_axis(a, r.values[a]);
          break;
      }
      std::lock_guard<std::mutex> lock(mutex_);
      applied_.emplace_back(i, steady_ns());
    }
    done_ = true;
  });
}

void VirtualGamepad::stop() {
  stop_ = true;
  if (player_.joinable()) player_.join();
}

std::vector<std::pair<std::size_t, std::int64_t>> VirtualGamepad::applied() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return applied_;
}

std::vector<RumbleEvent> VirtualGamepad::rumbles() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return rumbles_;
}

}  // namespace mixpilot::input
