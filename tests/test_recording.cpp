// Session recordings (core/recording/recording.hpp): every message type round-trips bit-exactly, a
// recorded session reads back in order with its metadata and how it ended, a failed session
// keeps its temporary, corrupt or truncated recordings give errors naming a byte offset, a
// recording cut at any byte is recovered as a prefix of the original
// (core/recording/recover.hpp), and output files never clobber anything
// (core/base/output_file.hpp).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "core/base/input_file.hpp"
#include "core/numerics/version.hpp"
#include "core/base/output_file.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/recover.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "temp_files.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
using test::slurp;
using test::temporaries_of;

fs::path temp_path(const std::string& name) {
  return test::fresh_path("recording", name);
}

double nan_with_payload() {
  const uint64_t bits = 0x7FF8000000012345ull;
  double d;
  std::memcpy(&d, &bits, 8);
  return d;
}

// Awkward doubles: a NaN payload, −0, the smallest subnormal, extremes, values with no short
// decimal form. Bit-exactness is checked by re-encoding (NaN ≠ NaN under ==).
const std::vector<double> kDoubles = {0.1, -0.0, std::numeric_limits<double>::denorm_min(),
                                      1.7976931348623157e308, -1.0 / 3.0, nan_with_payload(),
                                      std::numeric_limits<double>::infinity()};

// `old_format`: a truncation the decoder must accept as a whole message of an older version
// (true for the lengths that end where that version ended).
template <class Msg>
void expect_bit_exact_round_trip(const Msg& m,
                                 bool (*old_format)(const Msg& part, const Msg& whole) = nullptr) {
  CdrWriter w;
  encode(m, w);
  Msg back;
  std::string err;
  ASSERT_TRUE(decode(w.span(), back, err)) << err;
  CdrWriter again;
  encode(back, again);
  EXPECT_EQ(w.bytes(), again.bytes());
  // Every truncation of the message is an error naming a byte offset, but for the lengths of a
  // whole message of an older version (the end of its last field and the zero padding after it).
  int old = 0;
  for (std::size_t n = 0; n < w.bytes().size(); ++n) {
    Msg part;
    if (old_format && decode(std::span<const uint8_t>(w.bytes().data(), n), part, err)) {
      EXPECT_TRUE(old_format(part, m)) << n;
      ++old;
      continue;
    }
    ASSERT_FALSE(decode(std::span<const uint8_t>(w.bytes().data(), n), part, err)) << n;
    ASSERT_NE(err.find("at byte "), std::string::npos) << err;
  }
  EXPECT_LE(old, 8);
  if (old_format) {
    EXPECT_GE(old, 1);
  }
}

TEST(RecordingMessages, EveryTypeRoundTripsBitExactly) {
  JoyMsg joy{{12, 345}, "gamepad0", {0.1f, -1.0f, std::numeric_limits<float>::denorm_min()}, {0, 1, -7}};
  expect_bit_exact_round_trip(joy);
  PilotCommandMsg pilot{{1, 2}, 1ull << 40, kDoubles[0], kDoubles[1],
                        {kDoubles[2], kDoubles[3], kDoubles[4], kDoubles[5]}, "replay:run ü.mcap",
                        0.375, 3};
  // Recordings made before `authority` and `input_state` existed end after `source`.
  expect_bit_exact_round_trip<PilotCommandMsg>(pilot, [](const auto& part, const auto& whole) {
    return part.authority == 1.0 && part.input_state == 0 && part.source == whole.source &&
           part.step == whole.step;
  });
  VehicleStateMsg state{{3, 4}, 99, kDoubles};
  expect_bit_exact_round_trip(state);
  AppliedCommandMsg applied{{5, 6}, 7, {0.1, 0.2, 0.3, 0.4}, kDoubles[4], kDoubles[5],
                            {kDoubles[6], 1, 2, 3}};
  expect_bit_exact_round_trip(applied);
  SolverStatsMsg solver{{7, 8}, 9, 3, 17, 1.5, 2.25, kDoubles[0], kDoubles[4], true};
  expect_bit_exact_round_trip(solver);
  PredictionMsg pred{{9, 10}, 11, kDoubles, {}};
  expect_bit_exact_round_trip(pred);
  PredictionMsg empty{};
  expect_bit_exact_round_trip(empty);
  ModeChannelsMsg channels{{11, 12}, 13, 0x11, {"lambda", "", "roll MPC ü"}, {"", "m", "rad"},
                           {kDoubles[0], kDoubles[5], kDoubles[6]}};
  expect_bit_exact_round_trip(channels);
  expect_bit_exact_round_trip(ModeChannelsMsg{});
  // rcl_interfaces/msg/Log: the debrief's events on /rosout.
  LogMsg log{{13, 14}, 30, "mixpilot.debrief",
             "planner took over for 1.8 s (lowest λ 0.21): you would leave the ball by 0.08 m",
             "", "takeover", 7};
  expect_bit_exact_round_trip(log);
  expect_bit_exact_round_trip(LogMsg{});

  // And == where NaN is absent.
  CdrWriter w;
  encode(joy, w);
  JoyMsg joy_back;
  std::string err;
  ASSERT_TRUE(decode(w.span(), joy_back, err));
  EXPECT_EQ(joy_back, joy);
  w.reset();
  encode(solver, w);
  SolverStatsMsg solver_back;
  ASSERT_TRUE(decode(w.span(), solver_back, err));
  EXPECT_EQ(solver_back, solver);

  w.reset();
  encode_float64(kDoubles[5], w);
  double d = 0;
  ASSERT_TRUE(decode_float64(w.span(), d, err));
  EXPECT_EQ(std::memcmp(&d, &kDoubles[5], 8), 0);
}

TEST(RecordingMessages, DecodeRejectsTrailingBytes) {
  CdrWriter w;
  encode_float64(1.0, w);
  std::vector<uint8_t> b = w.bytes();
  b.push_back(0);  // zero padding is tolerated (some CDR writers pad the end)
  double d;
  std::string err;
  EXPECT_TRUE(decode_float64(b, d, err)) << err;
  b.push_back(5);
  EXPECT_FALSE(decode_float64(b, d, err));
  EXPECT_NE(err.find("unexpected bytes after the message at byte 12"), std::string::npos) << err;
}

TEST(RecordingMessages, SchemasAreRos2msgWithDependencies) {
  const auto types = recorded_types();
  ASSERT_EQ(types.size(), 11u);
  const std::string sep(80, '=');
  for (const auto& t : types) {
    const std::string text = t.schema_text;
    // Every dependency is declared after a separator line; each type appears once.
    if (text.find("builtin_interfaces/Time stamp") != std::string::npos) {
      EXPECT_NE(text.find(sep + "\nMSG: builtin_interfaces/Time\n"), std::string::npos) << t.topic;
    }
    if (text.find("std_msgs/Header header") != std::string::npos) {
      EXPECT_NE(text.find(sep + "\nMSG: std_msgs/Header\n"), std::string::npos) << t.topic;
    }
  }
  EXPECT_STREQ(types[0].schema_name, "sensor_msgs/msg/Joy");
  EXPECT_STREQ(types[1].topic, "/pilot/command");
}

