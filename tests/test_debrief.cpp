// The debrief (SPEC §10 "Debrief events"): the events of the reckless pilot's recording of
// mi_helix, made by the command line, against its recorded channels (recomputed here as runs
// over the recorded λ, clearance, input state and event flags, not by the builder); the same
// events in the recording's /rosout (rcl_interfaces/msg/Log) as the independent Node reader
// decodes them, and as a replay rebuilds them; a scripted input loss gives input lost and back;
// a recording older than the topic replays and rebuilds its list; the words of every kind; and
// the Debrief panel in the window's replay, rendered headless, with ] and [ stepping through the
// events, a click selecting one and Export clip saving it.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <imgui.h>
#include <imgui_internal.h>

#include "app/cli.hpp"
#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "core/modes/debrief.hpp"
#include "core/modes/make_mode.hpp"
#include "core/modes/session.hpp"
#include "core/recording/mcap.hpp"
#include "core/recording/recording.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/session_recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/device_pilot.hpp"
#include "models/mikrokopter.hpp"
#include "ui/panels.hpp"
#include "ui/screen.hpp"
#include "ui/theme.hpp"

#include "run_mixpilot.hpp"
#include "scripted_pad.hpp"
#include "temp_files.hpp"
#include "ui_layout.hpp"

#ifndef MIXPILOT_NODE
#define MIXPILOT_NODE ""
#endif

