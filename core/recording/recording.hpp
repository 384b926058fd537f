#pragma once
// Session recordings: MCAP files (core/recording/mcap.hpp) with the ros2 profile, CDR-encoded messages
// (core/recording/cdr.hpp) and ros2msg schemas, so ROS 2 tools and Foxglove read them as they are.
// Topics, types and metadata keys are listed in docs/recording-format.md.
//
// Time: every message of control step k is logged at k·Δt (Δt = control period, integer ns),
// and its stamp (when the type has one) is that same time. A session therefore replays
// bit-identically from its recording.
#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/control/ph_index.hpp"  // AuthorityBounds
#include "core/recording/cdr.hpp"
#include "core/recording/mcap.hpp"

namespace mixpilot {

// builtin_interfaces/Time.
struct RosTime {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  bool operator==(const RosTime&) const = default;
};
RosTime ros_time_from_ns(uint64_t ns);
uint64_t ros_time_to_ns(const RosTime& t);  // negative sec saturates to 0

// sensor_msgs/msg/Joy on /joy: the raw gamepad (header.stamp, header.frame_id).
struct JoyMsg {
  RosTime stamp;
  std::string frame_id;
  std::vector<float> axes;      // [-1, 1]
  std::vector<int32_t> buttons;  // 0 / 1
  bool operator==(const JoyMsg&) const = default;
};

// mixpilot_msgs/msg/PilotCommand on /pilot/command: the human reference ν^r = (φ_h, θ_h, Ω_h)
// of SPEC §5.4 and where it came from.
struct PilotCommandMsg {
  RosTime stamp;
  uint64_t step = 0;
  double roll = 0.0;                     // φ_h [rad]
  double pitch = 0.0;                    // θ_h [rad]
  std::array<double, 4> rotor_speed{};   // Ω_h [kHz, the model's scaled unit]
  std::string source;  // "novice", "experienced", "reckless", "gamepad", "replay:<file>", ...
  double authority = 1.0;     // the source's cap on λ (PilotCommand::authority)
  uint8_t input_state = 0;    // InputState: 0 ok, 1 lost, 2 re-centre, 3 returning
  bool operator==(const PilotCommandMsg&) const = default;
};

// mixpilot_msgs/msg/VehicleState on /vehicle/state: the MikroKopter state of SPEC §3.3,
// x = (p, φ θ ψ, v_b, ω, Ω) ∈ R¹⁶.
struct VehicleStateMsg {
  RosTime stamp;
  uint64_t step = 0;
  std::vector<double> x;
  bool operator==(const VehicleStateMsg&) const = default;
};

// mixpilot_msgs/msg/AppliedCommand on /controller/applied: what the pilot's command became.
struct AppliedCommandMsg {
  RosTime stamp;
  uint64_t step = 0;
  std::vector<double> u;                // rotor torques τ [N·m] applied to the vehicle
  double roll = 0.0;                    // MPC stage-1 φ [rad]
  double pitch = 0.0;                   // MPC stage-1 θ [rad]
  std::array<double, 4> rotor_speed{};  // MPC stage-1 Ω
  bool operator==(const AppliedCommandMsg&) const = default;
};

// mixpilot_msgs/msg/SolverStats on /controller/solver.
struct SolverStatsMsg {
  RosTime stamp;
  uint64_t step = 0;
  uint8_t status = 0;
  uint32_t qp_iterations = 0;
  double integration_us = 0.0, linearization_us = 0.0, qp_us = 0.0, total_us = 0.0;
  bool fallback = false;
  bool operator==(const SolverStatsMsg&) const = default;
};

// mixpilot_msgs/msg/Prediction on /controller/prediction: 3·(N+1) values each, stage-major
// (x0 y0 z0 x1 y1 z1 ...).
struct PredictionMsg {
  RosTime stamp;
  uint64_t step = 0;
  std::vector<double> position;   // predicted positions η_{i|k}
  std::vector<double> reference;  // planner reference η^r_{i|k}
  bool operator==(const PredictionMsg&) const = default;
};

// std_msgs/msg/Float64 on /controller/lambda (no stamp in the type: the step is the log time).
struct LambdaSample {
  uint64_t step = 0;
  double lambda = 0.0;
  bool operator==(const LambdaSample&) const = default;
};

// mixpilot_msgs/msg/ModeChannels on /mode/channels: a mode's named scalars of one step and its
// events (core/modes/mode.hpp), for plots of any mode.
struct ModeChannelsMsg {
  RosTime stamp;
  uint64_t step = 0;
  uint32_t events = 0;  // ModeEvent bit flags
  std::vector<std::string> names;
  std::vector<std::string> units;
  std::vector<double> values;
  bool operator==(const ModeChannelsMsg&) const = default;
};

// mixpilot_msgs/msg/LambdaReason on /controller/lambda_reason: what decided the step's λ
// (SPEC §10 "Why λ fell", from §5.4), mixed initiative only.
struct LambdaReasonMsg {
  RosTime stamp;
  uint64_t step = 0;
  double lambda = 0.0;    // λ used in the step (as /controller/lambda)
  double ph_index = 0.0;  // λ of the PH index from d_res, before any cap
  double d_res = 0.0;     // [m] largest deviation of the previous prediction over nodes 0..N_b
  int32_t node = -1;      // i*, where it is reached; −1: no prediction yet (λ initial)
  double ahead = 0.0;     // [s] i*·Δt
  std::array<double, 3> direction{};  // unit η_{i*} − η^r_{i*}, world frame (0 when d_res = 0)
  uint8_t cap = 0;        // LambdaCap: 0 none, 1 input lost, 2 probe, 3 safe hold
  bool operator==(const LambdaReasonMsg&) const = default;
};

// rcl_interfaces/msg/Log on /rosout: the debrief's events (SPEC §10, core/modes/debrief.hpp),
// one message per event, written when it closes, so Foxglove's and Lichtblick's Log panel list
// them. Unlike the other topics, the stamp is the event's start, the log time the step that
// closed it (the message then knows the event's end, its lowest λ and why).
struct LogMsg {
  RosTime stamp;
  uint8_t level = 20;     // DEBUG 10, INFO 20, WARN 30, ERROR 40, FATAL 50
  std::string name;       // the logger: "mixpilot.debrief"
  std::string msg;        // the event in words
  std::string file;       // "": no source file said it, the flight did
  std::string function;   // the event's kind, as to_string(DebriefKind) names it ("takeover")
  uint32_t line = 0;      // 0
  bool operator==(const LogMsg&) const = default;
};
inline constexpr const char* kDebriefLogger = "mixpilot.debrief";

// mixpilot_msgs/msg/InstructorCommand on /instructor/command: an instructor's command (SPEC
// §10, core/modes/instructor.hpp) and the control step it took effect at, so a replay applies
// it at that step again. Every kind has every field; those of other kinds are their defaults.
struct InstructorCommandMsg {
  RosTime stamp;
  uint64_t step = 0;
  uint8_t kind = 0;                // InstructorCommandKind
  double floor = 0.0;              // bounds
  double ceiling = 1.0;
  std::array<double, 3> force{};   // gust [N], world frame
  double duration = 0.0;           // [s] gust, input loss
  double delay = 0.0;              // [s] extra delay
  std::string text;                // marker
  bool operator==(const InstructorCommandMsg&) const = default;
};

// ---- encoding ---------------------------------------------------------------------------

// The ros2msg schema (top-level definition followed by its dependencies) and schema name of
// each type, and the topic it is recorded on.
struct RecordedType {
  const char* topic;
  const char* schema_name;  // e.g. "mixpilot_msgs/msg/PilotCommand"
  const char* schema_text;  // ros2msg
};
std::span<const RecordedType> recorded_types();

// CDR encode (appended to `out`; call out.reset() first for a new message) and decode.
// Decoders return false and set `error` ("CDR: ... at byte N of the message") on malformed
// data, including trailing bytes beyond CDR's final alignment padding.
void encode(const JoyMsg& m, CdrWriter& out);
void encode(const PilotCommandMsg& m, CdrWriter& out);
void encode(const VehicleStateMsg& m, CdrWriter& out);
void encode(const AppliedCommandMsg& m, CdrWriter& out);
void encode(const SolverStatsMsg& m, CdrWriter& out);
void encode(const PredictionMsg& m, CdrWriter& out);
void encode(const ModeChannelsMsg& m, CdrWriter& out);
void encode(const LambdaReasonMsg& m, CdrWriter& out);
void encode(const LogMsg& m, CdrWriter& out);
void encode(const InstructorCommandMsg& m, CdrWriter& out);
void encode_float64(double v, CdrWriter& out);
bool decode(std::span<const uint8_t> data, JoyMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, PilotCommandMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, VehicleStateMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, AppliedCommandMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, SolverStatsMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, PredictionMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, ModeChannelsMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, LambdaReasonMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, LogMsg& m, std::string& error);
bool decode(std::span<const uint8_t> data, InstructorCommandMsg& m, std::string& error);
bool decode_float64(std::span<const uint8_t> data, double& v, std::string& error);

// ---- recording --------------------------------------------------------------------------

// What the "mixpilot" Metadata record holds besides version and control_period_ns.
struct SessionInfo {
  std::string mode;           // "mixed_initiative", "pendubot_swingup", ...
  std::string scenario;       // full scenario file text
  std::string scenario_path;
  uint64_t seed = 0;
  std::string pilot;          // pilot source, as in PilotCommandMsg::source (mixed initiative)
  std::string trainee = {};   // the person flying, as typed in the app ("" unknown)
  std::string vehicle = {};   // "dds": a remote vehicle flew (fly --vehicle dds); "": simulated
  std::int64_t planned_steps = 0;  // the flight's planned length (its mode's steps_total)
  // Mixed initiative: "on" (the planner assists), or "off" for a probe flight (SPEC §10), which
  // a replay flies again as one; "" (other modes): no key is written. A recording without the
  // key was assisted.
  std::string assist = {};
  // Mixed initiative: the instructor's (or a lesson's) bounds on λ at the first step (SPEC
  // §10); written as authority_floor / authority_ceiling where not [0, 1], and a replay flies
  // with them. RecordingSink::open() takes them from the mode.
  AuthorityBounds bounds = {};
  // Fly from here (SPEC §10): a branch names its parent recording (its absolute path and
  // SHA-256) and the parent's step k it was taken over at, its own first step. "" / −1: none.
  std::string parent_recording = {};
  std::string parent_sha256 = {};
  std::int64_t parent_step = -1;
  // A lesson step's flight (SPEC §10): the lesson's name and file hash, the step's number
  // (1-based, as the trainee sees it) of how many, and its title; written as lesson,
  // lesson_hash, lesson_step, lesson_steps and lesson_step_title. "" / 0: not a lesson's.
  std::string lesson = {};
  std::string lesson_hash = {};
  int lesson_step = 0;
  int lesson_steps = 0;
  std::string lesson_step_title = {};
};

// How a recording ended: its closing "mixpilot_end" Metadata record, written by
// SessionRecorder::close() and by recover_recording(). A recording without one was cut short,
// or written before the record existed.
struct RecordingEnd {
  bool interrupted = false;    // the flight stopped before its scheduled end (a signal, a crash)
  bool recovered = false;      // rebuilt by recover_recording() from a cut-short file
  uint64_t steps = 0;          // control steps recorded (messages on /vehicle/state)
  uint64_t dropped_steps = 0;  // steps flown but not recorded (a full ring in real time)
  bool operator==(const RecordingEnd&) const = default;
};
inline constexpr const char* kEndMetadataName = "mixpilot_end";
McapStringMap to_metadata(const RecordingEnd& end);

// Writes one session. Each record_* call appends one message at log time step·Δt and fills
// the message's stamp with that time; steps must not decrease across calls (MCAP log-time
// order). Calls after a failure do nothing; close() reports the first failure.
class SessionRecorder {
 public:
  SessionRecorder() = default;
  SessionRecorder(const SessionRecorder&) = delete;
  SessionRecorder& operator=(const SessionRecorder&) = delete;

