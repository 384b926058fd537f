#include "core/recording/recording.hpp"

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <iterator>
#include <limits>
#include <utility>

#include "core/base/input_file.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot {

RosTime ros_time_from_ns(uint64_t ns) {
  const uint64_t sec = ns / 1'000'000'000u;
  return {static_cast<int32_t>(std::min<uint64_t>(sec, std::numeric_limits<int32_t>::max())),
          static_cast<uint32_t>(ns % 1'000'000'000u)};
}

uint64_t ros_time_to_ns(const RosTime& t) {
  if (t.sec < 0) return 0;
  return static_cast<uint64_t>(t.sec) * 1'000'000'000u + t.nanosec;
}

namespace {
// The shortest text that reads back as exactly v.
std::string exact_text(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
}  // namespace

// ---- schemas ----------------------------------------------------------------------------
// ros2msg text as rosbag2 stores it: the top-level definition, then each dependency after a
// line of 80 '=' and "MSG: pkg/Type" (MCAP well-known schema encoding "ros2msg").

namespace {
#define MIXPILOT_SEP "================================================================================\n"
#define MIXPILOT_TIME_DEP                                                          \
  MIXPILOT_SEP                                                                     \
  "MSG: builtin_interfaces/Time\n"                                                 \
  "# Time since an epoch; here the session clock (step * control period).\n"       \
  "int32 sec\n"                                                                    \
  "uint32 nanosec\n"

constexpr const char kJoySchema[] =
    "# Raw gamepad state, as read before any mapping to pilot commands.\n"
    "std_msgs/Header header\n"
    "float32[] axes\n"
    "int32[] buttons\n"
    "\n" MIXPILOT_SEP
    "MSG: std_msgs/Header\n"
    "builtin_interfaces/Time stamp\n"
    "string frame_id\n"
    "\n" MIXPILOT_TIME_DEP;

constexpr const char kPilotCommandSchema[] =
    "# The human reference nu^r = (phi_h, theta_h, Omega_h) of one control step.\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "float64 roll            # phi_h [rad]\n"
    "float64 pitch           # theta_h [rad]\n"
    "float64[4] rotor_speed  # Omega_h [kHz, scaled unit]\n"
    "string source           # novice, experienced, reckless, gamepad, replay:<file>, ...\n"
    "float64 authority       # the source's cap on lambda: 1, 0 while the input is lost\n"
    "uint8 input_state       # 0 ok, 1 lost, 2 waiting for re-centred sticks, 3 returning\n"
    "\n" MIXPILOT_TIME_DEP;

constexpr const char kVehicleStateSchema[] =
    "# MikroKopter state x = (p, phi theta psi, v_b, omega, Omega), 16 values.\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "float64[] x\n"
    "\n" MIXPILOT_TIME_DEP;

constexpr const char kFloat64Schema[] = "float64 data\n";

constexpr const char kAppliedCommandSchema[] =
    "# What the pilot's command became: applied torques and the MPC's stage-1 inputs.\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "float64[] u             # rotor torques tau [N m]\n"
    "float64 roll            # stage-1 phi [rad]\n"
    "float64 pitch           # stage-1 theta [rad]\n"
    "float64[4] rotor_speed  # stage-1 Omega\n"
    "\n" MIXPILOT_TIME_DEP;

constexpr const char kSolverStatsSchema[] =
    "# One real-time iteration of the NMPC.\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "uint8 status\n"
    "uint32 qp_iterations\n"
    "float64 integration_us\n"
    "float64 linearization_us\n"
    "float64 qp_us\n"
    "float64 total_us\n"
    "bool fallback\n"
    "\n" MIXPILOT_TIME_DEP;

constexpr const char kPredictionSchema[] =
    "# Predicted and reference positions over the horizon, 3*(N+1) values each (x y z per stage).\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "float64[] position\n"
    "float64[] reference\n"
    "\n" MIXPILOT_TIME_DEP;
constexpr const char kModeChannelsSchema[] =
    "# A mode's named scalars of one control step, and what happened in it.\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "uint32 events      # bits: 1 fallback, 2 collision, 4 violation, 8 controller switch, 16 lost,\n"
    "                  #   32 overrun (the solve overran its deadline in a real-time run)\n"
    "string[] names\n"
    "string[] units\n"
    "float64[] values\n"
    "\n" MIXPILOT_TIME_DEP;
constexpr const char kLambdaReasonSchema[] =
    "# What decided the authority lambda of one control step (the PH index, or a cap).\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "float64 lambda          # lambda used in the step\n"
    "float64 ph_index        # lambda of the PH index from d_res, before any cap\n"
    "float64 d_res           # [m] max over nodes 0..N_b of |eta - eta_r|, previous prediction\n"
    "int32 node              # i*, the node of that maximum; -1: no prediction yet\n"
    "float64 ahead           # [s] i* * dt\n"
    "float64[3] direction    # unit (eta - eta_r) at node i*, world frame; 0 when d_res = 0\n"
    "uint8 cap               # 0 none, 1 input lost, 2 probe, 3 safe hold,\n"
    "                        # 4 instructor ceiling, 5 instructor floor\n"
    "\n" MIXPILOT_TIME_DEP;
// ROS 2's own rcl_interfaces/msg/Log (github.com/ros2/rcl_interfaces), as rosbag2 stores
// /rosout, so log panels recognise it.
constexpr const char kLogSchema[] =
    "##\n"
    "## Severity level constants\n"
    "##\n"
    "## These logging levels follow the Python Standard\n"
    "## https://docs.python.org/3/library/logging.html#logging-levels\n"
    "## And are implemented in rcutils as well\n"
    "## https://github.com/ros2/rcutils/blob/35f29850064e0c33a4063cbc947ebbfeada11dba/include/rcutils/logging.h#L164-L172\n"
    "## This leaves space for other standard logging levels to be inserted in the middle in the future,\n"
    "## as well as custom user defined levels.\n"
    "## Since there are several other logging enumeration standard for different implementations,\n"
    "## other logging implementations may need to provide level mappings to match their internal implementations.\n"
    "##\n"
    "\n"
    "# Debug is for pedantic information, which is useful when debugging issues.\n"
    "uint8 DEBUG=10\n"
    "\n"
    "# Info is the standard informational level and is used to report expected\n"
    "# information.\n"
    "uint8 INFO=20\n"
    "\n"
    "# Warning is for information that may potentially cause issues or possibly unexpected\n"
    "# behavior.\n"
    "uint8 WARN=30\n"
    "\n"
    "# Error is for information that this node cannot resolve.\n"
    "uint8 ERROR=40\n"
    "\n"
    "# Information about a impending node shutdown.\n"
    "uint8 FATAL=50\n"
    "\n"
    "##\n"
    "## Fields\n"
    "##\n"
    "\n"
    "# Timestamp when this message was generated by the node.\n"
    "builtin_interfaces/Time stamp\n"
    "\n"
    "# Corresponding log level, see above definitions.\n"
    "uint8 level\n"
    "\n"
    "# The name representing the logger this message came from.\n"
    "string name\n"
    "\n"
    "# The full log message.\n"
    "string msg\n"
    "\n"
    "# The file the message came from.\n"
    "string file\n"
    "\n"
    "# The function the message came from.\n"
    "string function\n"
    "\n"
    "# The line in the file the message came from.\n"
    "uint32 line\n"
    "\n" MIXPILOT_SEP
    "MSG: builtin_interfaces/Time\n"
    "int32 sec\n"
    "uint32 nanosec\n";
constexpr const char kInstructorCommandSchema[] =
    "# An instructor's command and the control step it took effect at (replays apply it there).\n"
    "builtin_interfaces/Time stamp\n"
    "uint64 step\n"
    "uint8 kind              # 0 bounds, 1 gust, 2 extra delay, 3 input loss, 4 marker, 5 pause,\n"
    "                        # 6 resume, 7 end\n"
    "float64 floor           # bounds: lambda never below it, 0 <= floor <= ceiling\n"
    "float64 ceiling         # bounds: lambda never above it, ceiling <= 1\n"
    "float64[3] force        # gust [N], world frame (x north, y west, z up), |force| <= 20\n"
    "float64 duration        # [s] gust, input loss: 0 < duration <= 10\n"
    "float64 delay           # [s] extra delay, 0 <= delay <= 0.5 (0 removes it)\n"
    "string text             # marker\n"
    "\n" MIXPILOT_TIME_DEP;
#undef MIXPILOT_TIME_DEP
#undef MIXPILOT_SEP

// Order = SessionRecorder::Topic.
constexpr RecordedType kTypes[] = {
    {"/joy", "sensor_msgs/msg/Joy", kJoySchema},
    {"/pilot/command", "mixpilot_msgs/msg/PilotCommand", kPilotCommandSchema},
    {"/vehicle/state", "mixpilot_msgs/msg/VehicleState", kVehicleStateSchema},
    {"/controller/lambda", "std_msgs/msg/Float64", kFloat64Schema},
    {"/controller/applied", "mixpilot_msgs/msg/AppliedCommand", kAppliedCommandSchema},
    {"/controller/solver", "mixpilot_msgs/msg/SolverStats", kSolverStatsSchema},
    {"/controller/prediction", "mixpilot_msgs/msg/Prediction", kPredictionSchema},
    {"/mode/channels", "mixpilot_msgs/msg/ModeChannels", kModeChannelsSchema},
    {"/controller/lambda_reason", "mixpilot_msgs/msg/LambdaReason", kLambdaReasonSchema},
    {"/rosout", "rcl_interfaces/msg/Log", kLogSchema},
    {"/instructor/command", "mixpilot_msgs/msg/InstructorCommand", kInstructorCommandSchema},
};

// rosbag2's serialization of one QoS profile (reliable, volatile, default durations): the ros2
// MCAP profile requires the offered_qos_profiles channel metadata key, and `ros2 bag play`
// parses it as YAML.
constexpr const char kQosProfiles[] =
    "- history: 3\n"
    "  depth: 0\n"
    "  reliability: 1\n"
    "  durability: 2\n"
    "  deadline:\n"
    "    sec: 2147483647\n"
    "    nsec: 4294967295\n"
    "  lifespan:\n"
    "    sec: 2147483647\n"
    "    nsec: 4294967295\n"
    "  liveliness: 1\n"
    "  liveliness_lease_duration:\n"
    "    sec: 2147483647\n"
    "    nsec: 4294967295\n"
    "  avoid_ros_namespace_conventions: false";
}  // namespace

std::span<const RecordedType> recorded_types() { return kTypes; }

// ---- CDR encode/decode --------------------------------------------------------------------

// The encoders with the stamp given separately: the recorder stamps messages without copying
// them (no allocation per recorded message once the buffers have grown).
void encode_body(const JoyMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const PilotCommandMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const VehicleStateMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const AppliedCommandMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const SolverStatsMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const PredictionMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const ModeChannelsMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const LambdaReasonMsg& m, const RosTime& stamp, CdrWriter& w);
void encode_body(const InstructorCommandMsg& m, const RosTime& stamp, CdrWriter& w);

namespace {
void put_time(const RosTime& t, CdrWriter& w) {
  w.write(t.sec);
  w.write(t.nanosec);
}
bool get_time(CdrReader& r, RosTime& t) { return r.read(t.sec) && r.read(t.nanosec); }

template <class T, std::size_t N>
void put_array(const std::array<T, N>& a, CdrWriter& w) {
  w.write_array(std::span<const T>(a));
}
template <class T, std::size_t N>
bool get_array(CdrReader& r, std::array<T, N>& a) {
  return r.read_array(std::span<T>(a));
}

// Ends a decode: the reader must have succeeded and consumed everything except possibly
// zero padding to an 8-byte boundary, which some CDR writers append.
bool finish(CdrReader& r, std::string& error) {
  if (r.ok() && r.remaining() > 0) {
    // Reading zero padding through the reader keeps the error wording in one place.
    const std::size_t at = r.position();
    bool zero = r.remaining() < 8;
    std::vector<uint8_t> rest(r.remaining());
    if (!r.read_array(std::span<uint8_t>(rest))) zero = false;
    for (uint8_t b : rest) zero = zero && b == 0;
    if (!zero) {
      error = "CDR: " + std::to_string(rest.size()) + " unexpected bytes after the message at byte " +
              std::to_string(at) + " of the message";
      return false;
    }
  }
  if (!r.ok()) {
    error = r.error();
    return false;
  }
  return true;
}
}  // namespace

void encode(const JoyMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const JoyMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write_string(m.frame_id);
  w.write_sequence(std::span<const float>(m.axes));
  w.write_sequence(std::span<const int32_t>(m.buttons));
}
bool decode(std::span<const uint8_t> d, JoyMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read_string(m.frame_id) && r.read_sequence(m.axes) &&
      r.read_sequence(m.buttons));
  return finish(r, error);
}

void encode(const PilotCommandMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const PilotCommandMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write(m.roll);
  w.write(m.pitch);
  put_array(m.rotor_speed, w);
  w.write_string(m.source);
  w.write(m.authority);
  w.write(m.input_state);
}
bool decode(std::span<const uint8_t> d, PilotCommandMsg& m, std::string& error) {
  CdrReader r(d);
  m.authority = 1.0;  // recordings made before the fields existed end after `source`
  m.input_state = 0;
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read(m.roll) && r.read(m.pitch) &&
      get_array(r, m.rotor_speed) && r.read_string(m.source) &&
      (r.remaining() < 8 || (r.read(m.authority) && r.read(m.input_state))));
  return finish(r, error);
}

void encode(const VehicleStateMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const VehicleStateMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write_sequence(std::span<const double>(m.x));
}
bool decode(std::span<const uint8_t> d, VehicleStateMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read_sequence(m.x));
  return finish(r, error);
}

