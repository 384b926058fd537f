#pragma once
// The instructor's window (SPEC §10, `mixpilot instruct`): the stations announced on the DDS
// domain, up to four side by side — each a tile with a small arena, the λ strip, the deviation,
// the score so far, who flies what and in which state — one of them large with the full view
// (arena and plots), and the commands to the selected station with what became of each.
//
// A function of an immutable snapshot (InstructorView, made by app/instructor_app off the UI
// thread) and the window's own state (InstructorUi); what the user asked for comes back as
// requests. No network here: the view is the stations in the UI's terms.
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/modes/instructor.hpp"
#include "ui/scene.hpp"
#include "ui/screen.hpp"

namespace mixpilot::ui {

// What became of one command this window sent.
enum class CommandOutcome {
  waiting_for_station,  // not sent yet: the station's command reader has not matched ours
  sent,                 // sent, the station has not announced its result yet
  accepted,             // the station took it into its flight
  refused,              // the station refused it (why: the reason in words)
  failed,               // never sent (why: DDS said no, or the station never matched)
  no_answer,            // sent, but the station did not announce a result in time
};
const char* to_string(CommandOutcome o);  // "waiting", "sent", "accepted", "refused", ...

struct CommandRow {
  InstructorCommandKind kind = InstructorCommandKind::marker;
  std::string what;  // the command in words ("bounds: λ floor 0, ceiling 0.3")
  CommandOutcome outcome = CommandOutcome::sent;
  std::string why;   // refused / failed / no answer: the reason in words
  double age = 0.0;  // [s] since it was asked for
};

// One of the station's announced results (any instructor's).
struct AnnouncedResult {
  std::string issuer;
  std::uint64_t sequence = 0;
  bool accepted = false;
  std::string result;  // "accepted", or the refusal's reason ("instructor not allowed")
};

struct StationTile {
  std::string name, trainee, scenario, mode;
  std::string state = "ready";  // "ready", "flying", "paused", "ended"
  bool accepts_instructor = false;
  std::string security;         // how it treats commands, in words
  double t = 0, duration = 0;   // [s] the flight's time and planned length
  double lambda = 0, deviation = 0, time_in_ball = 0, mean_lambda = 0;  // announced
  // What the instructor's commands keep in force there now (bounds, a gust, an extra delay, an
  // input loss; the times left as announced, run down since while it flies); a pause is the
  // state "paused".
  InstructorInForce in_force;
  std::uint64_t accepted = 0, refused = 0;
  std::string last_refusal;     // the station's newest refusal in words
  double heard_ago = 0.0;       // [s] since its newest announcement
  bool telemetry = false;       // its pose and λ are heard here
  // The arena: the scenario's scene (nullptr: the scenario is not known here, the arena shows
  // the vehicle in a default volume) and the telemetry heard, as the app's screen draws it
  // (position, attitude, λ, reference point, deviation; the last seconds).
  std::shared_ptr<const Scene> scene;
  std::string scene_note;       // why there is no scene ("" none)
  std::shared_ptr<const History> history;
  std::vector<CommandRow> commands;        // this window's commands to it, oldest first
  std::vector<AnnouncedResult> announced;  // its newest results, newest last
};

struct InstructorView {
  std::vector<StationTile> stations;  // by name
  std::uint32_t domain = 0;
  std::string issuer;                 // who this window commands as
  std::string security;               // "DDS Security as FOLDER", "no DDS Security"
  std::string status;                 // a line for the top bar ("" none)
  bool status_is_error = false;
  bool can_command = true;            // the command writer exists (else: watching only)
};

// The commands' fields as the sliders and fields hold them.
struct CommandDraft {
  float floor = 0.0f, ceiling = 1.0f;
  float force[3] = {2.0f, 0.0f, 0.0f};  // [N]
  float gust_s = 0.5f;                  // [s]
  float delay_s = 0.1f;                 // [s]
  float loss_s = 1.0f;                  // [s]
  char marker[96] = "";
};

// The window's own state: kept between frames, changed only by the UI.
struct InstructorUi {
  std::string selected;  // the station commands go to ("" none yet: the first shown)
  bool large = false;    // the selected station shown large
  // Which stations the tiles show when more than four are announced (the list picks them);
  // empty: the first four.
  std::vector<std::string> shown;
  bool show_list = false;  // the list of every station (more than four)
  std::map<std::string, UiState> arenas;  // each tile's camera and plots
  CommandDraft draft;
  bool show_help = false;
};

// A command for a station.
struct InstructorRequest {
  std::string station;
  InstructorCommand command;
};

inline constexpr int kMaxTiles = 4;

// What a tile says is in force at its station, item by item as the trainee's HUD says it:
// {"instructor: paused", "· ceiling 0.30", "· gust 2.0 N, 0.3 s left", ...}; empty when
// nothing is. The tile shows them over the top of its arena (a window "##in force NAME"), a
// small tile on a line under its header.
std::vector<std::string> tile_in_force(const StationTile& t);

// The stations the tiles show: ui.shown's that are announced, completed up to four with the
// others in name order.
std::vector<const StationTile*> shown_tiles(const InstructorView& v, const InstructorUi& ui);

// Builds one frame over the whole display (between ImGui::NewFrame() and ImGui::Render());
// appends the commands asked for to `out`.
void draw_instructor(const InstructorView& v, InstructorUi& ui,
                     std::vector<InstructorRequest>& out);

// The λ strip: the recent λ of `h` (its last `seconds`) as a filled strip over [min, max): the
// pilot's share λ from the bottom in the pilot's colour, the planner's 1 − λ above it in the
// planner's (hatched, so the two read apart in greyscale), the λ line between them, and the
// instructor's bounds of each sample (Telemetry::instructor) as lines in the caution colour.
void draw_lambda_strip(const History& h, double seconds, ImVec2 min, ImVec2 max);

}  // namespace mixpilot::ui