constexpr uint64_t kPeriodNs = 15'000'000;  // Δt = 15 ms (SPEC §5.4)

SessionInfo test_info() {
  return {"mixed_initiative", "[scenario]\nname = \"helix\"\n# ü\n", "scenarios/mi_helix.toml",
          1234567890123ull, "novice"};
}

// Records `steps` control steps of every topic. Values depend on the step so order shows.
void record_session(SessionRecorder& rec, uint64_t steps) {
  for (uint64_t k = 0; k < steps; ++k) {
    const double s = static_cast<double>(k);
    ASSERT_TRUE(rec.record_joy(k, {{}, "gamepad", {static_cast<float>(s) * 0.5f, -1.0f}, {1, 0}}));
    PilotCommandMsg p;
    p.step = k;
    p.roll = 0.01 * s;
    p.pitch = -0.02 * s;
    p.rotor_speed = {0.0655 + s, 0.0656, 0.0657, 0.0658};
    p.source = "novice";
    ASSERT_TRUE(rec.record_pilot(p));
    VehicleStateMsg x{{}, k, std::vector<double>(16, s / 3.0)};
    ASSERT_TRUE(rec.record_state(x));
    ASSERT_TRUE(rec.record_lambda(k, 1.0 / (1.0 + s)));
    ASSERT_TRUE(rec.record_applied({{}, k, {0.07, 0.08, 0.09, s}, 0.1, 0.2, {1, 2, 3, 4}}));
    ASSERT_TRUE(rec.record_solver({{}, k, 0, static_cast<uint32_t>(k), 1, 2, 3, 6 + s, k % 2 == 1}));
    ASSERT_TRUE(rec.record_prediction({{}, k, std::vector<double>(33, s), std::vector<double>(33, -s)}));
    ASSERT_TRUE(rec.record_channels({{}, k, uint32_t(k % 4), {"lambda", "deviation"}, {"", "m"},
                                     {1.0 / (1.0 + s), 0.01 * s}}));
    ASSERT_TRUE(rec.record_reason({{}, k, 1.0 / (1.0 + s), 1.0 / (1.0 + s), 0.01 * s,
                                   int32_t(k % 11) - 1, 0.015 * double(k % 11), {0.0, 0.6, -0.8},
                                   uint8_t(k % 4)}));
    // A debrief event's message: stamped at its start, logged when it closed (now).
    ASSERT_TRUE(rec.record_log(k, {ros_time_from_ns(k / 2 * kPeriodNs), 30, "mixpilot.debrief",
                                   "near miss for " + std::to_string(k) + " s", "", "near miss",
                                   0}));
    ASSERT_TRUE(rec.record_command({{}, k, uint8_t(k % 8), 0.0, 1.0, {s, 0.0, -s}, 0.5, 0.0,
                                    k % 8 == 4 ? "marker " + std::to_string(k) : ""}));
  }
}

TEST(SessionRecorder, RecordsAndReadsBack) {
  const fs::path p = temp_path("session.mcap");
  SessionRecorder rec;
  std::string err;
  ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
  record_session(rec, 20);
  ASSERT_TRUE(rec.close(err)) << err;
  EXPECT_TRUE(temporaries_of(p).empty());

  const auto r = read_recording(p.string(), err);
  ASSERT_TRUE(r) << err;
  EXPECT_TRUE(r->complete);
  EXPECT_EQ(r->library, version());
  EXPECT_EQ(r->control_period_ns, kPeriodNs);
  EXPECT_EQ(r->metadata.at("scenario"), test_info().scenario);
  EXPECT_EQ(r->metadata.at("scenario_path"), "scenarios/mi_helix.toml");
  EXPECT_EQ(r->metadata.at("version"), version());
  EXPECT_EQ(r->metadata.at("seed"), "1234567890123");
  EXPECT_EQ(r->metadata.at("pilot"), "novice");
  EXPECT_EQ(r->metadata.at("mode"), "mixed_initiative");
  ASSERT_TRUE(r->end);  // closed normally: a complete flight
  EXPECT_EQ(*r->end, (RecordingEnd{false, false, 20, 0}));
  for (const auto& t : recorded_types()) EXPECT_EQ(r->message_counts.at(t.topic), 20u) << t.topic;
  ASSERT_EQ(r->pilot.size(), 20u);
  for (uint64_t k = 0; k < 20; ++k) {
    const auto& p = r->pilot[k];
    EXPECT_EQ(p.step, k);
    EXPECT_EQ(ros_time_to_ns(p.stamp), k * kPeriodNs);  // stamp = log time = k·Δt, exact
    EXPECT_EQ(p.roll, 0.01 * static_cast<double>(k));
    EXPECT_EQ(p.rotor_speed[0], 0.0655 + static_cast<double>(k));
    EXPECT_EQ(p.source, "novice");
    EXPECT_EQ(r->lambda[k].step, k);
    EXPECT_EQ(r->lambda[k].lambda, 1.0 / (1.0 + static_cast<double>(k)));
    EXPECT_EQ(ros_time_to_ns(r->joy[k].stamp), k * kPeriodNs);
    EXPECT_EQ(r->joy[k].frame_id, "gamepad");
    EXPECT_EQ(r->states[k].x.size(), 16u);
    EXPECT_EQ(r->solver[k].fallback, k % 2 == 1);
    EXPECT_EQ(r->predictions[k].reference.size(), 33u);
    EXPECT_EQ(r->applied[k].u[3], static_cast<double>(k));
    EXPECT_EQ(r->channels[k].events, k % 4);
    EXPECT_EQ(r->channels[k].names[1], "deviation");
    EXPECT_EQ(r->channels[k].values[1], 0.01 * static_cast<double>(k));
    const LambdaReasonMsg& why = r->reasons[k];
    EXPECT_EQ(why.step, k);
    EXPECT_EQ(ros_time_to_ns(why.stamp), k * kPeriodNs);
    EXPECT_EQ(why.d_res, 0.01 * static_cast<double>(k));
    EXPECT_EQ(why.node, int32_t(k % 11) - 1);
    EXPECT_EQ(why.ahead, 0.015 * double(k % 11));
    EXPECT_EQ(why.direction, (std::array<double, 3>{0.0, 0.6, -0.8}));
    EXPECT_EQ(why.cap, k % 4);
    const LogMsg& log = r->log[k];
    EXPECT_EQ(ros_time_to_ns(log.stamp), k / 2 * kPeriodNs);  // its own stamp, not the log time
    EXPECT_EQ(log.level, 30u);
    EXPECT_EQ(log.name, "mixpilot.debrief");
    EXPECT_EQ(log.msg, "near miss for " + std::to_string(k) + " s");
    EXPECT_EQ(log.function, "near miss");
    const InstructorCommandMsg& c = r->commands[k];
    EXPECT_EQ(ros_time_to_ns(c.stamp), k * kPeriodNs);
    EXPECT_EQ(c.step, k);
    EXPECT_EQ(c.kind, k % 8);
    EXPECT_EQ(c.force, (std::array<double, 3>{double(k), 0.0, -double(k)}));
    EXPECT_EQ(c.text, k % 8 == 4 ? "marker " + std::to_string(k) : "");
  }
  // Log times in the container are k·Δt too.
  std::string e2;
  const auto f = read_mcap(p.string(), e2);
  ASSERT_TRUE(f) << e2;
  EXPECT_EQ(f->messages.back().log_time, 19 * kPeriodNs);
  for (const auto& [id, ch] : f->channels) EXPECT_TRUE(ch.metadata.count("offered_qos_profiles"));
}

