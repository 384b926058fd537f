#include "input/gamepad.hpp"

#include <SDL2/SDL.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "core/base/input_file.hpp"
#include "core/base/realtime_priority.hpp"
#include "core/scenario/scenario_toml.hpp"

namespace mixpilot::input {

namespace {

SDL_GameController* as_controller(void* p) { return static_cast<SDL_GameController*>(p); }

float axis_value(Sint16 v) { return std::clamp(float(v) / 32767.0f, -1.0f, 1.0f); }

// Community mapping databases are a few hundred kilobytes; the cap is every text input's.
constexpr long long kMaxMappingsBytes = kMaxTextFileBytes;

}  // namespace

// SDL mapping lines "GUID,name,mapping,...[,platform:NAME,]" by GUID, in one pass: comments and
// lines for another platform skipped, a later line for a GUID replacing an earlier one (as SDL
// does), a line without a GUID and a name counted as malformed.
MappingFile parse_mappings(std::string_view text) {
  MappingFile m;
  const std::string_view platform = SDL_GetPlatform();
  const std::string normalized = normalize_text(text);
  std::string_view rest = normalized;
  while (!rest.empty()) {
    const std::size_t end = rest.find('\n');
    std::string_view line = rest.substr(0, end);
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
    while (!line.empty() && (line.front() == ' ' || line.front() == '\t')) line.remove_prefix(1);
    if (line.empty() || line.front() == '#') continue;
    const std::size_t comma = line.find(',');
    if (comma == 0 || comma == std::string_view::npos || line.find(',', comma + 1) == std::string_view::npos) {
      ++m.malformed;
      continue;
    }
    if (const std::size_t p = line.find("platform:"); p != std::string_view::npos) {
      const std::string_view name = line.substr(p + 9, line.find(',', p) - (p + 9));
      if (name != platform) continue;
    }
    m.by_guid[std::string(line.substr(0, comma))] = std::string(line);
  }
  return m;
}

bool Gamepad::start(const Options& options, std::string& error) {
  options_ = options;
  // Pads keep working while the window is in the background (the trainee looks at the pad).
  SDL_SetHint(SDL_HINT_JOYSTICK_ALLOW_BACKGROUND_EVENTS, "1");
  if (SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER) != 0) {
    error = std::string("gamepad: SDL cannot start its game controller support (") +
            SDL_GetError() + ")";
    return false;
  }
  user_mappings_.clear();
  mappings_note_.clear();
  std::error_code ec;
  const std::string& file = options.mappings_file;
  if (!file.empty() && (std::filesystem::exists(file, ec) || std::filesystem::is_symlink(file, ec))) {
    std::string text, why;
    if (read_input_file(file, kMaxMappingsBytes, text, why)) {
      MappingFile m = parse_mappings(text);
      user_mappings_ = std::move(m.by_guid);
      if (m.malformed > 0)
        mappings_note_ = file + ": " + std::to_string(m.malformed) +
                         " line(s) are not SDL mappings (GUID,name,mapping...) and were skipped";
    } else {
      mappings_note_ = why + "\n(your gamepad mappings are left out; SDL's built-in ones apply)";
    }
  }
  running_ = true;
  thread_ = std::thread([this] { run(); });
  return true;
}

void Gamepad::stop() {
  if (!running_.exchange(false)) return;
  thread_.join();
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
}

std::vector<GamepadInfo> Gamepad::devices() const {
  std::lock_guard<std::mutex> lock(devices_mutex_);
  return devices_;
}

std::string Gamepad::active_name() const {
  std::lock_guard<std::mutex> lock(devices_mutex_);
  return active_;
}

void Gamepad::apply_user_mapping(int device_index) {
  if (user_mappings_.empty()) return;
  char guid[64];
  SDL_JoystickGetGUIDString(SDL_JoystickGetDeviceGUID(device_index), guid, sizeof guid);
  const auto it = user_mappings_.find(guid);
  if (it == user_mappings_.end()) return;
  (void)SDL_GameControllerAddMapping(it->second.c_str());  // a line SDL refuses: as SDL's loader
  user_mappings_.erase(it);
}

void Gamepad::refresh_devices() {
  std::vector<GamepadInfo> list;
  for (int i = 0; i < SDL_NumJoysticks(); ++i) {
    apply_user_mapping(i);
    GamepadInfo d;
    d.instance = SDL_JoystickGetDeviceInstanceID(i);
    const char* n = SDL_JoystickNameForIndex(i);
    d.name = n ? n : "(unnamed)";
    d.controller = SDL_IsGameController(i) == SDL_TRUE;
    char guid[64];
    SDL_JoystickGetGUIDString(SDL_JoystickGetDeviceGUID(i), guid, sizeof guid);
    d.guid = guid;
    list.push_back(std::move(d));
  }
  std::lock_guard<std::mutex> lock(devices_mutex_);
  devices_ = std::move(list);
}

