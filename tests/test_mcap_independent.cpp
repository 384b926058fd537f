// Independent reader: a recording written by SessionRecorder is read by the reference MCAP
// implementation (npm @mcap/core) and its messages decoded by Foxglove's ros2msg parser and
// CDR deserializer (tests/mcap_check/check.mjs). The JSON that script prints must equal the
// JSON built here from what was written: topics, schema names/encodings, message counts,
// Statistics, metadata names and keys, the data-section CRC, and the last message of every
// topic field by field (which proves the CDR layout and the embedded schemas).
//
// Needs node and tests/mcap_check/node_modules (the CTest fixture mcap_check_npm_ci runs
// `npm ci` there). Without node the test is skipped.
#include <gtest/gtest.h>

#include <charconv>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "core/numerics/version.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "temp_files.hpp"

#ifndef MIXPILOT_NODE
#define MIXPILOT_NODE ""
#endif

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

// Compact JSON as JSON.stringify prints it. Numbers use fixed notation with the shortest
// round-trip digits, which is what JavaScript prints for magnitudes in [1e-7, 1e21).
class Json {
 public:
  Json& raw(std::string_view s) {
    comma();
    out_ += s;
    return *this;
  }
  Json& key(std::string_view k) {
    str(k);
    out_ += ':';
    fresh_ = true;
    return *this;
  }
  Json& str(std::string_view s) {
    comma();
    out_ += '"';
    for (char c : s) {
      if (c == '"' || c == '\\') out_ += '\\';
      if (c == '\n') {
        out_ += "\\n";
        continue;
      }
      out_ += c;
    }
    out_ += '"';
    return *this;
  }
  Json& num(double v) {
    comma();
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed);
    out_.append(buf, r.ptr);
    return *this;
  }
  Json& begin(char c) {
    comma();
    out_ += c;
    fresh_ = true;
    return *this;
  }
  Json& end(char c) {
    out_ += c;
    fresh_ = false;
    return *this;
  }
  template <class T>
  Json& nums(const T& values) {
    begin('[');
    for (double v : values) num(v);
    return end(']');
  }
  Json& strs(const std::vector<std::string>& values) {
    begin('[');
    for (const auto& v : values) str(v);
    return end(']');
  }
  Json& stamp(const RosTime& t) {
    key("stamp").begin('{').key("sec").num(t.sec).key("nanosec").num(t.nanosec);
    return end('}');
  }
  const std::string& text() const { return out_; }

 private:
  void comma() {
    if (!fresh_ && !out_.empty()) out_ += ',';
    fresh_ = false;
  }
  std::string out_;
  bool fresh_ = true;
};

