// Session recordings (core/recording/recording.hpp): every message type round-trips bit-exactly, a
// recorded session reads back in order with its metadata, a failed session keeps its .tmp,
// and corrupt or truncated recordings give errors naming a byte offset.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "core/recording/recording.hpp"
#include "core/numerics/version.hpp"

namespace mixpilot {
namespace {

namespace fs = std::filesystem;

fs::path temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / "mixpilot_test_recording";
  fs::create_directories(dir);
  fs::remove(dir / name);
  fs::remove(dir / (name + ".tmp"));
  return dir / name;
}

std::vector<uint8_t> slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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

template <class Msg>
void expect_bit_exact_round_trip(const Msg& m) {
  CdrWriter w;
  encode(m, w);
  Msg back;
  std::string err;
  ASSERT_TRUE(decode(w.span(), back, err)) << err;
  CdrWriter again;
  encode(back, again);
  EXPECT_EQ(w.bytes(), again.bytes());
  // Every truncation of the message is an error naming a byte offset.
  for (std::size_t n = 0; n < w.bytes().size(); ++n) {
    Msg part;
    ASSERT_FALSE(decode(std::span<const uint8_t>(w.bytes().data(), n), part, err)) << n;
    ASSERT_NE(err.find("at byte "), std::string::npos) << err;
  }
}

TEST(RecordingMessages, EveryTypeRoundTripsBitExactly) {
  JoyMsg joy{{12, 345}, "gamepad0", {0.1f, -1.0f, std::numeric_limits<float>::denorm_min()}, {0, 1, -7}};
  expect_bit_exact_round_trip(joy);
  PilotCommandMsg pilot{{1, 2}, 1ull << 40, kDoubles[0], kDoubles[1],
                        {kDoubles[2], kDoubles[3], kDoubles[4], kDoubles[5]}, "replay:run ü.mcap"};
  expect_bit_exact_round_trip(pilot);
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
  ASSERT_EQ(types.size(), 8u);
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
  }
}

TEST(SessionRecorder, RecordsAndReadsBack) {
  const fs::path p = temp_path("session.mcap");
  SessionRecorder rec;
  std::string err;
  ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
  record_session(rec, 20);
  ASSERT_TRUE(rec.close(err)) << err;
  EXPECT_FALSE(fs::exists(p.string() + ".tmp"));

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
  {
    SessionRecorder rec;
    std::string err;
    ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
    record_session(rec, 5);
    // A step going back in time is refused, and the recording cannot be completed...
    EXPECT_FALSE(rec.record_lambda(2, 0.5));
    EXPECT_FALSE(rec.close(err));
    EXPECT_NE(err.find("log-time order"), std::string::npos) << err;
    EXPECT_NE(err.find(".tmp"), std::string::npos) << err;
  }
  // ...but all that was recorded before stays in the .tmp file.
  EXPECT_FALSE(fs::exists(p));
  std::string err;
  EXPECT_FALSE(read_recording(p.string() + ".tmp", err));
  McapReadOptions lenient;
  lenient.allow_truncated = true;
  const auto r = read_recording(p.string() + ".tmp", err, lenient);
  ASSERT_TRUE(r) << err;
  EXPECT_FALSE(r->complete);
  EXPECT_EQ(r->pilot.size(), 5u);
  EXPECT_EQ(r->metadata.at("pilot"), "novice");
}

TEST(SessionRecorder, CrashMidSessionLosesNothingFlushed) {
  const fs::path p = temp_path("crashed.mcap");
  {
    SessionRecorder rec;
    std::string err;
    ASSERT_TRUE(rec.open(p.string(), kPeriodNs, test_info(), err)) << err;
    record_session(rec, 7);
    ASSERT_TRUE(rec.flush());
    const auto partial = slurp(p.string() + ".tmp");
    McapReadOptions lenient;
    lenient.allow_truncated = true;
    auto f = parse_mcap(partial, "crashed.mcap.tmp", err, lenient);
    ASSERT_TRUE(f) << err;
    const auto r = decode_recording(*f, "crashed.mcap.tmp", err);
    ASSERT_TRUE(r) << err;
    EXPECT_EQ(r->predictions.size(), 7u);  // everything up to the flush is on disk
  }
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

}  // namespace
}  // namespace mixpilot
