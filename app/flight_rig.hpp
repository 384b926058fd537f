#pragma once
// One flight, assembled once (SPEC §8): the mode of the scenario or recording the options name,
// its session, the person's device or network pilot, the remote vehicle's link, every sink
// (recording, replay check, haptic cue, telemetry publisher, and what a front end adds, such as
// screenshots or a replay's tape) and the real-time runner. Every way a flight is run builds it
// here: the window's live flights (app/trainer.cpp), `fly --headless` (app/fly.cpp), a replay's
// tape (app/replay_tape.cpp, the window's and `replay --headless`'s) and `score`
// (app/score.cpp); the tests drive the same class. A live flight is remembered in the trainee's
// history (SPEC §10) when it closes: remember() hands its row to the history's thread. Errors come back as values with an exit
// status; nothing here exits.
//
// The threads mixpilot starts, and who owns them (each is joined by its owner's stop or
// destructor; the UI thread, main's, never waits on any of them for longer than a join):
//   control       RealtimeRunner (core/runtime), SCHED_FIFO 10   the rig of a paced flight
//   recorder      RecordingSink's writer (core/recording)        the rig, while recording
//   publisher     net::TelemetryPublisher (input/net)            the rig, with --publish
//   instructor    net::InstructorLink (input/net): announces the  the rig, with --publish
//                 station, takes commands into the rig's ring
//   vehicle link  net::RemoteVehicle's reader (input/net), and   the rig's Flight, with
//                 Cyclone's receive threads, SCHED_FIFO 10 where  --vehicle dds
//                 allowed (core/base/realtime_priority.hpp)
//   joy peer      net::JoyPeer's reader (input/net)              the rig's Devices, --pilot dds
//   script pad    input::VirtualGamepad's player                 the rig's Devices, with
//                                                                --gamepad-script
//   gamepad       input::Gamepad's poller, SCHED_FIFO 9          the app, one per process
//                                                                (SDL's joystick state has one
//                                                                owner); a rig holds a share
//   replay tape   ReplayTape's loader (app/replay_tape.hpp)      the window's replay
//   take over     TakeOver's worker (app/take_over.hpp): flies   the window's Trainer, while
//                 a recording to the moment flown on from        it makes that moment ready
//   score jobs    score's worker pool (app/score.cpp)            `mixpilot score`
//   sweep jobs    run_pool (app/sweep_folder.hpp): one flight or  `mixpilot sweep`, `mixpilot
//                 replay per thread, each its own rig            score DIR`
//   history       HistoryWriter (app/history_writer.hpp): opens  the window's Trainer, or
//                 the store, hashes recordings, writes rows,    `fly --headless` (which waits
//                 loads what the window shows of the history    for it at the end)
//   vehicle       `mixpilot vehicle`'s plant loop runs on main; its DDS link's threads are
//                 Cyclone's, under RealtimeThreadsScope
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "app/flight.hpp"
#include "app/history_writer.hpp"
#include "core/history/history.hpp"
#include "core/modes/command_inbox.hpp"
#include "core/modes/report.hpp"
#include "core/modes/session.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/lesson.hpp"
#include "core/runtime/realtime_runner.hpp"
#include "core/base/spsc_ring.hpp"
#include "core/modes/instructor.hpp"
#include "input/net/instructor_link.hpp"
#include "input/net/telemetry_publisher.hpp"

namespace mixpilot::cli {

class FlightRig {
 public:
  // The flight `o` names, assembled: scenario (or the recording to fly again), mode, the
  // pilot's device, the replay check, the haptic cue, and with --vehicle dds the link, which
  // `wait` says whether to wait for here (block: up to --vehicle-wait) or to poll_vehicle()
  // frame by frame (later: the window, which never blocks). `gamepad`: the app's running
  // gamepad (one per process). nullptr with the reason and the exit status.
  [[nodiscard]] static std::unique_ptr<FlightRig> assemble(
      const FlyOptions& o, std::string& error, int& status,
      std::shared_ptr<input::Gamepad> gamepad = nullptr, VehicleWait wait = VehicleWait::block);
  ~FlightRig();
  FlightRig(const FlightRig&) = delete;
  FlightRig& operator=(const FlightRig&) = delete;