std::string run(const std::string& command) {
  std::string out;
  std::FILE* p = ::popen(command.c_str(), "r");
  if (p == nullptr) return "popen failed";
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  ::pclose(p);
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

constexpr uint64_t kPeriodNs = 15'000'000;
constexpr uint64_t kSteps = 70;  // last step at 1.035 s: the stamp's sec and nanosec both used

TEST(McapIndependentReader, NodeMcapCoreReadsWhatWeWrite) {
  const std::string node = MIXPILOT_NODE;
  if (node.empty()) GTEST_SKIP() << "node not found at configure time";
  const fs::path check_dir = fs::path(MIXPILOT_SOURCE_DIR) / "tests" / "mcap_check";
  ASSERT_TRUE(fs::exists(check_dir / "node_modules" / "@mcap" / "core"))
      << "run `npm ci --prefix tests/mcap_check` (CTest fixture mcap_check_npm_ci)";

  const fs::path file = test::fresh_path("mcap_independent", "session.mcap");

  SessionRecorder rec;
  std::string err;
  ASSERT_TRUE(rec.open(file.string(), kPeriodNs,
                       {"mixed_initiative", "[arena]\nradius = 0.175\n", "scenarios/x.toml", 7,
                        "experienced"},
                       err))
      << err;
  JoyMsg joy;
  PilotCommandMsg pilot;
  VehicleStateMsg state;
  AppliedCommandMsg applied;
  SolverStatsMsg solver;
  PredictionMsg pred;
  ModeChannelsMsg channels;
  LambdaReasonMsg reason;
  LogMsg log;
  InstructorCommandMsg command;
  double lambda = 0;
  for (uint64_t k = 0; k < kSteps; ++k) {
    const double s = static_cast<double>(k);
    joy = {{}, "gamepad0", {0.5f, -0.25f, static_cast<float>(k) * 0.125f, 1.0f}, {1, 0, 0, 1, 3}};
    ASSERT_TRUE(rec.record_joy(k, joy));
    pilot = {{}, k, 0.01 * s, -0.02 * s, {0.0655, 0.0656, 0.0657, 0.0658}, "experienced",
             0.125 * static_cast<double>(k % 9), static_cast<uint8_t>(k % 4)};
    ASSERT_TRUE(rec.record_pilot(pilot));
    state.step = k;
    state.x.assign(16, 0.0);
    for (std::size_t i = 0; i < 16; ++i) state.x[i] = 0.001 * s + static_cast<double>(i);
    ASSERT_TRUE(rec.record_state(state));
    lambda = 1.0 / (1.0 + s);
    ASSERT_TRUE(rec.record_lambda(k, lambda));
    applied = {{}, k, {0.0756, -0.1285, 0.1285, 0.03}, 0.1 * s, -0.1, {0.06, 0.07, 0.08, 0.09}};
    ASSERT_TRUE(rec.record_applied(applied));
    solver = {{}, k, static_cast<uint8_t>(k % 3), static_cast<uint32_t>(k + 5), 12.5, 30.25,
              101.0, 150.75, k % 2 == 1};
    ASSERT_TRUE(rec.record_solver(solver));
    pred = {{}, k, std::vector<double>(33, 0.5 * s), std::vector<double>(30, -0.25)};
    ASSERT_TRUE(rec.record_prediction(pred));
    channels = {{}, k, static_cast<uint32_t>(k % 32), {"lambda", "roll MPC"}, {"", "rad"},
                {lambda, -0.125 * s}};
    ASSERT_TRUE(rec.record_channels(channels));
    reason = {{}, k, lambda, 0.75 - 0.001 * s, 0.0625 * s, static_cast<int32_t>(k % 11) - 1,
              0.015 * static_cast<double>(k % 11), {0.6, -0.8, 0.0}, static_cast<uint8_t>(k % 4)};
    ASSERT_TRUE(rec.record_reason(reason));
    // Its stamp is its own (a debrief event's start), before the log time.
    log = {ros_time_from_ns(k / 2 * kPeriodNs), static_cast<uint8_t>(10 * (1 + k % 5)),
           kDebriefLogger, "planner took over for 1.8 s (lowest λ 0.21) at step " + std::to_string(k),
           "", k % 2 ? "takeover" : "near miss", static_cast<uint32_t>(k)};
    ASSERT_TRUE(rec.record_log(k, log));
    command = {{}, k, static_cast<uint8_t>(k % 8), 0.125, 0.875, {2.0, -0.5 * s, 0.25},
               0.5, 0.0625, k % 8 == 4 ? "watch the column" : ""};
    ASSERT_TRUE(rec.record_command(command));
  }
  ASSERT_TRUE(rec.close(err)) << err;

  const std::string actual =
      run("'" + node + "' '" + (check_dir / "check.mjs").string() + "' '" + file.string() + "' 2>&1");

  // The expected JSON, in check.mjs's order.
  const RosTime t = ros_time_from_ns((kSteps - 1) * kPeriodNs);
  ASSERT_GT(t.sec, 0);
  ASSERT_GT(t.nanosec, 0u);
  Json j;
  j.begin('{');
  j.key("profile").str("ros2").key("library").str(version()).key("dataSectionCrc").str("ok");
  j.key("statistics").begin('{');
  const double topics = static_cast<double>(recorded_types().size());
  j.key("messageCount").num(topics * kSteps).key("schemaCount").num(topics);
  j.key("channelCount").num(topics);
  j.key("metadataCount").num(2).key("messageStartTime").num(0);
  j.key("messageEndTime").num(static_cast<double>((kSteps - 1) * kPeriodNs));
  j.end('}');
  std::vector<RecordedType> types(recorded_types().begin(), recorded_types().end());
  std::sort(types.begin(), types.end(),
            [](const auto& a, const auto& b) { return std::string(a.topic) < b.topic; });
  j.key("channels").begin('[');
  for (const auto& ty : types) {
    j.begin('{').key("topic").str(ty.topic).key("schemaName").str(ty.schema_name);
    j.key("schemaEncoding").str("ros2msg").key("messageEncoding").str("cdr");
    j.key("messages").num(kSteps).key("statistics").num(kSteps).end('}');
  }
  j.end(']');
  j.key("metadata").begin('[').begin('{').key("name").str("mixpilot").key("keys").begin('[');
  for (const char* k :
       {"control_period_ns", "mode", "pilot", "planned_steps", "scenario", "scenario_path", "seed",
        "trainee", "vehicle", "version"})
    j.str(k);
  j.end(']').end('}');
  j.begin('{').key("name").str("mixpilot_end").key("keys").begin('[');
  for (const char* k : {"dropped_steps", "interrupted", "recovered", "steps"}) j.str(k);
  j.end(']').end('}').end(']');
  j.key("last").begin('{');
  // Sorted by topic, fields in .msg order.
  j.key("/controller/applied").begin('{').stamp(t).key("step").num(applied.step);
  j.key("u").nums(applied.u).key("roll").num(applied.roll).key("pitch").num(applied.pitch);
  j.key("rotor_speed").nums(applied.rotor_speed).end('}');
  j.key("/controller/lambda").begin('{').key("data").num(lambda).end('}');
  j.key("/controller/lambda_reason").begin('{').stamp(t).key("step").num(reason.step);
  j.key("lambda").num(reason.lambda).key("ph_index").num(reason.ph_index);
  j.key("d_res").num(reason.d_res).key("node").num(reason.node).key("ahead").num(reason.ahead);
  j.key("direction").nums(reason.direction).key("cap").num(reason.cap).end('}');
  j.key("/controller/prediction").begin('{').stamp(t).key("step").num(pred.step);
  j.key("position").nums(pred.position).key("reference").nums(pred.reference).end('}');
  j.key("/controller/solver").begin('{').stamp(t).key("step").num(solver.step);
  j.key("status").num(solver.status).key("qp_iterations").num(solver.qp_iterations);
  j.key("integration_us").num(solver.integration_us);
  j.key("linearization_us").num(solver.linearization_us).key("qp_us").num(solver.qp_us);
  j.key("total_us").num(solver.total_us).key("fallback").raw(solver.fallback ? "true" : "false");
  j.end('}');
  j.key("/instructor/command").begin('{').stamp(t).key("step").num(command.step);
  j.key("kind").num(command.kind).key("floor").num(command.floor);
  j.key("ceiling").num(command.ceiling).key("force").nums(command.force);
  j.key("duration").num(command.duration).key("delay").num(command.delay);
  j.key("text").str(command.text).end('}');
  j.key("/joy").begin('{').key("header").begin('{').stamp(t).key("frame_id").str(joy.frame_id);
  j.end('}').key("axes").nums(joy.axes).key("buttons").nums(joy.buttons).end('}');
  j.key("/mode/channels").begin('{').stamp(t).key("step").num(channels.step);
  j.key("events").num(channels.events).key("names").strs(channels.names);
  j.key("units").strs(channels.units).key("values").nums(channels.values).end('}');
  j.key("/pilot/command").begin('{').stamp(t).key("step").num(pilot.step);
  j.key("roll").num(pilot.roll).key("pitch").num(pilot.pitch);
  j.key("rotor_speed").nums(pilot.rotor_speed).key("source").str(pilot.source);
  j.key("authority").num(pilot.authority).key("input_state").num(pilot.input_state).end('}');
  j.key("/rosout").begin('{').stamp(log.stamp).key("level").num(log.level);
  j.key("name").str(log.name).key("msg").str(log.msg).key("file").str(log.file);
  j.key("function").str(log.function).key("line").num(log.line).end('}');
  j.key("/vehicle/state").begin('{').stamp(t).key("step").num(state.step);
  j.key("x").nums(state.x).end('}');
  j.end('}');
  j.end('}');

  EXPECT_EQ(actual, j.text());
}

// A recording of another mode, made the way `mixpilot fly --record` makes it: the Pendubot
// swing-up (4 states, 1 input, no pilot, no prediction) is read by the independent reader too.
TEST(McapIndependentReader, ReadsAPendubotRecording) {
  const std::string node = MIXPILOT_NODE;
  if (node.empty()) GTEST_SKIP() << "node not found at configure time";
  const fs::path check_dir = fs::path(MIXPILOT_SOURCE_DIR) / "tests" / "mcap_check";
  const fs::path file = test::fresh_path("mcap_independent", "pendubot.mcap");
  const std::string scenario = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/pendubot_swingup.toml";

  std::string err, text;
  ASSERT_TRUE(read_text_file(scenario, text, err)) << err;
  ModeRequest request;
  request.duration = 0.5;  // 250 steps of 2 ms
  auto mode = make_mode(text, scenario, std::move(request), err);
  ASSERT_TRUE(mode) << err;
  RecordingSink recorder;
  ASSERT_TRUE(recorder.open(file.string(), *mode, {"pendubot_swingup", text, scenario, 0, ""}, err))
      << err;
  Session session(*mode);
  session.add_sink(&recorder);
  session.run();
  ASSERT_TRUE(recorder.close(err)) << err;
  ASSERT_EQ(mode->steps_done(), 250);

  const std::string out =
      run("'" + node + "' '" + (check_dir / "check.mjs").string() + "' '" + file.string() + "' 2>&1");
  const auto has = [&](const std::string& s) {
    EXPECT_NE(out.find(s), std::string::npos) << "missing " << s << " in\n" << out.substr(0, 2000);
  };
  has(R"("profile":"ros2")");
  has(R"("dataSectionCrc":"ok")");
  for (const char* topic : {"/vehicle/state", "/controller/applied", "/controller/solver"}) {
    has(std::string(R"({"topic":")") + topic + R"(","schemaName":")");
  }
  has(R"("schemaName":"mixpilot_msgs/msg/ModeChannels","schemaEncoding":"ros2msg","messageEncoding":"cdr","messages":250,"statistics":250})");
  has(R"("schemaName":"mixpilot_msgs/msg/VehicleState","schemaEncoding":"ros2msg","messageEncoding":"cdr","messages":250,"statistics":250})");
  has(R"("schemaName":"mixpilot_msgs/msg/PilotCommand","schemaEncoding":"ros2msg","messageEncoding":"cdr","messages":0,"statistics":0})");
  const Telemetry& last = mode->telemetry();
  ASSERT_GT(last.num_channels, 0);
  has(std::string(R"("names":[")") + last.channels[0].name + "\"");
  Json x;
  x.nums(std::vector<double>(last.x.data(), last.x.data() + last.x.size()));
  has(R"("step":249,"x":)" + x.text());  // the last state, decoded from CDR by the reader
}

// A mixed-initiative flight's /controller/lambda_reason (SPEC §10 "Why λ fell"), as recorded by
// the sink every step: the independent reader decodes each message with the embedded schema,
// and the last one holds what the flight's last step said.
TEST(McapIndependentReader, DecodesTheLambdaReasonOfAFlight) {
  const std::string node = MIXPILOT_NODE;
  if (node.empty()) GTEST_SKIP() << "node not found at configure time";
  const fs::path check_dir = fs::path(MIXPILOT_SOURCE_DIR) / "tests" / "mcap_check";
  const fs::path file = test::fresh_path("mcap_independent", "reason.mcap");
  const std::string scenario = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
  std::string err, text;
  ASSERT_TRUE(read_text_file(scenario, text, err)) << err;
  ModeRequest request;
  request.duration = 3.0;  // 200 steps of 15 ms
  request.pilot_name = "reckless";
  auto mode = make_mode(text, scenario, std::move(request), err);
  ASSERT_TRUE(mode) << err;
  RecordingSink recorder;
  ASSERT_TRUE(recorder.open(file.string(), *mode,
                            {"mixed_initiative", text, scenario, 1, "reckless"}, err))
      << err;
  Session session(*mode);
  session.add_sink(&recorder);
  session.run();
  ASSERT_TRUE(recorder.close(err)) << err;

  const std::string out =
      run("'" + node + "' '" + (check_dir / "check.mjs").string() + "' '" + file.string() + "' 2>&1");
  const auto has = [&](const std::string& s) {
    EXPECT_NE(out.find(s), std::string::npos) << "missing " << s << " in\n" << out.substr(0, 3000);
  };
  has(R"("dataSectionCrc":"ok")");
  has(R"({"topic":"/controller/lambda_reason","schemaName":"mixpilot_msgs/msg/LambdaReason","schemaEncoding":"ros2msg","messageEncoding":"cdr","messages":200,"statistics":200})");
  const Telemetry& s = mode->telemetry();
  const LambdaReason& r = s.reason;
  ASSERT_GE(r.node, 0);
  Json last;
  last.begin('{').stamp(ros_time_from_ns(std::uint64_t(s.step) * kPeriodNs));
  last.key("step").num(double(s.step)).key("lambda").num(s.lambda).key("ph_index").num(r.ph_index);
  last.key("d_res").num(r.d_res).key("node").num(r.node).key("ahead").num(r.ahead);
  // The direction's layout is checked above; its components may be small enough for JavaScript
  // to print them in exponent form.
  has(R"("/controller/lambda_reason":)" + last.text() + R"(,"direction":[)");
  has(R"("cap":)" + std::to_string(int(r.cap)) + R"(},"/controller/prediction")");
}

}  // namespace
}  // namespace mixpilot
