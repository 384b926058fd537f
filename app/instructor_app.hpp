#pragma once
// The instructor's window behind `mixpilot instruct` (SPEC §10): a thread of its own runs the
// network (net::InstructorClient: the stations' announcements and telemetry, the commands and
// what became of each) and publishes an immutable snapshot (ui::InstructorView) after each of
// its rounds; the UI thread draws the newest snapshot (ui/instructor.hpp) and hands the commands
// asked for to that thread. The UI thread never waits on DDS: it only swaps pointers under a
// lock the network thread holds for nothing longer.
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "ui/instructor.hpp"

namespace mixpilot::net {
class InstructorClient;
}

namespace mixpilot::cli {

struct InstructorAppOptions {
  std::uint32_t domain = 0;
  std::string issuer;          // who commands (1 to 63 bytes of printable UTF-8)
  std::string security;        // the DDS Security folder in use, for the top bar ("" none)
  std::string select;          // the station shown large from the start ("" none)
  double period_s = 0.04;      // one round of the network thread
  double answer_s = 10.0;      // how long a command waits for its station, then its answer
};

class InstructorApp {
 public:
  explicit InstructorApp(InstructorAppOptions o);
  ~InstructorApp();
  InstructorApp(const InstructorApp&) = delete;
  InstructorApp& operator=(const InstructorApp&) = delete;

  // Joins the domain and starts the network thread. Without the right to command (DDS Security
  // refuses this identity the command writer) it watches only and says why; false with the
  // reason when it cannot even watch.
  [[nodiscard]] bool open(std::string& error);

  // One frame: the newest snapshot drawn, the commands asked for handed over.
  void build_frame(double wall_dt);

  // The newest snapshot (never null once open).
  std::shared_ptr<const ui::InstructorView> view() const;
  ui::InstructorUi& ui_state() { return ui_; }
  // The commands the window asked for since it opened (tests).
  std::uint64_t asked() const { return asked_; }

 private:
  // A command asked for, and what became of it.
  struct Command {
    InstructorCommand command;
    std::string what;  // in words
    double asked = 0.0, sent = 0.0;  // [s] this thread's clock
    std::uint64_t sequence = 0;
    std::int64_t issued_ns = 0;
    ui::CommandOutcome outcome = ui::CommandOutcome::waiting_for_station;
    std::string why;
  };
  // What the window keeps of a station heard.
  struct Sample {
    double t = 0.0;  // [s] the station's flight time (estimated between announcements)
    double p[3] = {}, q[4] = {1, 0, 0, 0};  // position [m], attitude (w, x, y, z)
    double lambda = 0.0, deviation = 0.0;
    AuthorityBounds bounds;  // the instructor's bounds as announced then
  };
  struct Station {
    std::uint64_t poses = 0, lambdas = 0;  // the telemetry counts last seen
    std::vector<Sample> samples;           // the last seconds, oldest first
    std::shared_ptr<const ui::History> history;  // made of them for the snapshot
    bool changed = false;
    std::vector<Command> commands;
  };
  struct SceneEntry {
    std::shared_ptr<const ui::Scene> scene;
    std::string note;
  };
  void run();  // the network thread
  void round();
  void take_requests();
  void track_commands(double now);
  std::shared_ptr<const ui::InstructorView> make_view(double now);
  const SceneEntry& scene_for(const std::string& scenario);

  InstructorAppOptions options_;
  std::unique_ptr<net::InstructorClient> client_;  // the network thread's alone once open
  std::string watch_only_;  // why this window cannot command ("" it can)

  // UI thread → network thread.
  mutable std::mutex inbox_mutex_;
  std::vector<ui::InstructorRequest> inbox_;
  // Network thread → UI thread.
  mutable std::mutex view_mutex_;
  std::shared_ptr<const ui::InstructorView> view_;

  std::thread thread_;
  std::atomic<bool> running_{false};

  // The network thread's own.
  std::map<std::string, Station> stations_;
  std::map<std::string, SceneEntry> scenes_;  // by scenario name

  // The UI thread's own.
  ui::InstructorUi ui_;
  std::vector<ui::InstructorRequest> requests_;
  std::uint64_t asked_ = 0;
};

// `mixpilot instruct`'s window (or, headless, its screenshots): app/instruct.cpp's options.
struct InstructWindowOptions {
  InstructorAppOptions app;
  bool headless = false;
  struct Shot {
    double t = 0;  // [s] after the window opened (headless: after `count` stations were heard)
    std::string path;
  };
  std::vector<Shot> screenshots;
  int width = 1280, height = 720;
  float scale = 0.0f;  // 0: the display's (headless: 1)
  bool overwrite = false;
  int count = 0;       // headless: wait for this many stations with telemetry first
  double wait_s = 10.0;  // ... at most this long
};

// Shows the window until it is closed, or renders the screenshots headless. The exit status
// (0, or kExitError / 5 when the stations were not heard) with the reason in `error`.
int run_instruct_window(const InstructWindowOptions& o, std::string& error);

}  // namespace mixpilot::cli