bool Gamepad::open_device(std::int32_t wanted) {
  // The wanted instance, else the preferred name, else the first game controller.
  int pick = -1;
  for (int i = 0; i < SDL_NumJoysticks(); ++i) {
    apply_user_mapping(i);
    if (!SDL_IsGameController(i)) continue;
    if (SDL_JoystickGetDeviceInstanceID(i) == wanted) {
      pick = i;
      break;
    }
    const char* n = SDL_JoystickNameForIndex(i);
    if (wanted < 0 && !options_.preferred.empty() && n && options_.preferred == n) pick = i;
    if (pick < 0) pick = i;
  }
  if (pick < 0) return false;
  SDL_GameController* gc = SDL_GameControllerOpen(pick);
  if (!gc) return false;
  if (!SDL_GameControllerGetAttached(gc)) {  // a device SDL still lists but that is gone
    SDL_GameControllerClose(gc);
    return false;
  }
  controller_ = gc;
  instance_ = SDL_JoystickInstanceID(SDL_GameControllerGetJoystick(gc));
  const char* n = SDL_GameControllerName(gc);
  {
    std::lock_guard<std::mutex> lock(devices_mutex_);
    active_ = n ? n : "(unnamed)";
  }
  reading_.connected = true;
  connected_ = true;
  rumble_sent_ = 0.0f;
  return true;
}

void Gamepad::close_device() {
  if (controller_) SDL_GameControllerClose(as_controller(controller_));
  controller_ = nullptr;
  instance_ = -1;
  reading_.connected = false;
  connected_ = false;
  std::lock_guard<std::mutex> lock(devices_mutex_);
  active_.clear();
}

void Gamepad::add_mapping(const std::string& line) {
  std::lock_guard<std::mutex> lock(mapping_mutex_);
  pending_mapping_ = line;
  mapping_status_ = 0;
  mapping_error_.clear();
}

int Gamepad::mapping_status(std::string& error) const {
  std::lock_guard<std::mutex> lock(mapping_mutex_);
  error = mapping_error_;
  return mapping_status_;
}

bool Gamepad::apply_pending_mapping() {
  std::string line;
  {
    std::lock_guard<std::mutex> lock(mapping_mutex_);
    if (pending_mapping_.empty()) return false;
    line.swap(pending_mapping_);
  }
  const int added = SDL_GameControllerAddMapping(line.c_str());
  const std::string why = added < 0 ? SDL_GetError() : "";
  refresh_devices();
  std::lock_guard<std::mutex> lock(mapping_mutex_);
  mapping_status_ = added < 0 ? -1 : 1;
  mapping_error_ = added < 0 ? "SDL refused the mapping (" + why + ")" : "";
  return true;
}

void Gamepad::update_watch() {
  const std::int32_t want = watched_.load(std::memory_order_relaxed);
  auto* js = static_cast<SDL_Joystick*>(joystick_);
  if (js && (want != raw_reading_.instance || !SDL_JoystickGetAttached(js))) {
    SDL_JoystickClose(js);
    js = nullptr;
    joystick_ = nullptr;
    raw_reading_ = RawJoystick{};
    raw_.publish(raw_reading_);
  }
  if (!js && want >= 0) {
    for (int i = 0; i < SDL_NumJoysticks(); ++i)
      if (SDL_JoystickGetDeviceInstanceID(i) == want) js = SDL_JoystickOpen(i);
    if (!js) return;
    joystick_ = js;
    raw_reading_.instance = want;
  }
  if (!js) return;
  RawJoystick& r = raw_reading_;
  r.num_axes = std::min(SDL_JoystickNumAxes(js), RawJoystick::kMaxAxes);
  r.num_buttons = std::min(SDL_JoystickNumButtons(js), RawJoystick::kMaxButtons);
  r.num_hats = std::min(SDL_JoystickNumHats(js), RawJoystick::kMaxHats);
  for (int a = 0; a < r.num_axes; ++a) r.axes[std::size_t(a)] = axis_value(SDL_JoystickGetAxis(js, a));
  for (int b = 0; b < r.num_buttons; ++b) r.buttons[std::size_t(b)] = SDL_JoystickGetButton(js, b) != 0;
  for (int h = 0; h < r.num_hats; ++h) r.hats[std::size_t(h)] = SDL_JoystickGetHat(js, h);
  raw_.publish(r);
}

