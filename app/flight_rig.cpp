#include "app/flight_rig.hpp"

#include "app/cli.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "core/base/content_hash.hpp"
#include "core/modes/command_script.hpp"
#include "core/numerics/version.hpp"
#include "core/recording/branch_replay.hpp"
#include "input/net/dds.hpp"

namespace mixpilot::cli {

namespace {

// Each scripted command against the flight: one it would refuse, or one after its end, is an
// error before the flight rather than a surprise in it.
bool check_script(const std::vector<ScriptedCommand>& script, const Mode& mode,
                  const std::string& path, std::string& error) {
  const double end = double(mode.steps_total()) * mode.dt();
  for (const ScriptedCommand& c : script) {
    const std::string at = path + ":" + std::to_string(c.line) + ": ";
    const InstructorStatus s = mode.accepts(c.command.kind);
    if (s != InstructorStatus::applied) {
      error = at + "a " + to_string(c.command.kind) + " command, which this flight (" +
              to_string(mode.kind()) + ") refuses: " + to_string(s);
      return false;
    }
    if (CommandInbox::step_of(c.at, mode.dt()) >= mode.steps_total()) {
      error = at + "at = " + seconds_text(c.at) + " s is not before the flight's end at " +
              seconds_text(end) + " s";
      return false;
    }
  }
  return true;
}

}  // namespace

FlightRig::FlightRig(FlyOptions o, Flight f) : options_(std::move(o)), flight_(std::move(f)) {
  session_ = std::make_unique<Session>(*flight_.mode);
  if (!flight_.recording) session_->set_inbox(&inbox_);
  if (flight_.recording) {
    check_.emplace(*flight_.recording);
    session_->add_sink(&*check_);
  }
  if (flight_.devices) {
    haptic_.emplace(*flight_.devices);
    session_->add_sink(&*haptic_);
  }
}

FlightRig::~FlightRig() {
  if (!closed_) (void)close(!flight_.mode->finished());
}

std::unique_ptr<FlightRig> FlightRig::assemble(const FlyOptions& o, std::string& error,
                                               int& status,
                                               std::shared_ptr<input::Gamepad> gamepad,
                                               VehicleWait wait) {
  std::optional<Flight> f = prepare_flight(o, error, status, std::move(gamepad), wait);
  if (!f) return nullptr;
  std::unique_ptr<FlightRig> rig(new FlightRig(o, std::move(*f)));
  if (!o.commands.empty()) {
    auto script = load_command_script(o.commands, error);
    if (!script || !check_script(*script, rig->mode(), o.commands, error)) {
      status = kExitError;
      return nullptr;
    }
    rig->inbox_.schedule(std::move(*script));
  }
  if (rig->flight_.vehicle) {
    if (wait == VehicleWait::later) {
      rig->vehicle_ = VehicleStatus::waiting;
      rig->vehicle_deadline_ = std::chrono::steady_clock::now() +
                               std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>(o.vehicle_wait_s));
    } else {
      rig->vehicle_ = VehicleStatus::ready;  // prepare_flight waited and attached it
    }
  }
  return rig;
}


FlightRig::VehicleStatus FlightRig::poll_vehicle(std::string& error) {
  if (vehicle_ != VehicleStatus::waiting) return vehicle_;
  if (flight_.vehicle->heard()) {
    vehicle_ = attach_vehicle(flight_, error) ? VehicleStatus::ready : VehicleStatus::failed;
  } else if (std::chrono::steady_clock::now() >= vehicle_deadline_) {
    error = vehicle_not_heard(options_, flight_);
    vehicle_ = VehicleStatus::failed;
  }
  return vehicle_;
}

double FlightRig::vehicle_wait_left() const {
  if (vehicle_ != VehicleStatus::waiting) return 0.0;
  return std::max(0.0, std::chrono::duration<double>(vehicle_deadline_ -
                                                     std::chrono::steady_clock::now())
                           .count());
}

void FlightRig::cancel_vehicle_wait() {
  if (vehicle_ == VehicleStatus::waiting) vehicle_deadline_ = std::chrono::steady_clock::now();
}

bool FlightRig::publish(std::string& error) {
  net::use_loopback_unless_configured();
  // The station's identity and policy first: a station that cannot say what it obeys does not
  // fly.
  net::InstructorLink::Options lo;
  lo.domain = options_.domain;
  if (!options_.dds_security.empty()) {
    const std::optional<net::SecurityFiles> files =
        net::security_files(options_.dds_security, error);
    if (!files) return false;
    net::use_security(*files);
  }
  if (!net::command_security(options_.instructor, net::security_configured(),
                             options_.allow_unauthenticated_commands, lo.security, error))
    return false;
  lo.station.name = options_.station.empty() ? net::default_station_name() : options_.station;
  if (const std::string why = net::check_station_name(lo.station.name); !why.empty()) {
    error = "--station: " + why;
    return false;
  }
  const Mode& mode = *flight_.mode;
  lo.station.trainee = options_.trainee.empty() ? history::login_name() : options_.trainee;
  lo.station.scenario = mode.scenario_name();
  lo.station.mode = to_string(mode.kind());
  lo.station.duration = double(mode.steps_total()) * mode.dt();
  lo.station.ball_radius = mode.view().ball_radius;
  lo.paused = [this] {
    const RealtimeRunner* r = paced_.load();
    return r && r->instructor_paused();
  };
  publisher_.emplace();
  if (!publisher_->start(options_.domain, mode.telemetry(), error, lo.station.name)) {
    publisher_.reset();
    error = "--publish: " + error;
    return false;
  }
  instructor_.emplace();
  if (!instructor_->start(lo, &inbox_.ring(), error)) {
    instructor_.reset();
    publisher_->stop();
    publisher_.reset();
    error = "--publish: " + error;
    return false;
  }
  // READY announces what the flight will start with (λ within its bounds), not a λ of 0.
  instructor_->ready(mode.telemetry());
  session_->add_sink(&*publisher_);
  session_->add_sink(&*instructor_);
  return true;
}