void encode(const AppliedCommandMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const AppliedCommandMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write_sequence(std::span<const double>(m.u));
  w.write(m.roll);
  w.write(m.pitch);
  put_array(m.rotor_speed, w);
}
bool decode(std::span<const uint8_t> d, AppliedCommandMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read_sequence(m.u) && r.read(m.roll) &&
      r.read(m.pitch) && get_array(r, m.rotor_speed));
  return finish(r, error);
}

void encode(const SolverStatsMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const SolverStatsMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write(m.status);
  w.write(m.qp_iterations);
  w.write(m.integration_us);
  w.write(m.linearization_us);
  w.write(m.qp_us);
  w.write(m.total_us);
  w.write(m.fallback);
}
bool decode(std::span<const uint8_t> d, SolverStatsMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read(m.status) && r.read(m.qp_iterations) &&
      r.read(m.integration_us) && r.read(m.linearization_us) && r.read(m.qp_us) &&
      r.read(m.total_us) && r.read(m.fallback));
  return finish(r, error);
}

void encode(const PredictionMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const PredictionMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write_sequence(std::span<const double>(m.position));
  w.write_sequence(std::span<const double>(m.reference));
}
bool decode(std::span<const uint8_t> d, PredictionMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read_sequence(m.position) &&
      r.read_sequence(m.reference));
  return finish(r, error);
}