TEST(SessionRecorder, LargeStepsKeepExactTimes) {
  // 2^32 steps of 15 ms is 2 years; stamps split into sec/nanosec without rounding.
  const uint64_t k = (1ull << 32) + 7;
  const RosTime t = ros_time_from_ns(k * kPeriodNs);
  EXPECT_EQ(ros_time_to_ns(t), k * kPeriodNs);
  EXPECT_LT(t.nanosec, 1'000'000'000u);
}

TEST(SessionRecorder, FailedSessionKeepsItsTmp) {
  const fs::path p = temp_path("failed.mcap");
  std::string tmp;
  {
    SessionRecorder rec;
    std::string err;
    ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
    tmp = rec.writer().tmp_path();
    record_session(rec, 5);
    // A step going back in time is refused, and the recording cannot be completed...
    EXPECT_FALSE(rec.record_lambda(2, 0.5));
    EXPECT_FALSE(rec.close(err));
    EXPECT_NE(err.find("log-time order"), std::string::npos) << err;
    EXPECT_NE(err.find("kept in " + tmp), std::string::npos) << err;
  }
  // ...but all that was recorded before stays in the temporary.
  EXPECT_FALSE(fs::exists(p));
  std::string err;
  EXPECT_FALSE(read_recording(tmp, err));
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  const auto r = read_recording(tmp, err, lenient);
  ASSERT_TRUE(r) << err;
  EXPECT_FALSE(r->complete);
  EXPECT_FALSE(r->end);  // the closing record is written only when the file can be completed
  EXPECT_EQ(r->pilot.size(), 5u);
  EXPECT_EQ(r->metadata.at("pilot"), "novice");
}

// A real crash: a child process records 7 steps, flushes and is killed (SIGKILL: no
// destructor, no close). What was flushed is on disk in its temporary.
TEST(SessionRecorder, CrashMidSessionLosesNothingFlushed) {
  const fs::path p = temp_path("crashed.mcap");
  const pid_t child = fork();
  ASSERT_GE(child, 0) << std::strerror(errno);
  if (child == 0) {
    SessionRecorder rec;
    std::string err;
    if (!rec.open(p.string(), kPeriodNs, test_info(), err)) _exit(1);
    record_session(rec, 7);
    if (!rec.flush()) _exit(2);
    raise(SIGKILL);
    _exit(3);  // not reached
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "the child did not die by SIGKILL (exit " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1)
      << ")";
  const std::vector<fs::path> tmp = temporaries_of(p);
  ASSERT_EQ(tmp.size(), 1u) << "the killed recorder's temporary";
  EXPECT_FALSE(fs::exists(p));  // never put in place
  std::string err;
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  auto f = parse_mcap(slurp(tmp[0]), "crashed.mcap.tmp", err, lenient);
  ASSERT_TRUE(f) << err;
  const auto r = decode_recording(*f, "crashed.mcap.tmp", err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->predictions.size(), 7u);  // everything up to the flush is on disk
}

// A small recording for the exhaustive malformed-input tests.
std::vector<uint8_t> small_recording() {
  const fs::path p = temp_path("small.mcap");
  SessionRecorder rec;
  std::string err;
  EXPECT_TRUE(rec.open(p.string(), kPeriodNs, {"mixed_initiative", "x = 1\n", "s.toml", 1, "gamepad"}, err));
  record_session(rec, 2);
  EXPECT_TRUE(rec.close(err)) << err;
  return slurp(p);
}

TEST(SessionRecorder, TruncatedRecordingsGiveByteOffsets) {
  const auto good = small_recording();
  std::string err;
  ASSERT_TRUE(parse_mcap(good, "r.mcap", err));
  for (std::size_t n = 0; n < good.size(); ++n) {
    const std::vector<uint8_t> b(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    const auto f = parse_mcap(b, "r.mcap", err);
    ASSERT_FALSE(f) << n;
    ASSERT_EQ(err.rfind("r.mcap: ", 0), 0u) << err;
    ASSERT_NE(err.find(" at byte "), std::string::npos) << err;
  }
}

TEST(SessionRecorder, CorruptRecordingsNeverCrash) {
  auto good = small_recording();
  // Without CRCs the corruptions reach the MCAP structure checks and the CDR decoders.
  const std::size_t footer = good.size() - 8 - 29;
  uint64_t summary_start;
  std::memcpy(&summary_start, good.data() + footer + 9, 8);
  std::memset(good.data() + summary_start - 4, 0, 4);
  std::memset(good.data() + footer + 25, 0, 4);
  std::mt19937 rng(777);
  int decoded = 0, rejected = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    auto b = good;
    const std::size_t at = rng() % b.size();
    b[at] = static_cast<uint8_t>(rng());
    std::string err;
    const auto f = parse_mcap(b, "c.mcap", err);
    if (!f) {
      ++rejected;
      ASSERT_NE(err.find(" at byte "), std::string::npos) << err;
      continue;
    }
    const auto r = decode_recording(*f, "c.mcap", err);
    if (r) {
      ++decoded;
    } else {
      ++rejected;
      ASSERT_NE(err.find(" at byte "), std::string::npos) << err;
    }
  }
  EXPECT_GT(decoded, 0);  // corrupt payload values still decode (no CRC): that is expected
  EXPECT_GT(rejected, 0);
}

// ---- how a recording ended ---------------------------------------------------------------

TEST(RecordingEnd, InterruptedAndDroppedStepsAreRecorded) {
  const fs::path p = temp_path("interrupted.mcap");
  SessionRecorder rec;
  std::string err;
  ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
  record_session(rec, 6);
  ASSERT_TRUE(rec.close(err, /*interrupted=*/true, /*dropped_steps=*/3)) << err;
  const auto r = read_recording(p.string(), err);
  ASSERT_TRUE(r) << err;
  ASSERT_TRUE(r->end);
  EXPECT_EQ(*r->end, (RecordingEnd{true, false, 6, 3}));
}

// Writes a recording whose "mixpilot_end" record holds `end` and whose data has `steps` states.
std::vector<uint8_t> recording_with_end(const McapStringMap& end, uint64_t steps) {
  const fs::path p = temp_path("end.mcap");
  McapWriter w;
  std::string err;
  EXPECT_TRUE(w.open(p.string(), err)) << err;
  const auto& state = recorded_types()[2];
  EXPECT_EQ(std::string(state.topic), "/vehicle/state");
  const auto c = w.add_channel(w.add_schema(state.schema_name, "ros2msg", state.schema_text),
                               state.topic, "cdr");
  CdrWriter cdr;
  for (uint64_t k = 0; k < steps; ++k) {
    cdr.reset();
    encode(VehicleStateMsg{{}, k, {1.0}}, cdr);
    EXPECT_TRUE(w.write_message(c, uint32_t(k), k, k, cdr.span()));
  }
  EXPECT_TRUE(w.write_metadata("mixpilot_end", end));
  EXPECT_TRUE(w.close(err)) << err;
  return slurp(p);
}

TEST(RecordingEnd, MalformedOrInconsistentEndRecordsAreErrors) {
  std::string err;
  auto decode_bytes = [&](const std::vector<uint8_t>& b) {
    const auto f = parse_mcap(b, "e.mcap", err);
    EXPECT_TRUE(f) << err;
    return f ? decode_recording(*f, "e.mcap", err) : std::nullopt;
  };
  const auto good = decode_bytes(recording_with_end({{"interrupted", "false"}, {"steps", "2"}}, 2));
  ASSERT_TRUE(good) << err;
  EXPECT_EQ(*good->end, (RecordingEnd{false, false, 2, 0}));  // optional keys default

  const std::vector<std::pair<McapStringMap, std::string>> bad = {
      {{{"steps", "2"}}, "no 'interrupted' key"},
      {{{"interrupted", "yes"}, {"steps", "2"}}, "interrupted is 'yes', expected true or false"},
      {{{"interrupted", "true"}, {"steps", "-2"}}, "steps is '-2', expected a decimal count"},
      {{{"interrupted", "true"}, {"steps", "2x"}}, "steps is '2x', expected a decimal count"},
      {{{"interrupted", "true"}, {"steps", "99999999999999999999"}},
       "steps is '99999999999999999999', expected a decimal count"},
      {{{"interrupted", "true"}, {"steps", "2"}, {"recovered", ""}},
       "recovered is '', expected true or false"},
  };
  for (const auto& [end, why] : bad) {
    EXPECT_FALSE(decode_bytes(recording_with_end(end, 2))) << why;
    EXPECT_NE(err.find("malformed mixpilot_end Metadata record (" + why + ") at byte "),
              std::string::npos)
        << err;
  }
  EXPECT_FALSE(decode_bytes(recording_with_end({{"interrupted", "false"}, {"steps", "3"}}, 2)));
  EXPECT_NE(err.find("mixpilot_end Metadata record says 3 steps, the recording has 2 at byte "),
            std::string::npos)
      << err;
}

// The sink ends the file with the flight's end: interrupted or not, and the steps it holds.
TEST(RecordingEnd, SinkMarksAnInterruptedFlight) {
  const std::string scenario = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";
  std::string err, text;
  ASSERT_TRUE(read_text_file(scenario, text, err)) << err;
  for (const bool interrupted : {false, true}) {
    const fs::path p = temp_path(interrupted ? "sink_interrupted.mcap" : "sink_complete.mcap");
    ModeRequest request;
    request.duration = 0.3;
    auto mode = make_mode(text, scenario, std::move(request), err);
    ASSERT_TRUE(mode) << err;
    RecordingSink sink;
    ASSERT_TRUE(sink.open(p.string(), *mode, {"mixed_initiative", text, scenario, 1, "novice"},
                          err, RecordingSink::Settings{}, /*overwrite=*/false))
        << err;
    EXPECT_EQ(temporaries_of(p), std::vector<fs::path>{fs::path(sink.temp_path())});
    Session session(*mode);
    session.add_sink(&sink);
    if (interrupted) {
      for (int k = 0; k < 7; ++k) ASSERT_TRUE(session.step());
    } else {
      session.run();
    }
    ASSERT_TRUE(sink.close(err, interrupted)) << err;
    const auto r = read_recording(p.string(), err);
    ASSERT_TRUE(r) << err;
    ASSERT_TRUE(r->end);
    EXPECT_EQ(r->end->interrupted, interrupted);
    EXPECT_EQ(r->end->steps, uint64_t(mode->steps_done()));
    EXPECT_EQ(r->states.size(), uint64_t(mode->steps_done()));
    if (interrupted) {
      EXPECT_EQ(mode->steps_done(), 7);
    }
    EXPECT_EQ(r->end->dropped_steps, 0u);
  }
}

// ---- recovery ----------------------------------------------------------------------------

struct MessageKey {
  std::string topic;
  uint32_t sequence;
  uint64_t log_time;
  std::vector<uint8_t> data;
  bool operator==(const MessageKey&) const = default;
};
std::vector<MessageKey> message_keys(const McapFile& f) {
  std::vector<MessageKey> out;
  for (const auto& m : f.messages) {
    const auto d = f.data(m);
    out.push_back({f.channels.at(m.channel_id).topic, m.sequence, m.log_time, {d.begin(), d.end()}});
  }
  return out;
}

// A recording cut at any byte — every record boundary and points inside records, header to
// footer — is recovered as a valid recording whose messages are a prefix of the original's:
// every message whose step was followed by another, all of them when the cut fell after the
// closing record. A cut that leaves no whole control step is refused: such a file holds no
// flight, and `score` could not replay it.
TEST(Recovery, CutAnywhereRecoversAPrefix) {
  const fs::path src = temp_path("original.mcap");
  {
    SessionRecorder rec;
    std::string err;
    ASSERT_TRUE(rec.open(src.string(), kPeriodNs, test_info(), err)) << err;
    record_session(rec, 6);
    ASSERT_TRUE(rec.close(err)) << err;
  }
  const auto bytes = slurp(src);
  std::string err;
  const auto original = parse_mcap(bytes, "original.mcap", err);
  ASSERT_TRUE(original) << err;
  const auto all = message_keys(*original);
  uint64_t end_record_end = 0;  // the closing "mixpilot_end" record, whole
  for (const auto& md : original->metadata)
    if (md.name == "mixpilot_end") end_record_end = md.record_offset + 9 + [&] {
      uint64_t len;
      std::memcpy(&len, bytes.data() + md.record_offset + 1, 8);
      return len;
    }();
  ASSERT_GT(end_record_end, 0u);

  std::vector<std::size_t> cuts;
  for (std::size_t at = 8; at < bytes.size() - 8;) {
    for (std::size_t d : {0, 1, 20}) cuts.push_back(at + d);
    uint64_t len;
    std::memcpy(&len, bytes.data() + at + 1, 8);
    at += 9 + len;
  }
  for (std::size_t d = 1; d <= 8; ++d) cuts.push_back(bytes.size() - d);  // in the magic
  // Each recovery fsyncs its output: on a RAM file system when there is one, that costs nothing.
  fs::path dir = fs::temp_directory_path();
  if (::access("/dev/shm", W_OK) == 0) dir = "/dev/shm";
  const fs::path cut = dir / ("mixpilot_cut_" + std::to_string(::getpid()) + ".mcap.Abc123.tmp");
  const fs::path out = dir / ("mixpilot_recovered_" + std::to_string(::getpid()) + ".mcap");
  int recovered = 0, refused = 0, stepless = 0;
  std::size_t last_kept = 0;
  for (const std::size_t n : cuts) {
    if (n >= bytes.size()) continue;
    std::ofstream(cut, std::ios::binary | std::ios::trunc)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(n));
    // The whole steps the cut leaves: every message of a step that another step follows
    // within the cut (all of them after the closing record).
    std::size_t whole_messages = 0;
    for (const auto& m : original->messages)
      if (m.data_offset + m.data_size <= n) ++whole_messages;
    std::size_t kept_messages = whole_messages;
    if (n < end_record_end)
      while (kept_messages > 0 && original->messages[kept_messages - 1].log_time ==
                                      original->messages[whole_messages - 1].log_time)
        --kept_messages;
    std::size_t steps = 0;
    for (std::size_t i = 0; i < kept_messages; ++i)
      steps += original->channels.at(original->messages[i].channel_id).topic == "/vehicle/state";
    fs::remove(out);
    const auto result = recover_recording(cut.string(), out.string(), true, err);
    if (!result) {
      ++refused;
      EXPECT_FALSE(fs::exists(out)) << "a refused recovery writes nothing";
      if (n < original->schemas.begin()->second.record_offset) {  // inside the magic or Header
        ASSERT_NE(err.find(" at byte "), std::string::npos) << err;
      } else {
        ++stepless;
        ASSERT_EQ(steps, 0u) << "cut at " << n << ": " << err;
        ASSERT_NE(err.find("cut before its first whole control step"), std::string::npos) << err;
      }
      continue;
    }
    ASSERT_GT(steps, 0u) << "cut at " << n;
    ++recovered;
    const auto f = read_mcap(out.string(), err);  // strict: a complete file
    ASSERT_TRUE(f) << n << ": " << err;
    const auto r = decode_recording(*f, "recovered.mcap", err);
    ASSERT_TRUE(r) << n << ": " << err;
    const auto got = message_keys(*f);
    ASSERT_LE(got.size(), all.size());
    ASSERT_TRUE(std::equal(got.begin(), got.end(), all.begin())) << "cut at " << n;
    // Every message of a step that another step follows within the cut is kept.
    std::size_t whole = 0;
    for (const auto& m : original->messages)
      if (m.data_offset + m.data_size <= n) ++whole;
    std::size_t expect = whole;
    if (n < end_record_end)
      while (expect > 0 && original->messages[expect - 1].log_time ==
                               original->messages[whole - 1].log_time)
        --expect;
    ASSERT_EQ(got.size(), expect) << "cut at " << n;
    ASSERT_GE(got.size(), last_kept);
    last_kept = got.size();
    EXPECT_EQ(result->messages, got.size());
    EXPECT_EQ(result->messages_left_out, whole - expect);
    EXPECT_EQ(result->bytes_total, n);
    EXPECT_LE(result->bytes_used, n);
    ASSERT_TRUE(r->end);
    EXPECT_TRUE(r->end->recovered);
    EXPECT_EQ(r->end->interrupted, n < end_record_end);  // after it: the original's "false"
    EXPECT_EQ(r->end->steps, r->states.size());
    EXPECT_EQ(r->pilot.size(), r->states.size());  // whole steps only
    if (n > original->metadata.front().record_offset + 100) {
      EXPECT_EQ(r->metadata.at("scenario"), test_info().scenario);
    }
    EXPECT_EQ(f->library, original->library);
  }
  fs::remove(cut);
  fs::remove(out);
  EXPECT_EQ(last_kept, all.size());
  EXPECT_GT(recovered, 200);
  EXPECT_GT(refused, 0);
  EXPECT_GT(stepless, 0);
}