  // Opens the output (McapWriter::open: a temporary beside `path`; an existing file at `path`
  // only with `overwrite`), writes the schemas, channels and the "mixpilot" Metadata record.
  // control_period_ns > 0 is Δt in nanoseconds.
  bool open(const std::string& path, uint64_t control_period_ns, const SessionInfo& info,
            std::string& error, bool overwrite = false);

  bool record_joy(uint64_t step, const JoyMsg& m);
  bool record_pilot(const PilotCommandMsg& m);
  bool record_state(const VehicleStateMsg& m);
  bool record_lambda(uint64_t step, double lambda);
  bool record_applied(const AppliedCommandMsg& m);
  bool record_solver(const SolverStatsMsg& m);
  bool record_prediction(const PredictionMsg& m);
  bool record_channels(const ModeChannelsMsg& m);
  bool record_reason(const LambdaReasonMsg& m);
  // At log time step·Δt with the stamp the message has (an event's start, before that step).
  bool record_log(uint64_t step, const LogMsg& m);
  bool record_command(const InstructorCommandMsg& m);

  bool flush() { return writer_.flush(); }
  // Writes the "mixpilot_end" Metadata record (steps = the /vehicle/state messages recorded),
  // completes the file and moves it to its path.
  bool close(std::string& error, bool interrupted = false, uint64_t dropped_steps = 0);