void encode(const ModeChannelsMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const ModeChannelsMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write(m.events);
  w.write_strings(m.names);
  w.write_strings(m.units);
  w.write_sequence(std::span<const double>(m.values));
}
bool decode(std::span<const uint8_t> d, ModeChannelsMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read(m.events) && r.read_strings(m.names) &&
         r.read_strings(m.units) && r.read_sequence(m.values));
  return finish(r, error);
}

void encode(const LambdaReasonMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const LambdaReasonMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write(m.lambda);
  w.write(m.ph_index);
  w.write(m.d_res);
  w.write(m.node);
  w.write(m.ahead);
  put_array(m.direction, w);
  w.write(m.cap);
}
bool decode(std::span<const uint8_t> d, LambdaReasonMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read(m.lambda) && r.read(m.ph_index) &&
         r.read(m.d_res) && r.read(m.node) && r.read(m.ahead) && get_array(r, m.direction) &&
         r.read(m.cap));
  return finish(r, error);
}

void encode(const LogMsg& m, CdrWriter& w) {
  put_time(m.stamp, w);
  w.write(m.level);
  w.write_string(m.name);
  w.write_string(m.msg);
  w.write_string(m.file);
  w.write_string(m.function);
  w.write(m.line);
}
bool decode(std::span<const uint8_t> d, LogMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.level) && r.read_string(m.name) &&
         r.read_string(m.msg) && r.read_string(m.file) && r.read_string(m.function) &&
         r.read(m.line));
  return finish(r, error);
}

