#pragma once
// The whole window, one frame at a time (SPEC §8, UI.md §1): a top bar with the status pill,
// the authority bar and the session buttons; the arena (3D) or Pendubot (2D) view in the centre;
// plots on the right; the sticks at the bottom. A function of the scene, the telemetry history
// and the UI's own state; what the user asked for comes back as a UiRequest.
#include "ui/scene.hpp"

namespace mixpilot::ui {

enum class Camera { chase, orbit, top, side };
const char* to_string(Camera c);

// What the app shows about the flight besides its telemetry.
enum class RunState { ready, flying, paused, finished, replay, lost };
const char* to_string(RunState s);

struct RunInfo {
  RunState state = RunState::ready;
  double speed = 1.0;            // real-time factor (slow motion < 1)
  std::int64_t deadline_misses = 0;
  bool recording = false;
  bool can_restart = false;      // the app can start the flight again (Restart, R)
  std::string message;           // a line for the status area ("" none)
  Metrics metrics;               // the score card at the end of a flight (empty: none yet)
};

// The UI's own state: kept by the app between frames, changed only by the UI.
struct UiState {
  Camera camera = Camera::chase;
  float orbit_yaw = 0.6f;     // [rad] orbit camera around the arena's centre
  float orbit_pitch = 0.5f;   // [rad]
  float orbit_distance = 0.0f;  // [m] 0: fit the arena
  bool plots_paused = false;
  double plot_window = 10.0;  // [s]
  bool show_sticks = true;
};

// What the user asked for in this frame (buttons, keys); the app acts on it.
struct UiRequest {
  bool start = false;
  bool toggle_pause = false;
  bool restart = false;
  bool quit = false;
  double speed = 0.0;  // > 0: a new speed
};

// Builds one frame's ImGui windows over the whole display (between ImGui::NewFrame() and
// ImGui::Render()).
UiRequest draw_screen(const Scene& scene, const History& history, const RunInfo& run,
                      UiState& ui);

}  // namespace mixpilot::ui