  // --vehicle dds with VehicleWait::later, polled without waiting: `none` without a remote
  // vehicle, `waiting` until it is heard, `ready` once it flies the mode, `failed` with the
  // reason (it answered with something this mode cannot fly).
  enum class VehicleStatus { none, waiting, ready, failed };
  [[nodiscard]] VehicleStatus poll_vehicle(std::string& error);
  // Seconds left of --vehicle-wait while waiting.
  double vehicle_wait_left() const;
  // Stops waiting (Esc): the next poll fails with "no vehicle heard".
  void cancel_vehicle_wait();

  // Sinks, added before start(). publish(): the telemetry over DDS (--publish), and the
  // station announced to instructors, whose commands it takes (--instructor) into
  // instructor_commands() (SPEC §10; --station, --dds-security,
  // --allow-unauthenticated-commands);
  // record(): the flight into `path` (a paced flight drops steps rather than wait for the
  // disk: `settings`). False with the reason.
  [[nodiscard]] bool publish(std::string& error);
  [[nodiscard]] bool record(const std::string& path, const std::string& trainee,
                            const RecordingSink::Settings& settings, bool overwrite,
                            std::string& error);
  // The flight goes into the history when it closes (SPEC §10: every flight one row), flown by
  // `trainee` ("" → the account's login name) from `front_end` ("window", "fly"; "vehicle"
  // whenever a remote vehicle flies it). Not a replay (it is no new flight: `history import`
  // adds recordings), nor a flight that never started. close() hands the row to `writer`
  // (which outlives the rig): its recording is hashed and the row written on the writer's
  // thread, so neither the control thread nor the UI ever waits for the history.
  void remember(HistoryWriter* writer, std::string trainee, std::string front_end);
  // A lesson step's flight (SPEC §10; the options' LessonTag names it): close() judges it
  // against `step`'s criteria (Closed::verdict), and a remembered flight goes into the history
  // with its verdict, as the step's attempt.
  void judge_as(LessonStep step) { lesson_step_ = std::move(step); }
  // Another sink (screenshots, a replay's tape), called on the thread that steps the session.
  void watch(TelemetrySink& sink) { session_->add_sink(&sink); }

  // The flight will be paced by the wall clock on the control thread, its telemetry handed
  // over through a ring of `ring_slots` steps (readable at once: runner()->telemetry()).
  // Without it the caller steps the flight with step(), as fast as it likes.
  void pace(std::size_t ring_slots);
  // The flight starts: the devices' clock (a script's t = 0) and, when paced, the runner.
  void start();
  bool step() { return session_->step(); }
  RealtimeRunner* runner() { return runner_.get(); }  // nullptr unless paced
  bool started() const { return started_; }
  // A paced flight has not ended yet (an unpaced one: not finished).
  bool running() const;
  // Stops the control thread (a paced flight): what it produced is in the ring to drain.
  void stop();

  // What closing the flight did, for the front end to say.
  struct Closed {
    std::string recorded;        // the recording's path ("" when none was written)
    std::int64_t dropped = 0;    // steps the recording lost (a paced flight on a slow disk)
    std::string error;           // the recording could not be completed ("" when fine)
    bool published = false;      // --publish: the publisher's counts
    std::uint64_t published_steps = 0, publish_dropped = 0;
    // --publish: the station's name and what became of the instructor's commands.
    std::string station;
    net::CommandSecurity command_security = net::CommandSecurity::no_instructor;
    net::InstructorLinkStats instructor;
    // remember(): the flight's row was handed to the writer (its outcome comes from there).
    bool remembering = false;
    // judge_as(): the verdict of a flight that flew (nullopt: none, or it never started).
    std::optional<LessonVerdict> verdict;
    std::optional<history::LessonAttempt> attempt;  // and the attempt it makes
  };
  // Stops the runner, the publisher and the vehicle link, and completes the recording
  // (`interrupted`: the flight stopped before its end). Once; later calls return {}.
  Closed close(bool interrupted);
  bool closed() const { return closed_; }