void encode(const InstructorCommandMsg& m, CdrWriter& w) { encode_body(m, m.stamp, w); }
void encode_body(const InstructorCommandMsg& m, const RosTime& stamp, CdrWriter& w) {
  put_time(stamp, w);
  w.write(m.step);
  w.write(m.kind);
  w.write(m.floor);
  w.write(m.ceiling);
  put_array(m.force, w);
  w.write(m.duration);
  w.write(m.delay);
  w.write_string(m.text);
}
bool decode(std::span<const uint8_t> d, InstructorCommandMsg& m, std::string& error) {
  CdrReader r(d);
  (void)(get_time(r, m.stamp) && r.read(m.step) && r.read(m.kind) && r.read(m.floor) &&
         r.read(m.ceiling) && get_array(r, m.force) && r.read(m.duration) && r.read(m.delay) &&
         r.read_string(m.text));
  return finish(r, error);
}

void encode_float64(double v, CdrWriter& w) { w.write(v); }
bool decode_float64(std::span<const uint8_t> d, double& v, std::string& error) {
  CdrReader r(d);
  r.read(v);
  return finish(r, error);
}

// ---- SessionRecorder ----------------------------------------------------------------------

bool SessionRecorder::open(const std::string& path, uint64_t control_period_ns,
                           const SessionInfo& info, std::string& error, bool overwrite) {
  if (control_period_ns == 0) {
    error = path + ": control period must be positive";
    return false;
  }
  period_ns_ = control_period_ns;
  sequence_.fill(0);
  McapWriteOptions options;
  options.overwrite = overwrite;
  if (!writer_.open(path, error, options)) return false;
  for (std::size_t t = 0; t < kTopicCount; ++t) {
    const auto schema = writer_.add_schema(kTypes[t].schema_name, "ros2msg", kTypes[t].schema_text);
    channel_[t] = writer_.add_channel(schema, kTypes[t].topic, "cdr",
                                      {{"offered_qos_profiles", kQosProfiles}});
  }
  // Metadata first, so a crashed session's .tmp still says what it was.
  McapStringMap metadata = {{"mode", info.mode},
                             {"scenario", info.scenario},
                             {"scenario_path", info.scenario_path},
                             {"version", version()},
                             {"seed", std::to_string(info.seed)},
                             {"pilot", info.pilot},
                             {"trainee", info.trainee},
                             {"vehicle", info.vehicle},
                             {"planned_steps", std::to_string(info.planned_steps)},
                             {"control_period_ns", std::to_string(period_ns_)}};
  if (!info.assist.empty()) metadata.emplace("assist", info.assist);
  if (info.bounds != AuthorityBounds{}) {
    metadata.emplace("authority_floor", exact_text(info.bounds.floor));
    metadata.emplace("authority_ceiling", exact_text(info.bounds.ceiling));
  }
  if (!info.lesson.empty()) {
    metadata.emplace("lesson", info.lesson);
    metadata.emplace("lesson_hash", info.lesson_hash);
    metadata.emplace("lesson_step", std::to_string(info.lesson_step));
    metadata.emplace("lesson_steps", std::to_string(info.lesson_steps));
    metadata.emplace("lesson_step_title", info.lesson_step_title);
  }
  if (info.parent_step >= 0) {
    metadata.emplace("parent_recording", info.parent_recording);
    metadata.emplace("parent_sha256", info.parent_sha256);
    metadata.emplace("parent_step", std::to_string(info.parent_step));
  }
  writer_.write_metadata("mixpilot", metadata);
  if (!writer_.error().empty()) {
    error = writer_.error() + "; no file is kept (no step had been recorded)";
    writer_.discard();
    return false;
  }
  return true;
}