namespace mixpilot {
namespace {

namespace fs = std::filesystem;
const std::string kHelix = std::string(MIXPILOT_SOURCE_DIR) + "/scenarios/mi_helix.toml";

// The reckless pilot's whole flight of mi_helix, recorded as a user records it:
// `mixpilot fly --scenario scenarios/mi_helix.toml --pilot reckless --headless --record R.mcap`.
const std::string& reckless_recording() {
  static const std::string path = [] {
    const fs::path home = test::fresh_path("debrief", "cli");
    fs::create_directories(home);
    const std::string rec = (home / "R.mcap").string();
    const int status = test::run_mixpilot(
        MIXPILOT_BINARY, "fly --scenario '" + kHelix + "' --pilot reckless --headless --record '" +
                             rec + "'",
        home);
    EXPECT_EQ(status, 0) << test::read_file(home / "out.txt");
    return rec;
  }();
  return path;
}

// The novice's whole flight of mi_helix, recorded the same way: many events, more than the
// panel shows at once.
const std::string& novice_recording() {
  static const std::string path = [] {
    const fs::path home = test::fresh_path("debrief", "novice");
    fs::create_directories(home);
    const std::string rec = (home / "N.mcap").string();
    const int status = test::run_mixpilot(
        MIXPILOT_BINARY, "fly --scenario '" + kHelix + "' --pilot novice --headless --record '" +
                             rec + "'",
        home);
    EXPECT_EQ(status, 0) << test::read_file(home / "out.txt");
    return rec;
  }();
  return path;
}

RecordingContents read(const std::string& path) {
  std::string error;
  auto rec = read_recording(path, error);
  EXPECT_TRUE(rec) << error;
  return rec ? std::move(*rec) : RecordingContents{};
}

double channel(const ModeChannelsMsg& m, const char* name) {
  for (std::size_t i = 0; i < m.names.size(); ++i)
    if (m.names[i] == name) return m.values[i];
  ADD_FAILURE() << "no channel " << name << " at step " << m.step;
  return 0.0;
}

// ---- the events recomputed from the recorded channels --------------------------------------

// An event as the recorded channels say it: its kind, first step, the first step after it,
// and its extreme (lowest λ, least clearance) or its steps.
struct Expected {
  DebriefKind kind;
  std::int64_t start, end;
  double extreme = 0.0;
  std::int64_t steps = 0;
};

// The runs of steps 0..K-1 where on(k), an on step joining the run before it when at most
// `join` steps after that run's last on step (join 1: only the next step); each run as its first
// and last on step, and how many steps were on.
struct Run {
  std::int64_t first, last, on;
};
std::vector<Run> runs(std::int64_t K, const std::function<bool(std::int64_t)>& on,
                      std::int64_t join) {
  std::vector<Run> out;
  for (std::int64_t k = 0; k < K; ++k) {
    if (!on(k)) continue;
    if (!out.empty() && k - out.back().last <= join) {
      out.back().last = k;
      ++out.back().on;
    } else {
      out.push_back({k, k, 1});
    }
  }
  return out;
}

// SPEC §10 over the recording: takeover λ < 0.5 until 0.5 s at or above it; near miss clearance
// below the vehicle radius (the centre within two radii of a surface) without contact, until
// 0.5 s clear; collision while in contact; fallbacks and safe holds joined when less than 0.5 s
// apart; input lost while lost; the vehicle lost where flagged.
std::vector<Expected> expected_events(const RecordingContents& rec, double vehicle_radius) {
  const auto K = std::int64_t(rec.states.size());
  const double dt = 1e-9 * double(rec.control_period_ns);
  const auto hold = std::int64_t(std::ceil(0.5 / dt));
  const auto ev = [&](std::int64_t k) { return rec.channels[std::size_t(k)].events; };
  const auto clearance = [&](std::int64_t k) {
    return channel(rec.channels[std::size_t(k)], "clearance");
  };
  const auto contact = [&](std::int64_t k) {
    return (ev(k) & kEventCollision) != 0 || clearance(k) < 0.0;
  };
  std::vector<Expected> out;
  // Takeovers: where something decided λ (not the initial one of the first step).
  const auto low = [&](std::int64_t k) {
    const LambdaReasonMsg& r = rec.reasons[std::size_t(k)];
    return (r.node >= 0 || r.cap != 0) && rec.lambda[std::size_t(k)].lambda < 0.5;
  };
  for (const Run& r : runs(K, low, hold)) {
    double lowest = 1.0;
    for (std::int64_t k = r.first; k <= r.last; ++k)
      if (low(k)) lowest = std::min(lowest, rec.lambda[std::size_t(k)].lambda);
    out.push_back({DebriefKind::takeover, r.first, r.last + 1, lowest, r.last + 1 - r.first});
  }
  for (const Run& r : runs(K, [&](std::int64_t k) { return clearance(k) < vehicle_radius; }, hold)) {
    bool touched = false;
    double least = 1e9;
    for (std::int64_t k = r.first; k <= r.last; ++k) {
      touched = touched || contact(k);
      if (clearance(k) < vehicle_radius) least = std::min(least, clearance(k));
    }
    if (!touched) out.push_back({DebriefKind::near_miss, r.first, r.last + 1, least, r.last + 1 - r.first});
  }
  for (const Run& r : runs(K, contact, 1)) {
    double deepest = 1e9;
    for (std::int64_t k = r.first; k <= r.last; ++k) deepest = std::min(deepest, clearance(k));
    out.push_back({DebriefKind::collision, r.first, r.last + 1, deepest, r.last + 1 - r.first});
  }
  for (const Run& r : runs(K, [&](std::int64_t k) { return (ev(k) & (kEventFallback | kEventOverrun)) != 0; }, hold))
    out.push_back({DebriefKind::fallback, r.first, r.last + 1, 0.0, r.on});
  for (const Run& r : runs(K, [&](std::int64_t k) { return (ev(k) & kEventSafeHold) != 0; }, hold))
    out.push_back({DebriefKind::safe_hold, r.first, r.last + 1, 0.0, r.on});
  for (const Run& r : runs(K, [&](std::int64_t k) { return rec.pilot[std::size_t(k)].input_state == 1; }, 1))
    out.push_back({DebriefKind::input_lost, r.first, r.last + 1, 0.0, r.last + 1 - r.first});
  for (std::int64_t k = 0; k < K; ++k)
    if (ev(k) & kEventLost) out.push_back({DebriefKind::lost, k, k, 0.0, 1});
  std::sort(out.begin(), out.end(), [](const Expected& a, const Expected& b) {
    return a.start != b.start ? a.start < b.start : a.kind < b.kind;
  });
  return out;
}

// The builder's events ordered as expected_events() orders them.
std::vector<DebriefEvent> by_start(std::vector<DebriefEvent> events) {
  std::stable_sort(events.begin(), events.end(), [](const DebriefEvent& a, const DebriefEvent& b) {
    return a.start_step != b.start_step ? a.start_step < b.start_step : a.kind < b.kind;
  });
  return events;
}

// A replay of `path` flown through a session with its check; the replay's telemetry.
struct Replayed {
  std::vector<Telemetry> steps;
  DebriefSettings settings;
  bool matches = false;
  std::string difference;
};
Replayed replay(const std::string& path) {
  Replayed out;
  std::string error;
  const RecordingContents rec = read(path);
  const std::string* scenario = embedded_scenario(rec, path, error);
  EXPECT_TRUE(scenario) << error;
  if (!scenario) return out;
  auto mode = replay_mode(rec, path, *scenario, kHelix, std::nullopt, error);
  EXPECT_TRUE(mode) << error;
  if (!mode) return out;
  out.settings = debrief_settings(*mode);
  struct Keep : TelemetrySink {
    std::vector<Telemetry>* steps;
    void on_sample(const Telemetry& s) override { steps->push_back(s); }
  } keep;
  keep.steps = &out.steps;
  ReplayCheck check(rec);
  Session session(*mode);
  session.add_sink(&check);
  session.add_sink(&keep);
  session.run();
  out.matches = check.matches(mode->steps_done());
  out.difference = check.first_difference(mode->steps_done());
  return out;
}

const char* kind_name(DebriefKind k) { return to_string(k); }

// (a) Each event of the reckless pilot's recording with the right time and kind: the runs of
// the recorded channels are the recorded /rosout messages (stamp = start, function = kind) and
// the replay's rebuilt list, which says the same words.
TEST(Debrief, TheRecklessPilotsEventsAreThoseOfItsRecordedChannels) {
  const RecordingContents rec = read(reckless_recording());
  ASSERT_EQ(rec.states.size(), 2000u);
  ASSERT_EQ(rec.channels.size(), rec.states.size());
  const double dt = 1e-9 * double(rec.control_period_ns);
  const Replayed r = replay(reckless_recording());
  ASSERT_TRUE(r.matches) << r.difference;
  ASSERT_EQ(r.settings.near_miss_margin, 0.3) << "mi_helix's vehicle radius";
  const std::vector<Expected> want = expected_events(rec, 0.3);
  // The reckless pilot hands the planner the flight and flies close to the central column.
  ASSERT_TRUE(std::any_of(want.begin(), want.end(), [](const Expected& e) { return e.kind == DebriefKind::takeover; }));
  ASSERT_TRUE(std::any_of(want.begin(), want.end(), [](const Expected& e) { return e.kind == DebriefKind::near_miss; }));

  const std::vector<DebriefEvent> rebuilt = by_start(debrief_of(r.steps, r.steps.size(), r.settings));
  ASSERT_EQ(rebuilt.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    SCOPED_TRACE(std::string(kind_name(want[i].kind)) + " from step " + std::to_string(want[i].start));
    const DebriefEvent& e = rebuilt[i];
    EXPECT_EQ(e.kind, want[i].kind);
    EXPECT_EQ(e.start_step, want[i].start);
    EXPECT_EQ(e.end_step, want[i].end);
    EXPECT_DOUBLE_EQ(e.start, double(want[i].start) * dt);
    EXPECT_EQ(e.extreme, want[i].extreme);
    EXPECT_EQ(e.steps, want[i].steps);
    EXPECT_EQ(e.until_end, e.end_step == std::int64_t(rec.states.size()));
  }

  // The recording's /rosout: one message per event, stamped at its start, its kind the
  // function, WARN (takeover, near miss) and the words the replay's list says.
  ASSERT_EQ(rec.log.size(), want.size());
  std::vector<LogMsg> log = rec.log;
  std::stable_sort(log.begin(), log.end(), [&](const LogMsg& a, const LogMsg& b) {
    return ros_time_to_ns(a.stamp) != ros_time_to_ns(b.stamp)
               ? ros_time_to_ns(a.stamp) < ros_time_to_ns(b.stamp)
               : std::string(a.function) < std::string(b.function);
  });
  for (std::size_t i = 0; i < want.size(); ++i) {
    const LogMsg& m = log[i];
    const DebriefEvent& e = rebuilt[i];
    EXPECT_EQ(ros_time_to_ns(m.stamp), std::uint64_t(want[i].start) * rec.control_period_ns);
    EXPECT_EQ(m.function, kind_name(want[i].kind));
    EXPECT_EQ(m.name, "mixpilot.debrief");
    EXPECT_EQ(m.level, std::uint8_t(LogLevel::warn));
    EXPECT_EQ(m.file, "");
    EXPECT_EQ(m.line, 0u);
    EXPECT_EQ(m.msg, describe(e, r.settings.ball_radius));
  }
  // In words: the takeover of the whole flight says its lowest λ and why.
  const auto takeover = std::find_if(log.begin(), log.end(), [](const LogMsg& m) { return m.function == "takeover"; });
  ASSERT_NE(takeover, log.end());
  EXPECT_EQ(takeover->msg.rfind("planner took over for the last ", 0), 0u) << takeover->msg;
  EXPECT_NE(takeover->msg.find("(lowest λ 0.15): you would "), std::string::npos) << takeover->msg;
}

// (b) The independent reader (npm @mcap/core and Foxglove's ros2msg parser and CDR reader,
// tests/mcap_check/check.mjs) decodes /rosout as rcl_interfaces/msg/Log: every message as the
// events say, each logged at the step that closed its event (a takeover 0.5 s after λ came
// back, or the flight's last step).
TEST(Debrief, TheIndependentReaderDecodesTheLogTopic) {
  const std::string node = MIXPILOT_NODE;
  if (node.empty()) GTEST_SKIP() << "node not found at configure time";
  const fs::path check_dir = fs::path(MIXPILOT_SOURCE_DIR) / "tests" / "mcap_check";
  ASSERT_TRUE(fs::exists(check_dir / "node_modules" / "@mcap" / "core"))
      << "run `npm ci --prefix tests/mcap_check` (CTest fixture mcap_check_npm_ci)";
  const RecordingContents rec = read(reckless_recording());
  const Replayed r = replay(reckless_recording());
  const std::vector<DebriefEvent> events = debrief_of(r.steps, r.steps.size(), r.settings);
  ASSERT_EQ(events.size(), rec.log.size());
  std::string out;
  {
    const std::string cmd = "'" + node + "' '" + (check_dir / "check.mjs").string() + "' '" +
                            reckless_recording() + "' --all /rosout 2>&1";
    std::FILE* p = ::popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    ::pclose(p);
  }
  const auto has = [&](const std::string& s) {
    EXPECT_NE(out.find(s), std::string::npos) << "missing " << s << " in\n" << out.substr(0, 3000);
  };
  has(R"({"topic":"/rosout","schemaName":"rcl_interfaces/msg/Log","schemaEncoding":"ros2msg","messageEncoding":"cdr","messages":)" +
      std::to_string(events.size()) + R"(,"statistics":)" + std::to_string(events.size()) + "}");
  // In the order they were logged: the order the events closed.
  std::string all = R"("all":{"/rosout":[)";
  for (std::size_t i = 0; i < events.size(); ++i) {
    const DebriefEvent& e = events[i];
    // Closed 0.5 s after its end, or at the end of the flight (its last step).
    const auto hold = std::int64_t(std::ceil(0.5 / r.settings.dt));
    const std::int64_t closed = e.until_end || e.end_step + hold - 1 >= std::int64_t(rec.states.size())
                                    ? std::int64_t(rec.states.size()) - 1
                                    : e.end_step + hold - 1;
    EXPECT_EQ(e.closed_step, closed) << i;
    const RosTime stamp = ros_time_from_ns(std::uint64_t(e.start_step) * rec.control_period_ns);
    char item[640];
    std::snprintf(item, sizeof item,
                  R"(%s{"logTime":%llu,"message":{"stamp":{"sec":%d,"nanosec":%u},"level":30,)"
                  R"("name":"mixpilot.debrief","msg":"%s","file":"","function":"%s","line":0}})",
                  i ? "," : "",
                  static_cast<unsigned long long>(std::uint64_t(closed) * rec.control_period_ns),
                  stamp.sec, stamp.nanosec, describe(e, r.settings.ball_radius).c_str(),
                  kind_name(e.kind));
    all += item;
  }
  has(all + "]}");
}

using test::ScriptedPad;

// (c) The gamepad unplugged at step 100 and plugged back at 300 (SPEC §6): an input lost event
// from 1.5 s to 4.5 s ("back"), recorded as a warning; the planner's takeover over it says the
// input was lost.
TEST(Debrief, AScriptedUnplugGivesInputLostAndBack) {
  ScriptedPad pad;
  pad.r.alive_ns = input::steady_ns() + 3'600'000'000'000;  // alive throughout
  pad.from = 100;
  pad.to = 300;
  input::InputSettings settings;
  ModeRequest request;
  request.duration = 7.5;
  request.pilot_source = std::make_unique<input::DevicePilot>(
      pad, settings, 0.015, models::MikroKopter().hover_speed());
  std::string error;
  auto mode = load_mode(kHelix, std::move(request), error);
  ASSERT_TRUE(mode) << error;
  const std::string path = test::fresh_path("debrief", "unplug.mcap").string();
  RecordingSink sink;
  SessionInfo info{"mixed_initiative", "", kHelix, 1, "gamepad"};
  ASSERT_TRUE(read_text_file(kHelix, info.scenario, error)) << error;
  ASSERT_TRUE(sink.open(path, *mode, info, error)) << error;
  Session session(*mode);
  session.add_sink(&sink);
  session.run();
  ASSERT_TRUE(sink.close(error)) << error;

  const std::vector<DebriefEvent>& events = sink.events();
  const auto lost = std::find_if(events.begin(), events.end(), [](const DebriefEvent& e) {
    return e.kind == DebriefKind::input_lost;
  });
  ASSERT_NE(lost, events.end());
  EXPECT_EQ(lost->start_step, 100);
  EXPECT_EQ(lost->end_step, 300) << "back when the gamepad is";
  EXPECT_FALSE(lost->until_end);
  EXPECT_EQ(lost->closed_step, 300);
  EXPECT_EQ(describe(*lost, 0.175), "input lost for 3.0 s: the planner flew until it came back");
  EXPECT_EQ(std::count_if(events.begin(), events.end(),
                          [](const DebriefEvent& e) { return e.kind == DebriefKind::input_lost; }),
            1);
  // The planner's takeover holds the loss (λ = 0 from the unplug) and says why.
  const auto takeover = std::find_if(events.begin(), events.end(), [](const DebriefEvent& e) {
    return e.kind == DebriefKind::takeover && e.start_step <= 100 && e.end_step >= 300;
  });
  ASSERT_NE(takeover, events.end());
  EXPECT_EQ(takeover->extreme, 0.0);
  EXPECT_EQ(takeover->reason.cap, LambdaCap::input_lost);
  EXPECT_NE(describe(*takeover, 0.175).find("(lowest λ 0.00): the input was lost"), std::string::npos)
      << describe(*takeover, 0.175);

  const RecordingContents rec = read(path);
  const auto logged = std::find_if(rec.log.begin(), rec.log.end(), [](const LogMsg& m) {
    return m.function == "input lost";
  });
  ASSERT_NE(logged, rec.log.end());
  EXPECT_EQ(ros_time_to_ns(logged->stamp), 100u * rec.control_period_ns);
  EXPECT_EQ(logged->level, std::uint8_t(LogLevel::warn));
  EXPECT_EQ(logged->msg, "input lost for 3.0 s: the planner flew until it came back");
}

// `in` without the /rosout topic: a recording made before it existed.
void drop_topic(const std::string& in, const std::string& out, const std::string& topic) {
  std::string error;
  const auto file = read_mcap(in, error);
  ASSERT_TRUE(file) << error;
  McapWriter w;
  ASSERT_TRUE(w.open(out, error)) << error;
  std::map<std::uint16_t, std::uint16_t> channel;  // old id → new id
  for (const auto& [id, ch] : file->channels) {
    if (ch.topic == topic) continue;
    const McapSchema& s = file->schemas.at(ch.schema_id);
    channel[id] = w.add_channel(w.add_schema(s.name, s.encoding, s.data), ch.topic,
                                ch.message_encoding, ch.metadata);
  }
  for (const McapMetadata& m : file->metadata)
    if (m.name == "mixpilot") w.write_metadata(m.name, m.metadata);
  for (const McapMessage& m : file->messages) {
    const auto it = channel.find(m.channel_id);
    if (it != channel.end()) {
      ASSERT_TRUE(w.write_message(it->second, m.sequence, m.log_time, m.publish_time, file->data(m)));
    }
  }
  for (const McapMetadata& m : file->metadata)
    if (m.name != "mixpilot") w.write_metadata(m.name, m.metadata);
  ASSERT_TRUE(w.close(error)) << error;
}

// (d) A recording older than /rosout (and than the clearance channel: a near miss needs the
// replay's own) replays bit for bit, and its replay rebuilds the same list from the telemetry.
TEST(Debrief, ARecordingWithoutTheLogTopicReplaysAndRebuildsItsList) {
  const std::string old = test::fresh_path("debrief", "old.mcap").string();
  drop_topic(reckless_recording(), old, "/rosout");
  const RecordingContents without = read(old);
  EXPECT_TRUE(without.log.empty());
  EXPECT_EQ(without.message_counts.count("/rosout"), 0u);
  const Replayed now = replay(reckless_recording()), before = replay(old);
  ASSERT_TRUE(before.matches) << before.difference;
  EXPECT_EQ(debrief_of(before.steps, before.steps.size(), before.settings),
            debrief_of(now.steps, now.steps.size(), now.settings));
}

// Telemetry of a mixed-initiative step for the builder: λ decided by the PH index, clear of
// everything, nothing flagged.
Telemetry step(std::int64_t k, double lambda = 0.9, double clearance = 1.0, std::uint32_t events = 0) {
  Telemetry s;
  s.mode = ModeKind::mixed_initiative;
  s.step = k;
  s.t = double(k) * 0.01;
  s.solved = true;
  s.lambda = lambda;
  s.reason.node = 4;
  s.reason.ahead = 0.04;
  s.reason.d_res = 0.2;
  s.reason.ph_index = lambda;
  s.clearance = clearance;
  s.events = events;
  return s;
}

// Scripted steps of every kind (Δt 10 ms, so the hold of 0.5 s is 50 steps), into `b`.
void script(DebriefBuilder& b) {
  std::int64_t k = 0;
  const auto add = [&](int n, const std::function<Telemetry(std::int64_t)>& make) {
    for (int i = 0; i < n; ++i, ++k) b.add(make(k));
  };
  add(1, [](std::int64_t j) {  // the first step: the initial λ, which nothing decided
    Telemetry s = step(j, 0.5);
    s.reason = LambdaReason{};
    return s;
  });
  add(9, [](std::int64_t j) { return step(j); });
  add(20, [](std::int64_t j) { return step(j, 0.3 + 0.001 * double(j)); });  // 10 .. 29 below
  add(40, [](std::int64_t j) { return step(j); });                           // 0.4 s above
  add(10, [](std::int64_t j) { return step(j, 0.2); });                      // 70 .. 79 below
  add(50, [](std::int64_t j) { return step(j); });                           // 0.5 s: it ends
  // 130: an approach to 0.2 m, away for 0.1 s, back to 0.12 m and into contact (148 .. 151).
  add(5, [](std::int64_t j) { return step(j, 0.9, 0.2); });
  add(10, [](std::int64_t j) { return step(j, 0.9, 0.6); });
  add(3, [](std::int64_t j) { return step(j, 0.9, 0.12); });
  add(4, [](std::int64_t j) {
    return step(j, 0.9, -0.05 + 0.01 * double(j - 148), j == 148 ? kEventCollision : 0u);
  });
  add(60, [](std::int64_t j) { return step(j, 0.9, 0.8); });
  // 212: a near miss alone, 0.2 s, down to 0.244 m.
  add(20, [](std::int64_t j) { return step(j, 0.9, 0.25 - 0.001 * double(j % 7)); });
  add(60, [](std::int64_t j) { return step(j); });
  // 292, 323, 353: fallbacks less than 0.5 s apart (an overrun among them) are one run.
  add(1, [](std::int64_t j) { return step(j, 0.9, 1.0, kEventFallback); });
  add(30, [](std::int64_t j) { return step(j); });
  add(1, [](std::int64_t j) { return step(j, 0.9, 1.0, kEventFallback | kEventOverrun); });
  add(29, [](std::int64_t j) { return step(j); });
  add(1, [](std::int64_t j) { return step(j, 0.9, 1.0, kEventOverrun); });
  add(60, [](std::int64_t j) { return step(j); });
  b.mark("watch the column");  // at step 413
  // 414 .. 423 the input lost (λ 0); 424 .. 433 back, the safe controller flying; the vehicle
  // lost at the last step.
  add(10, [](std::int64_t j) {
    Telemetry s = step(j, 0.0, 1.0, j == 414 ? kEventInputLost : 0u);
    s.pilot.input = InputState::lost;
    s.reason.cap = LambdaCap::input_lost;
    return s;
  });
  add(10, [](std::int64_t j) {
    Telemetry s = step(j, 0.0, 1.0, kEventSafeHold | (j == 433 ? kEventLost : 0u));
    s.pilot.input = InputState::recentre;
    s.reason.cap = LambdaCap::safe_hold;
    return s;
  });
  b.finish();
}

// (e) The builder on scripted steps: a dip back under λ_T within 0.5 s continues a takeover; an
// approach that touched is a collision, not a near miss; fallbacks 0.3 s apart are one run; a
// marker; input lost and back; the vehicle lost; what is open at the end lasts to it. In the
// order they closed, in words.
TEST(Debrief, TheBuilderReadsEachKindFromTheSteps) {
  DebriefSettings set;
  set.dt = 0.01;
  set.near_miss_margin = 0.3;
  set.ball_radius = 0.175;
  DebriefBuilder b(set);
  script(b);
  const std::vector<DebriefEvent>& e = b.events();
  ASSERT_EQ(e.size(), 9u);
  EXPECT_EQ(b.dropped(), 0);
  struct Want {
    DebriefKind kind;
    std::int64_t start, end, closed;
    bool until_end;
    const char* words;
  };
  const Want want[] = {
      {DebriefKind::takeover, 10, 80, 129, false,
       "planner took over for 0.70 s (lowest λ 0.20): you would leave the ball by 0.03 m in "
       "0.04 s"},
      {DebriefKind::collision, 148, 152, 152, false, "collision: in contact for 0.04 s, 0.050 m deep"},
      {DebriefKind::near_miss, 212, 232, 281, false,
       "near miss for 0.20 s: 0.244 m of clearance at the closest"},
      {DebriefKind::fallback, 292, 354, 403, false,
       "3 fallbacks in 0.62 s: the MPC applied its previous plan"},
      {DebriefKind::marker, 413, 413, 413, false, "marker: watch the column"},
      {DebriefKind::input_lost, 414, 424, 424, false,
       "input lost for 0.10 s: the planner flew until it came back"},
      {DebriefKind::lost, 433, 433, 433, false, "vehicle lost: the flight ended"},
      {DebriefKind::takeover, 414, 434, 433, true,
       "planner took over for the last 0.20 s (lowest λ 0.00): the input was lost"},
      {DebriefKind::safe_hold, 424, 434, 433, true,
       "safe hold for the last 0.10 s: the MPC fell behind, the safe controller flew"},
  };
  for (std::size_t i = 0; i < e.size(); ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(e[i].kind, want[i].kind);
    EXPECT_EQ(e[i].start_step, want[i].start);
    EXPECT_EQ(e[i].end_step, want[i].end);
    EXPECT_EQ(e[i].closed_step, want[i].closed);
    EXPECT_EQ(e[i].until_end, want[i].until_end);
    EXPECT_DOUBLE_EQ(e[i].start, 0.01 * double(want[i].start));
    EXPECT_DOUBLE_EQ(e[i].end, 0.01 * double(want[i].end));
    EXPECT_EQ(describe(e[i], set.ball_radius), want[i].words);
  }
  // The takeover's lowest λ and the reason there; the contact's depth; the near miss's least
  // clearance.
  EXPECT_EQ(e[0].extreme, 0.2);
  EXPECT_DOUBLE_EQ(e[0].extreme_t, 0.7);
  EXPECT_EQ(e[0].reason.d_res, 0.2);
  EXPECT_EQ(e[1].extreme, -0.05);
  EXPECT_DOUBLE_EQ(e[2].extreme, 0.244);
  EXPECT_EQ(e[3].steps, 3);
  EXPECT_EQ(e[7].reason.cap, LambdaCap::input_lost);
  EXPECT_EQ(e[7].input, InputState::lost);
  EXPECT_EQ(e[8].steps, 10);
  EXPECT_EQ(e[4].note.view(), "watch the column");
  EXPECT_EQ(log_level(DebriefKind::takeover), LogLevel::warn);
  EXPECT_EQ(log_level(DebriefKind::collision), LogLevel::error);
  EXPECT_EQ(log_level(DebriefKind::lost), LogLevel::error);
  EXPECT_EQ(log_level(DebriefKind::marker), LogLevel::info);

  // A full list counts what it cannot keep.
  set.capacity = 2;
  DebriefBuilder small(set);
  script(small);
  EXPECT_EQ(small.events().size(), 2u);
  EXPECT_EQ(small.dropped(), 7);
  EXPECT_EQ(small.events()[1], e[1]);

  // Words never end in a cut character; a marker's text is cut at a character too.
  char buf[48];
  const std::size_t n = describe(e[0], 0.175, buf, sizeof buf);
  EXPECT_EQ(std::string(buf, n), "planner took over for 0.70 s (lowest λ 0.20): ");
  const std::size_t m = describe(e[0], 0.175, buf, 39);  // 38 bytes: λ's first byte only
  EXPECT_EQ(std::string(buf, m), "planner took over for 0.70 s (lowest ");
  DebriefNote note;
  note.assign(std::string(94, 'a') + "λλ");
  EXPECT_EQ(note.view(), std::string(94, 'a'));
}

// The window's replay of the reckless pilot's recording (the app through the headless
// renderer): the Debrief panel lists the recorded events in words by their start; ] jumps to
// the next and selects it (highlighted in the list, its span on the timeline), [ back; a click
// on a row selects that one; nothing overlaps or is cut. With MIXPILOT_SHOT_DIR set it saves
// debrief_<percent>.png.
class DebriefScreen : public testing::TestWithParam<float> {};

std::string without_spaces(std::string s) {
  std::erase(s, ' ');
  return s;
}

// The text the window `name` (or its child windows) drew in the last frame, read back from the
// draw lists: each glyph is a quad whose texture corners are those of a glyph of the font atlas
// (spaces draw nothing; other characters than ASCII read as '?').
std::string drawn_text(const char* name) {
  std::map<std::array<float, 4>, unsigned> glyphs;
  for (const ImFont* f : ImGui::GetIO().Fonts->Fonts)
    for (const ImFontGlyph& g : f->Glyphs)
      if (g.Visible) glyphs[{g.U0, g.V0, g.U1, g.V1}] = g.Codepoint;
  std::string out;
  for (const ImGuiWindow* w : GImGui->Windows) {
    if (!w->Active || (std::string(w->Name) != name && std::string(w->Name).rfind(std::string(name) + "/", 0) != 0))
      continue;
    const ImVector<ImDrawVert>& v = w->DrawList->VtxBuffer;
    for (int i = 0; i + 3 < v.Size;) {
      const auto it = glyphs.find({v[i].uv.x, v[i].uv.y, v[i + 2].uv.x, v[i + 2].uv.y});
      if (it == glyphs.end()) {
        ++i;
        continue;
      }
      out += it->second < 0x80 ? char(it->second) : '?';
      i += 4;
    }
  }
  return out;
}

std::string ascii(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) out += char(c);
    else if ((c & 0xC0) == 0xC0) out += '?';  // a character's first byte
  }
  return out;
}