TEST(Recovery, RefusesCompleteFilesAndExistingOutputs) {
  const fs::path src = temp_path("whole.mcap");
  SessionRecorder rec;
  std::string err;
  ASSERT_TRUE(rec.open(src.string(), kPeriodNs, test_info(), err)) << err;
  record_session(rec, 3);
  ASSERT_TRUE(rec.close(err)) << err;
  EXPECT_FALSE(recover_recording(src.string(), temp_path("x.mcap").string(), false, err));
  EXPECT_EQ(err, src.string() + ": a complete recording; nothing to recover");

  auto bytes = slurp(src);
  bytes.resize(bytes.size() / 2);
  const fs::path cut = temp_path("half.mcap");
  std::ofstream(cut, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                             std::streamsize(bytes.size()));
  // Never in place, whatever name leads to the file: the cut one stays as evidence, and a
  // failed rewrite could not lose it.
  const fs::path alias = temp_path("alias.mcap");
  fs::create_symlink(cut, alias);
  for (const fs::path& target : {cut, alias}) {
    for (const bool overwrite : {false, true}) {
      EXPECT_FALSE(recover_recording(cut.string(), target.string(), overwrite, err));
      EXPECT_EQ(err, target.string() + ": the file being recovered; the recovered recording goes "
                                       "to another file (the cut one stays as it is)");
    }
  }
  EXPECT_EQ(slurp(cut), bytes);
  const fs::path beside = temp_path("half.recovered.mcap");
  const auto result = recover_recording(cut.string(), beside.string(), false, err);
  ASSERT_TRUE(result) << err;
  EXPECT_EQ(result->steps, 1u);  // steps 0 and 1 whole, step 2 cut: step 1 could be too
  const auto r = read_recording(beside.string(), err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->states.size(), 1u);
  EXPECT_EQ(slurp(cut), bytes);
  EXPECT_FALSE(recover_recording("/dev/zero", temp_path("y.mcap").string(), false, err));
  EXPECT_EQ(err, "/dev/zero: not a regular file (a character device)");
}