bool SessionRecorder::put_encoded(Topic t, uint64_t step) {
  const uint64_t time = log_time_ns(step);
  // publish_time = log_time: the session clock is the only clock (spec: "if not available,
  // must be set to the log time").
  return writer_.write_message(channel_[t], sequence_[t]++, time, time, cdr_.span());
}

template <class Msg>
bool SessionRecorder::put(Topic t, uint64_t step, const Msg& m) {
  cdr_.reset();
  encode_body(m, ros_time_from_ns(log_time_ns(step)), cdr_);
  return put_encoded(t, step);
}

bool SessionRecorder::record_joy(uint64_t step, const JoyMsg& m) { return put(kJoy, step, m); }
bool SessionRecorder::record_pilot(const PilotCommandMsg& m) { return put(kPilot, m.step, m); }
bool SessionRecorder::record_state(const VehicleStateMsg& m) { return put(kState, m.step, m); }
bool SessionRecorder::record_applied(const AppliedCommandMsg& m) {
  return put(kApplied, m.step, m);
}
bool SessionRecorder::record_solver(const SolverStatsMsg& m) { return put(kSolver, m.step, m); }
bool SessionRecorder::record_prediction(const PredictionMsg& m) {
  return put(kPrediction, m.step, m);
}
bool SessionRecorder::record_channels(const ModeChannelsMsg& m) {
  return put(kChannels, m.step, m);
}
bool SessionRecorder::record_reason(const LambdaReasonMsg& m) { return put(kReason, m.step, m); }
bool SessionRecorder::record_log(uint64_t step, const LogMsg& m) {
  cdr_.reset();
  encode(m, cdr_);
  return put_encoded(kLog, step);
}
bool SessionRecorder::record_command(const InstructorCommandMsg& m) {
  return put(kCommand, m.step, m);
}
bool SessionRecorder::record_lambda(uint64_t step, double lambda) {
  cdr_.reset();
  encode_float64(lambda, cdr_);
  return put_encoded(kLambda, step);
}