  uint64_t log_time_ns(uint64_t step) const { return step * period_ns_; }
  const McapWriter& writer() const { return writer_; }

 private:
  enum Topic {
    kJoy, kPilot, kState, kLambda, kApplied, kSolver, kPrediction, kChannels, kReason, kLog,
    kCommand, kTopicCount
  };
  template <class Msg>
  bool put(Topic t, uint64_t step, const Msg& m);
  bool put_encoded(Topic t, uint64_t step);

  McapWriter writer_;
  CdrWriter cdr_;
  uint64_t period_ns_ = 0;
  std::array<uint16_t, kTopicCount> channel_{};
  std::array<uint32_t, kTopicCount> sequence_{};
};

struct RecordingContents {
  std::string library;                          // the writer ("mixpilot 0.1.0")
  std::map<std::string, std::string> metadata;  // the "mixpilot" Metadata record
  uint64_t control_period_ns = 0;               // from metadata (0 if absent)
  std::map<std::string, uint64_t> message_counts;  // per topic, every channel listed
  std::vector<JoyMsg> joy;
  std::vector<PilotCommandMsg> pilot;  // in log-time order
  std::vector<VehicleStateMsg> states;
  std::vector<LambdaSample> lambda;
  std::vector<AppliedCommandMsg> applied;
  std::vector<SolverStatsMsg> solver;
  std::vector<PredictionMsg> predictions;
  std::vector<ModeChannelsMsg> channels;
  std::vector<LambdaReasonMsg> reasons;  // empty in recordings older than the topic
  std::vector<LogMsg> log;  // /rosout: the debrief's events (none in recordings older than it)
  // /instructor/command, in log-time order (none in recordings older than the topic).
  std::vector<InstructorCommandMsg> commands;
  bool complete = true;  // false: read from a cut-short temporary (allow_truncated)
  // The "mixpilot_end" record: absent when the file was cut short (or is older than it).
  std::optional<RecordingEnd> end;
};

// Reads a recording: validates the MCAP file (core/recording/mcap.hpp), checks that every known topic
// uses its expected schema name, ros2msg and cdr, decodes all messages and the "mixpilot_end"
// record (its step count must match the recorded states). Topics it does not know are counted,
// not decoded. Errors: "<path>: <what> at byte <offset> (...)".
std::optional<RecordingContents> read_recording(const std::string& path, std::string& error,
                                                const McapReadOptions& options = {});
std::optional<RecordingContents> decode_recording(const McapFile& file, std::string_view name,
                                                  std::string& error);

}  // namespace mixpilot