// A second ^C can stop a run after its recording is complete but before the move into place:
// the temporary then is the whole recording, and `recover` puts it in place as it is.
TEST(Recovery, ACompleteTemporaryIsPutInPlace) {
  const fs::path whole = temp_path("finished.mcap");
  {
    SessionRecorder rec;
    std::string err;
    ASSERT_TRUE(rec.open(whole.string(), kPeriodNs, test_info(), err)) << err;
    record_session(rec, 4);
    ASSERT_TRUE(rec.close(err)) << err;
  }
  const auto bytes = slurp(whole);
  const fs::path target = temp_path("stopped.mcap");
  const fs::path temp = target.string() + ".Qw12Er.tmp";
  fs::copy_file(whole, temp);
  std::string err;
  ASSERT_EQ(default_recovery_path(temp.string()), target.string());
  const auto result = recover_recording(temp.string(), target.string(), false, err);
  ASSERT_TRUE(result) << err;
  EXPECT_TRUE(result->was_complete);
  EXPECT_EQ(result->steps, 4u);
  EXPECT_EQ(slurp(target), bytes);          // as it was, byte for byte
  EXPECT_FALSE(fs::exists(temp));           // its bytes are at the target now
  // Never over an existing file without permission; the temporary then stays.
  fs::copy_file(whole, temp);
  EXPECT_FALSE(recover_recording(temp.string(), target.string(), false, err));
  EXPECT_NE(err.find("refusing to overwrite"), std::string::npos) << err;
  EXPECT_TRUE(fs::exists(temp));
  fs::remove(temp);
}