void Gamepad::run() {
  // Just below the control thread when the system allows it.
  (void)ask_realtime_priority(kInputPriority);

  const std::int64_t interval_ns = std::max<std::int64_t>(10'000, std::int64_t(options_.poll_interval_s * 1e9));
  const std::int64_t lead_ns = std::int64_t(options_.read_lead_s * 1e9);
  const std::uint64_t polls_per_second = std::max<std::int64_t>(1, 1'000'000'000 / interval_ns);
  const std::uint64_t pumps_every = std::max<std::int64_t>(1, 10'000'000 / interval_ns);
  std::int64_t next_tick = steady_ns(), served_read = 0;
  refresh_devices();
  std::int32_t wanted = -1;
  while (running_.load(std::memory_order_relaxed)) {
    // The next regular tick, or the sample just ahead of the control step's read if sooner.
    const std::int64_t read = next_read_ns_.load(std::memory_order_relaxed);
    const std::int64_t ahead = read - lead_ns;
    std::int64_t wake = next_tick + interval_ns;
    const bool for_read = read != served_read && ahead > steady_ns() && ahead < wake;
    if (for_read) wake = ahead;
    else next_tick = wake;
    const timespec ts{time_t(wake / 1'000'000'000), long(wake % 1'000'000'000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    if (for_read) served_read = read;
    if (steady_ns() > next_tick + 1'000'000'000) next_tick = steady_ns();  // no catching up

    // The sticks every poll; SDL's whole event pump (hot-plug) every 10 ms. The sample is
    // stamped before the device is read: whatever changed before the stamp is in it.
    SDL_Event e;
    bool changed_devices = false;
    const std::int64_t now = steady_ns();
    SDL_JoystickUpdate();
    if (polls_ % pumps_every == 0) SDL_PumpEvents();
    while (SDL_PeepEvents(&e, 1, SDL_GETEVENT, SDL_FIRSTEVENT, SDL_LASTEVENT) > 0) {
      if (e.type == SDL_CONTROLLERDEVICEREMOVED && e.cdevice.which == instance_) close_device();
      if (e.type == SDL_JOYDEVICEADDED || e.type == SDL_JOYDEVICEREMOVED ||
          e.type == SDL_CONTROLLERDEVICEADDED || e.type == SDL_CONTROLLERDEVICEREMOVED)
        changed_devices = true;
    }
    const std::int32_t w = wanted_.load(std::memory_order_relaxed);
    const bool rechoose = w != wanted;
    if (rechoose && controller_ && w != instance_) close_device();
    wanted = w;
    if (apply_pending_mapping()) changed_devices = true;  // a pad it names can open now
    else if (changed_devices) refresh_devices();
    update_watch();
    // Hot-plug: a pad that arrives is taken at once; otherwise look again every second.
    if (!controller_ && (changed_devices || rechoose || polls_ % polls_per_second == 0)) open_device(wanted);

    reading_.alive_ns = now;
    // Gone before SDL's removal event arrives: lost at once, not a poll of zeros later.
    if (controller_ && !SDL_GameControllerGetAttached(as_controller(controller_))) close_device();
    if (SDL_GameController* gc = as_controller(controller_)) {
      JoyInput j;
      j.num_axes = SDL_CONTROLLER_AXIS_MAX;  // LX, LY, RX, RY, LT, RT (SDL: y down positive)
      for (int a = 0; a < SDL_CONTROLLER_AXIS_MAX; ++a)
        j.axes[std::size_t(a)] = axis_value(SDL_GameControllerGetAxis(gc, SDL_GameControllerAxis(a)));
      j.num_buttons = std::min<int>(SDL_CONTROLLER_BUTTON_MAX, JoyInput::kMaxButtons);
      for (int b = 0; b < j.num_buttons; ++b)
        j.buttons[std::size_t(b)] = SDL_GameControllerGetButton(gc, SDL_GameControllerButton(b));
      if (j.axes != reading_.joy.axes || j.buttons != reading_.joy.buttons ||
          j.num_axes != reading_.joy.num_axes) {
        reading_.joy = j;
        reading_.sticks = {j.axes[0], -j.axes[1], j.axes[2], -j.axes[3]};
        reading_.changed_ns = now;
        ++reading_.serial;
      }
      // The haptic cue: refreshed while it plays, stopped once when it ends.
      const bool renewed = now - rumble_set_ns_.load(std::memory_order_relaxed) <= kRumbleHoldNs;
      const float r = renewed ? rumble_.load(std::memory_order_relaxed) : 0.0f;
      if (std::abs(r - rumble_sent_) >= 1.0f / 256 || (r > 0 && now - rumble_sent_ns_ > 100'000'000)) {
        const auto level = Uint16(std::lround(std::clamp(r, 0.0f, 1.0f) * 65535.0f));
        SDL_GameControllerRumble(gc, level, level, r > 0 ? 250 : 0);
        rumble_sent_ = r;
        rumble_sent_ns_ = now;
      }
    }
    for_control_.publish(reading_);
    for_ui_.publish(reading_);
    polls_.fetch_add(1, std::memory_order_relaxed);
  }
  close_device();
  if (joystick_) SDL_JoystickClose(static_cast<SDL_Joystick*>(joystick_));
  joystick_ = nullptr;
}

}  // namespace mixpilot::input