McapStringMap to_metadata(const RecordingEnd& end) {
  return {{"interrupted", end.interrupted ? "true" : "false"},
          {"recovered", end.recovered ? "true" : "false"},
          {"steps", std::to_string(end.steps)},
          {"dropped_steps", std::to_string(end.dropped_steps)}};
}

bool SessionRecorder::close(std::string& error, bool interrupted, uint64_t dropped_steps) {
  RecordingEnd end;
  end.interrupted = interrupted;
  end.steps = sequence_[kState];
  end.dropped_steps = dropped_steps;
  // Last record of the data section: a reader that finds it knows the flight's end was written.
  writer_.write_metadata(kEndMetadataName, to_metadata(end));
  return writer_.close(error);
}

// ---- reading ------------------------------------------------------------------------------

namespace {

bool parse_flag(const McapStringMap& m, const char* key, bool required, bool& out,
                std::string& what) {
  const auto it = m.find(key);
  if (it == m.end()) {
    if (required) what = std::string("no '") + key + "' key";
    return !required;
  }
  if (it->second != "true" && it->second != "false") {
    what = std::string(key) + " is '" + it->second + "', expected true or false";
    return false;
  }
  out = it->second == "true";
  return true;
}

bool parse_count(const McapStringMap& m, const char* key, bool required, uint64_t& out,
                 std::string& what) {
  const auto it = m.find(key);
  if (it == m.end()) {
    if (required) what = std::string("no '") + key + "' key";
    return !required;
  }
  const std::string& v = it->second;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), out);
  if (v.empty() || ec != std::errc() || end != v.data() + v.size()) {
    what = std::string(key) + " is '" + v + "', expected a decimal count";
    return false;
  }
  return true;
}

// The "mixpilot_end" record's values; false with what is wrong.
bool parse_end(const McapStringMap& m, RecordingEnd& end, std::string& what) {
  return parse_flag(m, "interrupted", true, end.interrupted, what) &&
         parse_flag(m, "recovered", false, end.recovered, what) &&
         parse_count(m, "steps", true, end.steps, what) &&
         parse_count(m, "dropped_steps", false, end.dropped_steps, what);
}

}  // namespace