TEST(Recovery, DefaultOutputPath) {
  EXPECT_EQ(default_recovery_path("out/run.mcap.Ab12Cd.tmp"), "out/run.mcap");
  EXPECT_EQ(default_recovery_path("run.mcap.tmp"), "run.mcap");
  EXPECT_EQ(default_recovery_path("out/run.mcap"), "out/run.recovered.mcap");
  EXPECT_EQ(default_recovery_path("run"), "run.recovered.mcap");
  EXPECT_EQ(default_recovery_path(".tmp"), ".tmp.recovered.mcap");
}

// A session killed with SIGKILL mid-flight: its temporary holds everything it had handed to
// the OS; recovery turns it into the recording at the path it was meant for.
TEST(Recovery, AfterKill9) {
  const fs::path p = temp_path("killed.mcap");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    SessionRecorder rec;
    std::string err;
    if (!rec.open(p.string(), kPeriodNs, test_info(), err)) ::_exit(3);
    for (uint64_t k = 0; k < 40; ++k) {
      VehicleStateMsg x{{}, k, std::vector<double>(16, double(k))};
      PilotCommandMsg c;
      c.step = k;
      if (!rec.record_pilot(c) || !rec.record_state(x)) ::_exit(4);
      if (k == 29 && !rec.flush()) ::_exit(5);
    }
    ::kill(::getpid(), SIGKILL);
    ::_exit(6);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
  EXPECT_FALSE(fs::exists(p));
  const auto temps = temporaries_of(p);
  ASSERT_EQ(temps.size(), 1u);
  const std::string out = default_recovery_path(temps[0].string());
  EXPECT_EQ(out, p.string());
  std::string err;
  const auto result = recover_recording(temps[0].string(), out, false, err);
  ASSERT_TRUE(result) << err;
  const auto r = read_recording(p.string(), err);
  ASSERT_TRUE(r) << err;
  // Steps 0..29 were flushed; the last of them may be the one left out.
  EXPECT_GE(r->states.size(), 29u);
  EXPECT_LE(r->states.size(), 40u);
  for (std::size_t k = 0; k < r->states.size(); ++k) EXPECT_EQ(r->states[k].x[0], double(k));
  EXPECT_EQ(*r->end, (RecordingEnd{true, true, r->states.size(), 0}));
  EXPECT_EQ(r->metadata.at("pilot"), "novice");
  fs::remove(temps[0]);
}

// ---- output files ------------------------------------------------------------------------

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool write_output(OutputFile& f, const std::string& text) {
  return std::fwrite(text.data(), 1, text.size(), f.stream()) == text.size();
}

TEST(OutputFile, AppearsWholeOnCommit) {
  const fs::path p = temp_path("out.txt");
  OutputFile f;
  std::string err;
  ASSERT_TRUE(f.open(p.string(), false, err)) << err;
  const std::string tmp = f.temp_path();
  EXPECT_EQ(temporaries_of(p), std::vector<fs::path>{fs::path(tmp)});
  ASSERT_TRUE(write_output(f, "hello"));
  EXPECT_FALSE(fs::exists(p));
  ASSERT_TRUE(f.commit(err)) << err;
  EXPECT_EQ(read_all(p), "hello");
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_EQ(f.temp_path(), "");
  // The temporary was created like any new file: the umask applies, not mkstemp's 0600.
  const mode_t mask = ::umask(022);
  ::umask(mask);
  EXPECT_EQ(fs::status(p).permissions(), fs::perms(0666 & ~mask));
}

TEST(OutputFile, ExistingFilesOnlyWithOverwrite) {
  const fs::path p = temp_path("existing.txt");
  std::ofstream(p) << "old";
  std::string err;
  EXPECT_FALSE(check_output_path(p.string(), false, err));
  EXPECT_EQ(err, p.string() + ": " + std::strerror(EEXIST) + " (refusing to overwrite it)");
  OutputFile f;
  EXPECT_FALSE(f.open(p.string(), false, err));
  EXPECT_FALSE(f.is_open());
  EXPECT_TRUE(check_output_path(p.string(), true, err)) << err;
  ASSERT_TRUE(f.open(p.string(), true, err)) << err;
  ASSERT_TRUE(write_output(f, "new"));
  EXPECT_EQ(read_all(p), "old");
  ASSERT_TRUE(f.commit(err)) << err;
  EXPECT_EQ(read_all(p), "new");
  EXPECT_TRUE(temporaries_of(p).empty());  // the check's probe left nothing either
}

TEST(OutputFile, NeverWritesOverWhatIsNotARegularFile) {
  const fs::path dir = temp_path("a_dir");
  fs::create_directories(dir);
  const fs::path fifo = temp_path("a_fifo");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path to_dir = temp_path("link_to_dir");
  fs::create_directory_symlink(dir, to_dir);
  const fs::path to_dev = temp_path("link_to_dev");
  fs::create_symlink("/dev/null", to_dev);
  const fs::path dangling = temp_path("dangling");
  fs::create_symlink(temp_path("nothing_here"), dangling);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"/dev/full", "/dev/full: not a regular file (a character device)"},
      {"/dev/null", "/dev/null: not a regular file (a character device)"},
      {dir.string(), dir.string() + ": not a regular file (a directory)"},
      {fifo.string(), fifo.string() + ": not a regular file (a FIFO)"},
      {to_dir.string(), to_dir.string() + ": not a regular file (a symbolic link to a directory)"},
      {to_dev.string(),
       to_dev.string() + ": not a regular file (a symbolic link to a character device)"},
      {dangling.string(), dangling.string() + ": symbolic link to nothing usable: " +
                              std::strerror(ENOENT)},
      {dir.string() + "/", dir.string() + "/: names a directory, not a file"},
      {"", "empty output path"},
  };
  for (const auto& [path, want] : cases) {
    for (const bool overwrite : {false, true}) {
      std::string err;
      EXPECT_FALSE(check_output_path(path, overwrite, err)) << path;
      EXPECT_EQ(err, want);
      OutputFile f;
      EXPECT_FALSE(f.open(path, overwrite, err)) << path;
      EXPECT_EQ(err, want);
    }
  }
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_directory(dir));
}