bool FlightRig::record(const std::string& path, const std::string& trainee,
                       const RecordingSink::Settings& settings, bool overwrite,
                       std::string& error) {
  if (!recorder_.open(path, *flight_.mode, session_info(flight_, trainee), error, settings,
                      overwrite))
    return false;
  record_path_ = path;
  session_->add_sink(&recorder_);
  return true;
}

void FlightRig::remember(HistoryWriter* writer, std::string trainee, std::string front_end) {
  history_ = writer;
  trainee_ = std::move(trainee);
  front_end_ = std::move(front_end);
}

void FlightRig::pace(std::size_t ring_slots) {
  runner_ = std::make_unique<RealtimeRunner>(*session_, ring_slots);
  paced_.store(runner_.get());
}

void FlightRig::start() {
  if (started_) return;
  if (flight_.devices) flight_.devices->started();
  if (runner_) runner_->start();
  started_ = true;
  started_unix_ms_ = std::chrono::duration_cast<std::chrono::milliseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
}

bool FlightRig::running() const {
  if (runner_) return !started_ || runner_->running();
  return !flight_.mode->finished();
}

void FlightRig::stop() {
  if (runner_) runner_->stop();
}

FlightRig::Closed FlightRig::close(bool interrupted) {
  Closed c;
  if (closed_) return c;
  closed_ = true;
  stop();
  if (publisher_) {
    publisher_->stop();
    c.published = true;
    c.published_steps = publisher_->published();
    c.publish_dropped = publisher_->dropped();
  }
  if (instructor_) {
    instructor_->set_state(net::StationState::ended);
    instructor_->stop();
    c.station = instructor_->options().station.name;
    c.command_security = instructor_->options().security;
    c.instructor = instructor_->stats();
  }
  if (flight_.vehicle) flight_.vehicle->finish();
  if (!record_path_.empty()) {
    if (recorder_.close(c.error, interrupted)) {
      c.recorded = record_path_;
      c.dropped = recorder_.dropped();
      completed_recording_ = true;
    }
  }
  const bool flown = started_ && !flight_.recording && flight_.mode->steps_done() > 0;
  // A lesson step's verdict (SPEC §10): the step's criteria against the score.
  if (lesson_step_ && flown && flight_.lesson.active()) {
    const Metrics m = metrics();
    const auto field = [&m](const char* name) {
      for (const auto& [k, v] : m)
        if (k == name) return v;
      return 0.0;
    };
    LessonScore score;
    score.skill = field("skill");
    score.time_in_ball = field("time_in_ball");
    score.collisions = field("collisions");
    score.completed = !interrupted && !flight_.mode->lost();
    c.verdict = judge(*lesson_step_, score);
    history::LessonAttempt a;
    a.lesson = flight_.lesson.lesson;
    a.lesson_hash = flight_.lesson.lesson_hash;
    a.steps = flight_.lesson.steps;
    a.step = flight_.lesson.step;
    a.step_title = flight_.lesson.title;
    a.ceiling = lesson_step_->flown_ceiling();
    a.passed = c.verdict->passed;
    a.failed_criterion = c.verdict->failed;
    if (a.passed) {
      for (const CriterionResult& r : c.verdict->results)
        a.detail += (a.detail.empty() ? "" : "; ") + r.text;
    } else {
      a.detail = c.verdict->detail;
    }
    c.attempt = std::move(a);
  }
  // The history's row, after the recording is complete (its hash is the finished file's, taken
  // on the writer's thread). A failure is said by the front end from the writer's outcome; the
  // flight and its recording stand.
  if (history_ && flown) {
    std::string error;
    if (std::optional<history::FlightRecord> row = flight_record(interrupted, error, false)) {
      history_->remember(std::move(*row), completed_recording_ ? record_path_ : std::string(),
                         c.attempt);
      c.remembering = true;
    }
  }
  return c;
}