std::optional<RecordingContents> decode_recording(const McapFile& file, std::string_view name,
                                                  std::string& error) {
  RecordingContents out;
  out.library = file.library;
  out.complete = file.complete;
  auto fail = [&](uint64_t at, const std::string& what) {
    // `what` may quote a topic, a profile or a value from the file.
    error = escape_controls(std::string(name) + ": " + what + " at byte " + std::to_string(at));
    return std::nullopt;
  };
  if (file.profile != "ros2")
    return fail(8, "Header profile is '" + file.profile + "', expected 'ros2'");

  // Channel id -> index into kTypes (or -1: a topic this reader does not know).
  std::map<uint16_t, int> kind;
  for (const auto& [id, ch] : file.channels) {
    out.message_counts[ch.topic] += 0;
    int k = -1;
    for (std::size_t t = 0; t < std::size(kTypes); ++t)
      if (ch.topic == kTypes[t].topic) k = static_cast<int>(t);
    if (k >= 0) {
      const auto s = file.schemas.find(ch.schema_id);
      if (s == file.schemas.end() || s->second.name != kTypes[k].schema_name ||
          s->second.encoding != "ros2msg" || ch.message_encoding != "cdr")
        return fail(ch.record_offset, "channel " + ch.topic + " is not " +
                                          kTypes[k].schema_name + " (ros2msg, cdr)");
    }
    kind[id] = k;
  }
  uint64_t end_at = 0;
  for (const auto& md : file.metadata) {
    if (md.name == "mixpilot") out.metadata = md.metadata;
    if (md.name != kEndMetadataName) continue;
    if (out.end) return fail(md.record_offset, "second mixpilot_end Metadata record");
    std::string what;
    if (!parse_end(md.metadata, out.end.emplace(), what))
      return fail(md.record_offset, "malformed mixpilot_end Metadata record (" + what + ")");
    end_at = md.record_offset;
  }
  if (auto it = out.metadata.find("control_period_ns"); it != out.metadata.end())
    out.control_period_ns = std::strtoull(it->second.c_str(), nullptr, 10);

  std::string why;
  for (const auto& msg : file.messages) {
    const auto& ch = file.channels.at(msg.channel_id);
    ++out.message_counts[ch.topic];
    const auto data = file.data(msg);
    bool ok = true;
    switch (kind.at(msg.channel_id)) {
      case 0: ok = decode(data, out.joy.emplace_back(), why); break;
      case 1: ok = decode(data, out.pilot.emplace_back(), why); break;
      case 2: ok = decode(data, out.states.emplace_back(), why); break;
      case 3: {
        LambdaSample s;
        ok = decode_float64(data, s.lambda, why);
        s.step = out.control_period_ns ? msg.log_time / out.control_period_ns : 0;
        out.lambda.push_back(s);
        break;
      }
      case 4: ok = decode(data, out.applied.emplace_back(), why); break;
      case 5: ok = decode(data, out.solver.emplace_back(), why); break;
      case 6: ok = decode(data, out.predictions.emplace_back(), why); break;
      case 7: ok = decode(data, out.channels.emplace_back(), why); break;
      case 8: ok = decode(data, out.reasons.emplace_back(), why); break;
      case 9: ok = decode(data, out.log.emplace_back(), why); break;
      case 10: ok = decode(data, out.commands.emplace_back(), why); break;
      default: break;
    }
    if (!ok)
      return fail(msg.record_offset, "undecodable " + ch.topic + " message (" + why + ")");
  }
  if (out.end && out.end->steps != out.states.size())
    return fail(end_at, "mixpilot_end Metadata record says " + std::to_string(out.end->steps) +
                            " steps, the recording has " + std::to_string(out.states.size()));
  return out;
}

std::optional<RecordingContents> read_recording(const std::string& path, std::string& error,
                                                const McapReadOptions& options) {
  const auto file = read_mcap(path, error, options);
  if (!file) return std::nullopt;
  return decode_recording(*file, path, error);
}

}  // namespace mixpilot