TEST(OutputFile, UnwritableDirectoriesAreErrorsWithTheReason) {
  std::string err;
  const fs::path missing = temp_path("no_such_dir") / "x.mcap";
  EXPECT_FALSE(check_output_path(missing.string(), false, err));
  EXPECT_EQ(err, missing.string() + ": cannot create a file in " +
                     missing.parent_path().string() + ": " + std::strerror(ENOENT));
  const fs::path file = temp_path("plain_file");
  std::ofstream(file) << "x";
  const fs::path under_file = file / "x.mcap";
  EXPECT_FALSE(check_output_path(under_file.string(), false, err));
  EXPECT_EQ(err, under_file.string() + ": cannot check the output path: " + std::strerror(ENOTDIR));
  // A read-only directory (0555). Root may create files in it whatever its mode, so as root
  // the check runs in a child process that has dropped to the unprivileged user 65534.
  const fs::path ro = temp_path("read_only_dir");
  fs::create_directories(ro);
  fs::permissions(ro, fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                          fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const std::string expected = (ro / "x").string() + ": cannot create a file in " + ro.string() +
                               ": " + std::strerror(EACCES);
  if (::geteuid() != 0) {
    EXPECT_FALSE(check_output_path((ro / "x").string(), false, err));
    EXPECT_EQ(err, expected);
  } else {
    const pid_t child = fork();
    ASSERT_GE(child, 0) << std::strerror(errno);
    if (child == 0) {
      if (::setgid(65534) != 0 || ::setuid(65534) != 0) _exit(2);
      std::string e;
      const bool refused = !check_output_path((ro / "x").string(), false, e);
      _exit(refused && e == expected ? 0 : 1);
    }
    int status = 0;
    ASSERT_EQ(waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFEXITED(status)) << "the unprivileged check crashed";
    ASSERT_NE(WEXITSTATUS(status), 2) << "could not drop to user 65534";
    EXPECT_EQ(WEXITSTATUS(status), 0) << "a read-only directory was not refused with: " << expected;
  }
  fs::permissions(ro, fs::perms::owner_all);
}

TEST(OutputFile, SymbolicLinkToAFileIsWrittenThrough) {
  const fs::path target = temp_path("real.txt");
  std::ofstream(target) << "old";
  const fs::path link = temp_path("link.txt");
  fs::create_symlink(target, link);
  OutputFile f;
  std::string err;
  EXPECT_FALSE(f.open(link.string(), false, err));
  EXPECT_EQ(err, link.string() + ": " + std::strerror(EEXIST) + " (refusing to overwrite it)");
  ASSERT_TRUE(f.open(link.string(), true, err)) << err;
  EXPECT_EQ(fs::path(f.temp_path()).parent_path(), target.parent_path());
  ASSERT_TRUE(write_output(f, "new"));
  ASSERT_TRUE(f.commit(err)) << err;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(read_all(target), "new");
}

// Two runs writing one path: the first to finish wins, the second fails with the reason and
// keeps its output in its temporary.
TEST(OutputFile, SecondWriterOfOnePathFailsAndKeepsItsData) {
  const fs::path p = temp_path("contested.txt");
  OutputFile a, b;
  std::string err;
  ASSERT_TRUE(a.open(p.string(), false, err)) << err;
  ASSERT_TRUE(b.open(p.string(), false, err)) << err;
  EXPECT_NE(a.temp_path(), b.temp_path());
  ASSERT_TRUE(write_output(a, "run A"));
  ASSERT_TRUE(write_output(b, "run B"));
  ASSERT_TRUE(a.commit(err)) << err;
  const std::string b_tmp = b.temp_path();
  EXPECT_FALSE(b.commit(err));
  EXPECT_EQ(err, p.string() + ": " + std::strerror(EEXIST) +
                     " (it appeared while this run was writing; not replaced); the output is "
                     "kept in " + b_tmp);
  EXPECT_EQ(read_all(p), "run A");
  EXPECT_EQ(read_all(b_tmp), "run B");
  EXPECT_EQ(b.temp_path(), b_tmp);
  b.discard();
  EXPECT_FALSE(fs::exists(b_tmp));
}

// The fallback for file systems without RENAME_NOREPLACE behaves the same.
TEST(OutputFile, LinkFallbackNeverReplaces) {
  const fs::path from = temp_path("from.txt"), to = temp_path("to.txt");
  std::ofstream(from) << "data";
  std::string err;
  ASSERT_TRUE(link_into_place(from.string(), to.string(), err)) << err;
  EXPECT_FALSE(fs::exists(from));
  EXPECT_EQ(read_all(to), "data");
  std::ofstream(from) << "other";
  EXPECT_FALSE(link_into_place(from.string(), to.string(), err));
  EXPECT_NE(err.find(std::strerror(EEXIST)), std::string::npos) << err;
  EXPECT_NE(err.find("kept in " + from.string()), std::string::npos) << err;
  EXPECT_EQ(read_all(to), "data");
  EXPECT_EQ(read_all(from), "other");
}

TEST(OutputFile, DiscardAndAbandon) {
  const fs::path p = temp_path("dropped.txt");
  std::string err, kept;
  {
    OutputFile f;
    ASSERT_TRUE(f.open(p.string(), false, err)) << err;
    ASSERT_TRUE(write_output(f, "partial"));
    kept = f.temp_path();
  }  // destroyed uncommitted: the data stays in the temporary
  EXPECT_EQ(read_all(kept), "partial");
  EXPECT_FALSE(fs::exists(p));
  fs::remove(kept);
  OutputFile f;
  ASSERT_TRUE(f.open(p.string(), false, err)) << err;
  const std::string tmp = f.temp_path();
  f.discard();
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_FALSE(f.is_open());
  EXPECT_FALSE(f.commit(err));
  EXPECT_FALSE(fs::exists(p));
}

// A child's log quoted in a message: its last lines in order, each after the prefix, a last
// line without its newline included, control characters made printable; nothing for a file
// that cannot be read.
TEST(InputFile, LastLinesOfALog) {
  const fs::path dir = temp_path("last_lines");
  fs::create_directories(dir);
  const auto log = [&](const std::string& text) {
    std::ofstream(dir / "log") << text;
    return (dir / "log").string();
  };
  EXPECT_EQ(last_lines(log("a\nb\nc\nd\ne\n"), 3, "| "), "\n| c\n| d\n| e");
  EXPECT_EQ(last_lines(log("a\nb\nc\nd\ne"), 3, "| "), "\n| c\n| d\n| e");
  EXPECT_EQ(last_lines(log("a\nb\n"), 3, "| "), "\n| a\n| b");
  EXPECT_EQ(last_lines(log("a\nb\nc\n"), 3, ""), "\na\nb\nc");
  EXPECT_EQ(last_lines(log("a\n\x1b[2Jb\n"), 1, "| "), "\n| \\x1B[2Jb");
  EXPECT_EQ(last_lines(log(""), 3, "| "), "");
  EXPECT_EQ(last_lines(log("a\n"), 0, "| "), "");
  EXPECT_EQ(last_lines((dir / "missing").string(), 3, "| "), "");
}

// An output never replaces a file this process read as an input, by any name: the --force
// that would turn the recording being scored into its own score is refused. A file read in order
// to be rewritten (the user's settings) says so.
TEST(OutputFile, NeverReplacesAnInputOfTheRun) {
  const fs::path dir = temp_path("inputs");
  fs::create_directories(dir);
  const fs::path in = dir / "in.toml";
  std::ofstream(in) << "x = 1\n";
  fs::create_symlink(in, dir / "alias.toml");
  fs::create_hard_link(in, dir / "hard.toml");
  std::string text, err;
  ASSERT_TRUE(read_input_file(in.string(), 1000, text, err)) << err;
  for (const char* name : {"in.toml", "alias.toml", "hard.toml"}) {
    const std::string path = (dir / name).string();
    EXPECT_FALSE(check_output_path(path, true, err)) << name;
    EXPECT_EQ(err, path + ": this run read it as an input (" + in.string() +
                       "); an output never replaces an input");
    OutputFile f;
    EXPECT_FALSE(f.open(path, true, err)) << name;
  }
  OutputFile f;
  ASSERT_TRUE(f.open(in.string(), true, err, InputReplacement::allowed)) << err;
  ASSERT_TRUE(write_output(f, "x = 2\n"));
  ASSERT_TRUE(f.commit(err)) << err;
  EXPECT_EQ(read_all(in), "x = 2\n");
  // The file at that name now is another one (new inode and change time): no longer an input.
  OutputFile g;
  EXPECT_TRUE(g.open(in.string(), true, err)) << err;
  g.discard();
}

// A legal name of NAME_MAX bytes leaves no room for ".XXXXXX.tmp": the temporary is named
// after the name's first part, and the output lands under its full name.
TEST(OutputFile, NamesAtNameMax) {
  const fs::path dir = temp_path("long_names");
  fs::create_directories(dir);
  const long max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  ASSERT_GT(max, 20);
  for (const std::size_t length : {std::size_t(max), std::size_t(max) - 6, std::size_t(max) - 11}) {
    const fs::path p = dir / (std::string(length - 5, 'n') + ".mcap");
    std::string err;
    EXPECT_TRUE(check_output_path(p.string(), false, err)) << length << ": " << err;
    OutputFile f;
    ASSERT_TRUE(f.open(p.string(), false, err)) << length << ": " << err;
    EXPECT_LE(fs::path(f.temp_path()).filename().string().size(), std::size_t(max));
    ASSERT_TRUE(write_output(f, "whole"));
    ASSERT_TRUE(f.commit(err)) << err;
    EXPECT_EQ(read_all(p), "whole");
    EXPECT_TRUE(temporaries_of(p).empty());
  }
  // A multi-byte character is never cut in half.
  const fs::path u =
      dir / (std::string(std::size_t(max) - 12, 'a') + "\xC3\xA9" + std::string(10, 'b'));
  OutputFile f;
  std::string err;
  ASSERT_TRUE(f.open(u.string(), false, err)) << err;
  EXPECT_EQ(escape_controls(fs::path(f.temp_path()).filename().string()),
            fs::path(f.temp_path()).filename().string());
  f.discard();
}

// A failure says what became of the output, and only what is true: a temporary whose folder
// was removed is not "kept", and one that nothing reached (a full disk, here a file-size limit
// of 0 bytes) is removed instead of being left empty.
TEST(OutputFile, FailuresSayWhatIsLeft) {
  const fs::path dir = temp_path("vanishing");
  fs::create_directories(dir);
  {
    OutputFile f;
    std::string err;
    ASSERT_TRUE(f.open((dir / "out.mcap").string(), false, err)) << err;
    const std::string tmp = f.temp_path();
    ASSERT_TRUE(write_output(f, "data"));
    fs::remove_all(dir);
    EXPECT_FALSE(f.commit(err));
    EXPECT_EQ(err.find("kept in"), std::string::npos) << err;
    EXPECT_NE(err.find("the output is lost: its temporary " + tmp + " is gone"), std::string::npos)
        << err;
  }
  fs::create_directories(dir);
  // A full disk: writes fail with EFBIG beyond the limit (SIGXFSZ ignored, as a full disk
  // sends no signal).
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = ::signal(SIGXFSZ, SIG_IGN);
  const auto with_limit = [&](rlim_t bytes, std::size_t size, std::string& err, std::string& tmp) {
    struct rlimit lim = old;
    lim.rlim_cur = bytes;
    EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &lim), 0);
    OutputFile f;
    EXPECT_TRUE(f.open((dir / "full.mcap").string(), false, err)) << err;
    tmp = f.temp_path();
    const std::string big(size, 'x');
    (void)std::fwrite(big.data(), 1, big.size(), f.stream());
    const bool ok = f.commit(err);
    EXPECT_EQ(::setrlimit(RLIMIT_FSIZE, &old), 0);
    return ok;
  };
  std::string err, tmp;
  EXPECT_FALSE(with_limit(0, 1000, err, tmp));
  EXPECT_EQ(err, (dir / "full.mcap").string() + ": write failed: " + std::strerror(EFBIG) +
                     "; nothing had reached the disk, so no file is kept");
  EXPECT_NE(err.find("nothing had reached the disk, so no file is kept"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_FALSE(with_limit(100000, 300000, err, tmp));  // a part reached it: kept for recover
  EXPECT_NE(err.find("what was written is kept in " + tmp), std::string::npos) << err;
  EXPECT_GT(fs::file_size(tmp), 0u);
  fs::remove(tmp);
  ::signal(SIGXFSZ, old_handler);
  EXPECT_TRUE(temporaries_of(dir / "full.mcap").empty());
}

TEST(OutputFile, SameOutputPath) {
  const fs::path dir = temp_path("same_dir");
  fs::create_directories(dir);
  EXPECT_TRUE(same_output_path((dir / "x.json").string(), (dir / "." / "x.json").string()));
  EXPECT_TRUE(same_output_path((dir / "x.json").string(), (dir / "sub" / ".." / "x.json").string()));
  EXPECT_FALSE(same_output_path((dir / "x.json").string(), (dir / "y.json").string()));
  std::ofstream(dir / "x.json") << "{}";
  fs::create_symlink(dir / "x.json", dir / "alias.json");
  EXPECT_TRUE(same_output_path((dir / "x.json").string(), (dir / "alias.json").string()));
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);
  EXPECT_TRUE(same_output_path("x.json", (dir / "x.json").string()));
  fs::current_path(cwd);
}

}  // namespace
}  // namespace mixpilot