TEST_P(DebriefScreen, ThePanelListsTheEventsAndTheBracketsStepThroughThem) {
  const float scale = GetParam();
  const int W = 1280, H = 720;
  cli::Offscreen screen;
  std::string error;
  if (!screen.open(W, H, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
  const RecordingContents rec = read(reckless_recording());
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = reckless_recording();
  o.history = "off";
  cli::Trainer app(o);
  ASSERT_TRUE(app.open_replay(reckless_recording(), error)) << error;
  app.load_replay();
  const auto frame = [&] { screen.frame([&] { app.build_frame(0.0); }, 1e-4f); };
  const auto key = [&](ui::Key k) {
    ui::set_key(ImGui::GetIO(), k, true);
    frame();
    ui::set_key(ImGui::GetIO(), k, false);
    frame();
  };
  frame();
  frame();
  ASSERT_TRUE(app.run_info().replay);
  const ui::ReplayInfo& r = *app.run_info().replay;
  ASSERT_TRUE(r.events_ready);
  EXPECT_EQ(app.replay()->mismatch(), "");
  // The rows: the recorded /rosout, by start.
  ASSERT_EQ(r.events.size(), rec.log.size());
  for (const ui::DebriefRow& row : r.events) {
    const auto logged = std::find_if(rec.log.begin(), rec.log.end(), [&](const LogMsg& m) {
      return m.msg == row.text;
    });
    ASSERT_NE(logged, rec.log.end()) << row.text;
    EXPECT_DOUBLE_EQ(row.t, 1e-9 * double(ros_time_to_ns(logged->stamp)));
  }
  EXPECT_TRUE(std::is_sorted(r.events.begin(), r.events.end(),
                             [](const ui::DebriefRow& a, const ui::DebriefRow& b) { return a.t < b.t; }));
  const std::string shown = drawn_text("Debrief");
  for (const ui::DebriefRow& row : r.events)
    EXPECT_NE(shown.find(without_spaces(ascii(row.text))), std::string::npos)
        << row.text << " not in " << shown;
  EXPECT_EQ(r.selected, -1);

  // ] from the start: the first event, selected; again: the second; [ back to the first.
  key(ui::Key::right_bracket);
  EXPECT_EQ(r.selected, 0);
  EXPECT_DOUBLE_EQ(r.t, r.events[0].t);
  key(ui::Key::right_bracket);
  EXPECT_EQ(r.selected, 1);
  EXPECT_DOUBLE_EQ(r.t, r.events[1].t);
  EXPECT_NEAR(app.shown_time(), r.events[1].t, 1e-9);
  key(ui::Key::left_bracket);
  EXPECT_EQ(r.selected, 0);
  EXPECT_DOUBLE_EQ(r.t, r.events[0].t);
  // The selected row is highlighted: its kind's bar at the list's left edge.
  {
    const auto px = screen.pixels();
    const ImGuiWindow* panel = ImGui::FindWindowByName("Debrief");
    ASSERT_TRUE(panel);
    const ImU32 c = ui::event_colour(r.events[0].kind);
    int bar = 0;
    const ImGuiWindow* rows = nullptr;  // the list: the panel's child window
    for (const ImGuiWindow* w : GImGui->Windows)
      if (w->ParentWindow == panel && w->Active) rows = w;
    ASSERT_TRUE(rows);
    for (int y = int(rows->Pos.y); y < int(rows->Pos.y + rows->Size.y); ++y)
      for (int x = int(rows->Pos.x); x < int(rows->Pos.x + ui::scaled(3)); ++x) {
        const std::uint8_t* p = &px[(std::size_t(y) * W + std::size_t(x)) * 4];
        bar += std::abs(p[0] - int(c & 0xFF)) <= 8 && std::abs(p[1] - int((c >> 8) & 0xFF)) <= 8 &&
               std::abs(p[2] - int((c >> 16) & 0xFF)) <= 8;
      }
    EXPECT_GT(bar, int(ImGui::GetTextLineHeight())) << "no highlight bar by the selected row";
  }
  EXPECT_TRUE(test::layout_problems().empty()) << test::layout_problems().front();

  // A click on the last row selects it and moves the playhead there.
  const ImGuiWindow* panel = ImGui::FindWindowByName("Debrief");
  ASSERT_TRUE(panel);
  const ImGuiWindow* list = nullptr;
  for (const ImGuiWindow* w : GImGui->Windows)
    if (w->ParentWindow == panel && w->Active) list = w;
  ASSERT_TRUE(list);
  ImGuiIO& io = ImGui::GetIO();
  // The middle of the last row's first line: the list ends one item spacing below that row.
  io.MousePos = ImVec2(0.5f * (list->Rect().Min.x + list->Rect().Max.x),
                       list->Rect().Max.y - ImGui::GetStyle().ItemSpacing.y -
                           0.5f * ImGui::GetTextLineHeight());
  frame();
  io.MouseDown[0] = true;
  frame();
  io.MouseDown[0] = false;
  frame();
  io.MousePos = ImVec2(-1, -1);
  EXPECT_EQ(r.selected, int(r.events.size()) - 1);
  EXPECT_DOUBLE_EQ(r.t, r.events.back().t);
  frame();  // the HUD fits what it says at the new time (ImGui sizes a window a frame late)
  frame();
  for (const std::string& problem : test::layout_problems()) ADD_FAILURE() << problem;
  if (const char* dir = std::getenv("MIXPILOT_SHOT_DIR"))
    (void)cli::write_file(std::string(dir) + "/debrief_" + std::to_string(int(scale * 100)) + ".png",
                          screen.png(), true, error);

  // L hides the panel and shows it again.
  key(ui::kDebriefKey);
  EXPECT_FALSE(app.ui_state().show_debrief);
  const ImGuiWindow* hidden = ImGui::FindWindowByName("Debrief");
  EXPECT_TRUE(!hidden || !hidden->Active);
  key(ui::kDebriefKey);
  EXPECT_TRUE(app.ui_state().show_debrief);
}

// The novice's replay lists more events than the panel holds: the list scrolls (nothing cut), and
// ] keeps the selected row in sight.
TEST_P(DebriefScreen, ALongListScrollsToTheSelectedEvent) {
  const float scale = GetParam();
  cli::Offscreen screen;
  std::string error;
  if (!screen.open(1280, 720, error, scale)) GTEST_SKIP() << "no EGL device: " << error;
  cli::FlyOptions o;
  o.replay = true;
  o.pilot = novice_recording();
  o.history = "off";
  cli::Trainer app(o);
  ASSERT_TRUE(app.open_replay(novice_recording(), error)) << error;
  app.load_replay();
  const auto frame = [&] { screen.frame([&] { app.build_frame(0.0); }, 1e-4f); };
  frame();
  frame();
  const ui::ReplayInfo& r = *app.run_info().replay;
  ASSERT_GE(r.events.size(), 10u) << "the novice's flight has many events";
  const auto list = [] {
    const ImGuiWindow* panel = ImGui::FindWindowByName("Debrief");
    for (const ImGuiWindow* w : GImGui->Windows)
      if (panel && w->ParentWindow == panel && w->Active) return w;
    return static_cast<const ImGuiWindow*>(nullptr);
  };
  ASSERT_TRUE(list());
  EXPECT_TRUE(list()->ScrollbarY) << "the list holds more than it shows";
  EXPECT_TRUE(test::layout_problems().empty()) << test::layout_problems().front();
  for (std::size_t i = 0; i < r.events.size(); ++i) {
    ui::set_key(ImGui::GetIO(), ui::Key::right_bracket, true);
    frame();
    ui::set_key(ImGui::GetIO(), ui::Key::right_bracket, false);
    frame();
  }
  EXPECT_EQ(r.selected, int(r.events.size()) - 1);
  frame();
  EXPECT_GT(list()->Scroll.y, 0.0f) << "the list scrolled to the last event";
  EXPECT_EQ(list()->Scroll.y, list()->ScrollMax.y);
  EXPECT_TRUE(test::layout_problems().empty()) << test::layout_problems().front();
}

INSTANTIATE_TEST_SUITE_P(Scales, DebriefScreen, testing::Values(1.0f, 1.5f));

// What the transport asks for: E exports the selected event with 5 s either side (within the
// recording), the playhead ± 5 s without a selection; the help sheet names L.
TEST(Debrief, ExportClipSavesTheSelectedEvent) {
  ui::ReplayInfo r;
  r.duration = 30.0;
  r.t = 20.0;
  r.events_ready = true;
  r.events = {{2.0, 4.5, DebriefKind::takeover, "planner took over", {}},
              {12.0, 12.5, DebriefKind::near_miss, "near miss", {}},
              {27.0, 29.0, DebriefKind::near_miss, "near miss", {}}};
  const ui::ExportClip none = ui::clip_of(r);
  EXPECT_EQ(none.from, 15.0);
  EXPECT_EQ(none.to, 25.0);
  r.selected = 0;
  EXPECT_EQ(ui::clip_of(r).from, 0.0);
  EXPECT_EQ(ui::clip_of(r).to, 9.5);
  r.selected = 2;
  EXPECT_EQ(ui::clip_of(r).from, 22.0);
  EXPECT_EQ(ui::clip_of(r).to, 30.0);
  // ] and [ from a playhead between events.
  EXPECT_EQ(ui::event_after(r.events, 5.0, +1), 1);
  EXPECT_EQ(ui::event_after(r.events, 12.0, +1), 2);
  EXPECT_EQ(ui::event_after(r.events, 12.0, -1), 0);
  EXPECT_EQ(ui::event_after(r.events, 27.0, +1), -1);
  EXPECT_EQ(ui::event_after(r.events, 2.0, -1), -1);

  cli::Offscreen screen;
  std::string error;
  if (!screen.open(1280, 720, error)) GTEST_SKIP() << "no EGL device: " << error;
  ui::Scene scene;
  ui::History h;
  ui::UiState st;
  ui::RunInfo run;
  run.state = ui::RunState::replay;
  run.replay = &r;
  r.selected = 1;
  ui::Requests out;
  const auto press = [&](ui::Key k) {
    out.clear();
    ui::set_key(ImGui::GetIO(), k, true);
    screen.frame([&] { ui::draw_screen(scene, h, run, st, out); });
    ui::set_key(ImGui::GetIO(), k, false);
    screen.frame([&] {
      ui::Requests ignored;
      ui::draw_screen(scene, h, run, st, ignored);
    });
  };
  press(ui::kExportClipKey);
  const ui::ExportClip* clip = nullptr;
  for (const ui::Request& q : out)
    if (const auto* a = std::get_if<ui::AppRequest>(&q))
      if (const auto* c = std::get_if<ui::ExportClip>(a)) clip = c;
  ASSERT_NE(clip, nullptr);
  EXPECT_EQ(clip->from, 7.0);
  EXPECT_EQ(clip->to, 17.5);
  st.show_help = true;
  for (int f = 0; f < 3; ++f)  // an auto-fitting window takes a frame to find its size
    screen.frame([&] {
      ui::Requests ignored;
      ui::draw_screen(scene, h, run, st, ignored);
    });
  const std::string help = drawn_text("Keyboard and mouse (F1)");
  EXPECT_NE(help.find("Debriefpanel"), std::string::npos) << help;
}

}  // namespace
}  // namespace mixpilot