  // After the flight: its metrics (a replay's timing fields are the recorded flight's), the
  // report's labels, and what a replay did differently from its recording ("" when nothing).
  Metrics metrics() const;
  Labels labels(bool interrupted) const { return report_labels(flight_, interrupted); }
  std::string replay_difference() const;
  // The same among the steps flown so far, however many (a replay flown to a moment).
  std::string replay_difference_so_far() const;
  // The flight's history row as it stands: its labels, metrics, times, the scenario's and
  // input settings' hashes; the recording's path and hash once close() has completed it.
  // A replay's row describes the recorded flight (trainee and pilot from the recording).
  // nullopt with the reason (the recording cannot be read to hash it). Without `hash` the
  // recording's hash is left empty, for the writer to fill in off this thread.
  [[nodiscard]] std::optional<history::FlightRecord> flight_record(bool interrupted,
                                                                   std::string& error,
                                                                   bool hash = true) const;
  std::string recording_path() const { return record_path_; }
  // Who flies it as remember() was told ("" the account's login name), and when start() was
  // called (Unix ms; 0 before): a live flight's history row has both.
  const std::string& trainee() const { return trainee_; }
  std::int64_t started_unix_ms() const { return started_unix_ms_; }

  Mode& mode() { return *flight_.mode; }
  const Mode& mode() const { return *flight_.mode; }
  Session& session() { return *session_; }
  const Flight& flight() const { return flight_; }
  Flight& flight() { return flight_; }
  const FlyOptions& options() const { return options_; }
  net::TelemetryPublisher* publisher() { return publisher_ ? &*publisher_ : nullptr; }
  // --publish: the station's link to instructors (nullptr otherwise).
  net::InstructorLink* instructor_link() { return instructor_ ? &*instructor_ : nullptr; }
  // The instructor's commands into this flight (SPEC §10, core/modes/command_inbox.hpp): a
  // live flight's session takes them before each step (a replay applies its recorded ones
  // and has none). The station's link pushes into commands().ring() (a full ring refuses a
  // command as busy); --commands is scheduled here by assemble().
  CommandInbox& commands() { return inbox_; }
  const CommandInbox& commands() const { return inbox_; }

 private:
  FlightRig(FlyOptions o, Flight f);

  FlyOptions options_;
  Flight flight_;
  std::unique_ptr<Session> session_;
  std::optional<ReplayCheck> check_;             // flying a recording's pilot commands
  std::optional<HapticSink> haptic_;             // a gamepad pilot: λ to the rumble
  std::optional<net::TelemetryPublisher> publisher_;
  CommandInbox inbox_;                           // before the link: it outlives it
  std::optional<net::InstructorLink> instructor_;
  RecordingSink recorder_;
  std::string record_path_;                      // "" when not recording
  std::unique_ptr<RealtimeRunner> runner_;
  // runner_ for the link's announcing thread (pace() may follow publish()); close() stops the
  // link before runner_ goes.
  std::atomic<const RealtimeRunner*> paced_{nullptr};
  VehicleStatus vehicle_ = VehicleStatus::none;
  std::chrono::steady_clock::time_point vehicle_deadline_;
  bool started_ = false, closed_ = false;
  std::int64_t started_unix_ms_ = 0;       // the wall-clock time of start()
  HistoryWriter* history_ = nullptr;        // remember()
  std::string trainee_, front_end_;
  bool completed_recording_ = false;        // close() completed record_path_
  std::optional<LessonStep> lesson_step_;   // judge_as()
};

// The station's lines of a summary (--publish): its name, how it treats an instructor's
// commands, how many it accepted and refused by reason, the newest refusal, and what DDS
// Security refused of the peers. "" without a station.
std::string station_summary(const FlightRig::Closed& c);
// "station NAME on rt/mixpilot/station (domain N): instructor commands ..." when it starts.
std::string station_started(const net::InstructorLink& link);

}  // namespace mixpilot::cli
