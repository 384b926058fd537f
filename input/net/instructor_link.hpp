#pragma once
// A station's side of the instructor's network (SPEC §10, docs/instructor-security.md): it
// announces the station on rt/mixpilot/station (mixpilot_msgs/StationStatus, twice a second and
// at once after each command) and takes the instructor's commands from
// rt/mixpilot/instructor/command (mixpilot_msgs/InstructorCommand).
//
// Its thread (DDS's side) reads each command; one addressed to another station is ignored; one
// addressed here is checked (input/net/instructor_checks.hpp: the station's policy, then the
// values, the age and the issuer's order) and, when taken, pushed into the ring of
// InstructorCommand the caller owns, which the control thread drains between two steps. Every
// refusal is counted by reason and announced with the station, as is what DDS Security refused
// of the peers (Cyclone's log, input/net/dds.hpp), and the newest results (issuer, sequence,
// result), so an instructor learns what became of its command.
//
// The control thread gives it each step's telemetry (on_sample: a few atomic stores and a
// wait-free slot, never a wait) for the announcement's time, λ, deviation, time in B, mean λ
// so far and what the instructor's commands keep in force (bounds, a gust, an extra delay, an
// input loss), which is announced at once when it changes, so an instructor sees a gust while
// it acts; before the first step, ready() gives what the flight will start with.
#include <array>
#include <atomic>
#include <functional>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "core/base/latest.hpp"
#include "core/base/spsc_ring.hpp"
#include "core/modes/instructor.hpp"
#include "core/modes/session.hpp"
#include "input/net/dds.hpp"
#include "input/net/instructor_checks.hpp"

namespace mixpilot::net {

inline constexpr const char* kStationTopic = "rt/mixpilot/station";
inline constexpr const char* kCommandTopic = "rt/mixpilot/instructor/command";

enum class StationState : std::uint8_t { ready = 0, flying = 1, paused = 2, ended = 3 };
const char* to_string(StationState s);  // "ready", "flying", "paused", "ended"

// How a station treats commands, announced with it.
enum class CommandSecurity : std::uint8_t {
  no_instructor = 0,             // it obeys no instructor: every command refused
  dds_security = 1,              // commands come over DDS Security
  unauthenticated_loopback = 2,  // unauthenticated commands explicitly allowed, DDS on loopback
  unauthenticated_refused = 3,   // no DDS Security configured: commands refused
};
const char* to_string(CommandSecurity s);

// The station's policy from what the user chose: `instructor` (fly --instructor or the
// setting), DDS Security configured, `allow_unauthenticated` (--allow-unauthenticated-commands).
// Unauthenticated commands are allowed only on a loopback-only configuration: false with the
// reason otherwise (the flight must not start).
[[nodiscard]] bool command_security(bool instructor, bool secured, bool allow_unauthenticated,
                                    CommandSecurity& out, std::string& error);

struct StationInfo {
  std::string name;      // the station's id (1 to 63 bytes of printable UTF-8)
  std::string trainee;
  std::string scenario;
  std::string mode;
  double duration = 0.0;     // [s] the flight's planned length
  double ball_radius = 0.0;  // [m] r of the ball B (time in B), 0: none
};
// "" when `name` can name a station, else why not.
std::string check_station_name(const std::string& name);
// The default station name: the host name and this process's id ("host-1234").
std::string default_station_name();

struct InstructorLinkStats {
  std::uint64_t accepted = 0;
  std::array<std::uint64_t, kCommandRefusals> refused{};  // by CommandRefusal (index 0 unused)
  std::uint64_t ignored = 0;        // addressed to another station
  std::uint64_t announcements = 0;  // written
  std::uint64_t security_refused = 0;  // what DDS Security refused (Cyclone's log)
  std::string security_last;
  std::string last_refusal;  // the newest refusal in words, "" when none
  std::uint64_t refused_total() const;
};

class InstructorLink final : public TelemetrySink {
 public:
  struct Options {
    std::uint32_t domain = 0;
    StationInfo station;
    CommandSecurity security = CommandSecurity::no_instructor;
    double announce_period_s = 0.5;
    InstructorCheck::Limits limits;
    // Whether the flight is held by an instructor's pause (no step flies, so no sample says
    // it), read by the announcing thread; empty: never paused.
    std::function<bool()> paused;
  };
  static constexpr int kRecent = 8;  // the newest command results announced

  InstructorLink() = default;
  ~InstructorLink() override { stop(); }
  InstructorLink(const InstructorLink&) = delete;
  InstructorLink& operator=(const InstructorLink&) = delete;

  // Joins the domain, creates the announcement writer and the command reader and starts the
  // thread; taken commands go into `ring` (which must outlive the link; its consumer is the
  // control thread).
  [[nodiscard]] bool start(const Options& options, SpscRing<InstructorCommand>* ring,
                           std::string& error);
  // Announces the station once more (its final state) and stops.
  void stop();

  void on_sample(const Telemetry& sample) override;  // control thread: atomic stores only
  // Before the flight starts (on the thread that starts it): its mode's telemetry before the
  // first step, for the announcement's λ (what the first step will use) and the bounds in
  // force. Not a sample: the state stays ready and no mean is taken.
  void ready(const Telemetry& before_first_step);
  void set_state(StationState s);                   // any thread

  InstructorLinkStats stats() const;
  const Options& options() const { return options_; }
  bool running() const { return running_.load(); }

 private:
  void run();
  void take_commands();
  void announce();
  // Whether what is in force, or the instructor's pause, changed in kind since the last
  // announcement (a gust started or ended, bounds or the delay changed...; not a gust's time
  // running down).
  bool in_force_changed();

  Options options_;
  SpscRing<InstructorCommand>* ring_ = nullptr;
  Participant participant_;
  std::int32_t reader_ = 0, writer_ = 0, waitset_ = 0;
  std::thread thread_;
  std::atomic<bool> running_{false};

  // Control thread → announcement.
  std::atomic<std::uint8_t> state_{std::uint8_t(StationState::ready)};
  std::atomic<double> t_{0}, lambda_{0}, deviation_{0}, time_in_ball_{0}, mean_lambda_{0};
  std::int64_t samples_ = 0, in_ball_ = 0;  // control thread only
  double lambda_sum_ = 0;
  Latest<InstructorInForce> in_force_;  // control thread → link thread (and stop()'s caller)

  // Link thread.
  InstructorCheck check_;
  RefusalLog refusals_;
  std::atomic<std::uint64_t> accepted_{0}, ignored_{0}, announcements_{0};
  struct Result {
    std::array<char, kMaxIssuer + 1> issuer{};
    std::uint64_t sequence = 0;
    std::int64_t issued_ns = 0;
    std::uint8_t result = 0;
  };
  std::array<Result, kRecent> recent_{};
  int recent_count_ = 0;  // results kept (newest last)
  // What the last announcement said is in force (link thread): a change in kind announces.
  InstructorInForce announced_force_;
  bool announced_paused_ = false;
};

}  // namespace mixpilot::net