std::optional<history::FlightRecord> FlightRig::flight_record(bool interrupted,
                                                              std::string& error,
                                                              bool hash) const {
  const Mode& mode = *flight_.mode;
  history::FlightRecord r;
  const auto meta = [this](const char* key) {
    if (!flight_.recording) return std::string();
    const auto it = flight_.recording->metadata.find(key);
    return it == flight_.recording->metadata.end() ? std::string() : it->second;
  };
  r.trainee = flight_.recording ? meta("trainee") : trainee_;
  if (r.trainee.empty()) r.trainee = history::login_name();
  if (r.trainee.empty()) r.trainee = "unnamed";  // an account without a name
  r.station = history::host_name();
  r.scenario = mode.scenario_name();
  r.scenario_hash = sha256_hex(flight_.scenario_text);
  r.mode = to_string(mode.kind());
  r.pilot = flight_.recording ? meta("pilot") : flight_.pilot;
  if (!flight_.recording && is_device_pilot(options_.pilot)) {
    r.input_device = options_.pilot;
    if (flight_.devices) r.input_settings_hash = sha256_hex(input::to_toml(flight_.devices->settings));
  }
  // A branch (fly from here): its parent flight, by that flight's recording hash, and the step
  // it was taken over at; a branch's replay (history import) as its recording names them.
  std::optional<ParentLink> parent;
  std::string malformed;  // a replay of a malformed link was refused before
  if (flight_.from)
    parent = ParentLink{flight_.from->parent, flight_.from->parent_sha256, flight_.from->step};
  else if (flight_.recording && !parent_link(*flight_.recording, "", parent, malformed))
    parent.reset();
  if (parent) {
    r.parent_recording_hash = parent->sha256;
    r.parent_step = parent->step;
  }
  r.started_unix_ms = started_unix_ms_;
  // The time flown: a branch's from its take-over on.
  r.duration_s = double(mode.steps_done() - (parent ? parent->step : 0)) * mode.dt();
  r.ended = mode.lost()                         ? history::Ended::lost
            : session_->ended_by_instructor() ? history::Ended::instructor
            : interrupted                     ? history::Ended::interrupted
                                              : history::Ended::completed;
  const bool remote = flight_.recording ? meta("vehicle") == "dds" : flight_.vehicle != nullptr;
  r.front_end = remote ? "vehicle" : front_end_;
  r.app_version = version();
  r.probe = mode.identity().probe;  // an unassisted probe (SPEC §10)
  if (completed_recording_) {
    std::error_code ec;
    const std::filesystem::path abs = std::filesystem::absolute(record_path_, ec);
    r.recording_path = ec ? record_path_ : abs.lexically_normal().string();
    if (hash) {
      const auto h = sha256_file(record_path_, error);
      if (!h) return std::nullopt;
      r.recording_hash = *h;
    }
  }
  r.metrics = metrics();
  return r;
}

Metrics FlightRig::metrics() const {
  const Mode& mode = *flight_.mode;
  return flight_.recording ? replay_metrics(mode, *flight_.recording)
                           : with_lost_fields(mode.metrics(), mode);
}

std::string FlightRig::replay_difference() const {
  if (!check_) return {};
  // A branch's replay: its parent's part first (core/recording/branch_replay.hpp).
  if (std::string d = parent_difference(*flight_.mode); !d.empty()) return d;
  return check_->first_difference(flight_.mode->steps_done());
}

std::string FlightRig::replay_difference_so_far() const {
  if (!check_) return {};
  if (std::string d = parent_difference(*flight_.mode); !d.empty()) return d;
  return check_->difference_so_far();
}

namespace {

const char* obeys(net::CommandSecurity s) {
  switch (s) {
    case net::CommandSecurity::no_instructor: return "refused (it obeys no instructor: --instructor)";
    case net::CommandSecurity::dds_security: return "obeyed from a certified instructor (DDS Security)";
    case net::CommandSecurity::unauthenticated_loopback:
      return "obeyed unauthenticated (--allow-unauthenticated-commands, loopback only)";
    case net::CommandSecurity::unauthenticated_refused:
      return "refused: no DDS Security configured (--dds-security FOLDER)";
  }
  return "?";
}

}  // namespace

std::string station_started(const net::InstructorLink& link) {
  const auto& o = link.options();
  return "station " + o.station.name + " announced on " + net::kStationTopic + " (domain " +
         std::to_string(o.domain) + "); instructor commands " + obeys(o.security);
}

std::string station_summary(const FlightRig::Closed& c) {
  if (c.station.empty()) return {};
  const net::InstructorLinkStats& s = c.instructor;
  std::string out = "  station " + c.station + ": instructor commands " +
                    obeys(c.command_security) + "; " + std::to_string(s.accepted) +
                    " accepted, " + std::to_string(s.refused_total()) + " refused";
  std::string reasons;
  for (int r = 1; r < net::kCommandRefusals; ++r)
    if (const std::uint64_t n = s.refused[std::size_t(r)]; n > 0)
      reasons += (reasons.empty() ? "" : ", ") + std::to_string(n) + " " +
                 net::to_string(net::CommandRefusal(r));
  if (!reasons.empty()) out += " (" + reasons + ")";
  out += "\n";
  if (!s.last_refusal.empty()) out += "    the newest refused: " + s.last_refusal + "\n";
  if (s.security_refused > 0)
    out += "    DDS Security refused peers " + std::to_string(s.security_refused) +
           " times; the newest: " + s.security_last + "\n";
  return out;
}

}  // namespace mixpilot::cli
