// Network peers over Cyclone DDS (SPEC §9), on loopback only: the ROS 2 type and topic names,
// sensor_msgs/Joy as a pilot source mapped like a gamepad, malformed samples and a second
// publisher rejected and counted, a silent peer as an input loss, and two processes
// (joy-publish and fly --pilot dds) flying a recording's sticks.
//
// Every test refuses to run unless CYCLONEDDS_URI keeps DDS on loopback (CTest sets it to
// assets/dds-loopback.xml), and each test process uses its own domain id.
#include <gtest/gtest.h>

#include <dds/dds.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <thread>

#include "core/recording/recording.hpp"
#include "input/device_pilot.hpp"
#include "input/net/dds.hpp"
#include "input/net/joy_peer.hpp"
#include "input/net/peer_checks.hpp"
#include "models/mikrokopter.hpp"
#include "ros2_msgs.h"
#include "net_test.hpp"
#include "run_mixpilot.hpp"
#include "temp_files.hpp"

namespace mixpilot::net {
namespace {

namespace fs = std::filesystem;
using test::numbers;
using test::read_file;

TEST(NetConfig, TheLoopbackCheckRefusesWhatWouldLeaveTheMachine) {
  const char* before = std::getenv("CYCLONEDDS_URI");
  const std::string saved = before ? before : "";
  std::string why;
  unsetenv("CYCLONEDDS_URI");
  EXPECT_FALSE(loopback_only(why));
  EXPECT_NE(why.find("multicast"), std::string::npos) << why;
  setenv("CYCLONEDDS_URI", "<General><AllowMulticast>false</AllowMulticast></General>", 1);
  EXPECT_FALSE(loopback_only(why));
  EXPECT_NE(why.find("loopback"), std::string::npos) << why;
  setenv("CYCLONEDDS_URI",
         "<General><Interfaces><NetworkInterface name=\"lo\"/></Interfaces></General>", 1);
  EXPECT_FALSE(loopback_only(why));
  EXPECT_NE(why.find("multicast"), std::string::npos) << why;
  setenv("CYCLONEDDS_URI", loopback_config_uri().c_str(), 1);
  EXPECT_TRUE(loopback_only(why)) << why;
  if (before) setenv("CYCLONEDDS_URI", saved.c_str(), 1);
  else unsetenv("CYCLONEDDS_URI");
}

// --- The checks themselves, on a clock of the test's (no DDS) ------------------------------

constexpr std::int64_t kSecond = 1'000'000'000;

// Joy: 0.5 s old and 0.05 s ahead are the limits; a taken sample orders as its stamp or its
// arrival, whichever is earlier, so a claim from the future stales nothing after it.
TEST(PeerChecks, JoyTimesAreCheckedAgainstTheReceiversClock) {
  JoyCheck check;
  check.setup({0.5, 0.05});
  const float axes[4] = {0, 0, 0, 0};
  const std::int64_t now = 1000 * kSecond;
  std::int64_t stamp = 0;
  RejectionNote note;
  const auto at = [&](std::int64_t arrival, std::int64_t sent) {
    const JoyFields f{std::int32_t(sent / kSecond), std::uint32_t(sent % kSecond), 3, 4, axes, 0,
                      nullptr};
    return check.check(f, arrival, stamp, note);
  };
  EXPECT_EQ(at(now, now - kSecond / 2), Rejection::none);           // 0.5 s old
  EXPECT_EQ(at(now, now - kSecond / 2 - 1'000'000), Rejection::stale);  // older
  EXPECT_EQ(at(now, now + 51'000'000), Rejection::stale);           // 51 ms ahead
  EXPECT_EQ(at(now, now + 49'000'000), Rejection::none);            // 49 ms ahead: taken
  EXPECT_EQ(at(now + 1'000'000, now + 500'000), Rejection::none);   // honest, after it
  EXPECT_EQ(at(now + 2'000'000, now + 400'000), Rejection::stale);  // older than the last
  char text[256];
  describe(note, text, sizeof text);
  EXPECT_STREQ(text, "stale: stamped 0.0001 s before the last sample taken");
  check.forget_order();  // another writer
  EXPECT_EQ(at(now + 3'000'000, now + 400'000), Rejection::none);
}

// States: an age no longer than since the command left (1 ms of clock tolerance); a stamp far
// from the vehicle's other stamps is refused without moving their median; order by command and
// age, so the honest states after a refused one are taken.
TEST(PeerChecks, VehicleStateTimesAreCheckedAgainstTheCommandsSent) {
  SentCommands sent;
  StateCheck check;
  StateCheck::Limits limits;
  limits.nx = 13;
  limits.max_abs.fill(1e6);
  check.setup(limits);
  double x[13] = {0, 0, 0.4, 1};
  RejectionNote note;
  const std::int64_t offset = 123 * kSecond;  // the vehicle's clock against the controller's
  // Command k left at 1 s + 15k ms; its state, measured `age` after it acted, arrives at
  // `received`; `shift` moves the vehicle's stamp off its clock.
  const auto state = [&](std::int64_t k, double age, std::int64_t received, std::int64_t shift) {
    const std::int64_t sent_at = k * 15'000'000 + kSecond;
    const StateFields f{sent_at + offset + std::int64_t(age * 1e9) + shift, k, sent_at, age, 0,
                        13, x};
    return check.check(f, received, sent, note);
  };
  for (std::int64_t k = 0; k < 6; ++k) sent.note(k, k * 15'000'000 + kSecond);
  const auto arrival = [](std::int64_t k) { return k * 15'000'000 + kSecond + 30'000'000; };
  for (std::int64_t k = 0; k < 4; ++k) EXPECT_EQ(state(k, 0.0, arrival(k), 0), Rejection::none);
  EXPECT_EQ(state(3, 0.0312, arrival(3), 0), Rejection::stale);  // acted longer than since sent
  EXPECT_EQ(state(3, 0.0305, arrival(3), 0), Rejection::none);   // within the 1 ms
  EXPECT_EQ(state(3, 0.0305, arrival(3), 0), Rejection::stale);  // measured no later
  EXPECT_EQ(state(4, 0.0, arrival(4), 10 * kSecond), Rejection::stale);  // 10 s off its clock
  EXPECT_EQ(state(4, 0.0, arrival(4), 0), Rejection::none);              // honest again
  EXPECT_EQ(state(5, 0.0, arrival(5), 400'000'000), Rejection::none);   // 0.4 s: delay jitter
  EXPECT_EQ(state(2, 0.0, arrival(5), 0), Rejection::stale);            // an older command
  x[7] = 2e6;
  EXPECT_EQ(state(5, 0.001, arrival(5), 0), Rejection::bad_value);
}

// Commands: in pace with the vehicle's clock from the first one taken; a step ahead of the pace
// (within 0.5 s) is taken, and orders as the step due then, so the honest steps after it are
// taken too; rotor values more than the rotors' range outside their limits are refused.
TEST(PeerChecks, RotorCommandStepsKeepPaceWithTheVehiclesClock) {
  CommandCheck check;
  check.setup({4, 0.015, 0.0, 22.0, 0.5});
  double u[4] = {15, 15, 15, 15};
  RejectionNote note;
  const std::int64_t t0 = 50 * kSecond, c0 = 7 * kSecond;  // vehicle's and controller's clocks
  const auto command = [&](std::int64_t k, double at_s) {
    const CommandFields f{k, c0 + std::int64_t(double(k) * 0.015 * 1e9), 4, u};
    return check.check(f, t0 + std::int64_t(at_s * 1e9), note);
  };
  EXPECT_EQ(command(40, 0.0), Rejection::stale);  // a flight starts near step 0
  EXPECT_EQ(command(0, 0.0), Rejection::none);
  EXPECT_EQ(command(6, 0.1), Rejection::none);
  EXPECT_EQ(command(1000, 0.1), Rejection::stale);  // 14.9 s ahead of the pace
  EXPECT_EQ(command(30, 0.1), Rejection::none);     // 0.35 s ahead: taken...
  EXPECT_EQ(command(7, 0.105), Rejection::none);    // ...without staling the next honest one
  EXPECT_EQ(command(7, 0.106), Rejection::stale);   // a repeat
  u[2] = 44.5;
  EXPECT_EQ(command(8, 0.12), Rejection::bad_value);  // beyond 22 + 22
  u[2] = 43.0;
  EXPECT_EQ(command(8, 0.12), Rejection::none);  // saturates at 22
  const CommandFields late{9, c0 + 10 * kSecond, 4, u};  // stamped 10 s after command 0
  EXPECT_EQ(check.check(late, t0 + 135'000'000, note), Rejection::stale);
}

// ROS 2's names: rt/<topic>, <pkg>::msg::dds_::<Type>_.
TEST_F(Net, TopicAndTypeNamesAreRos2s) {
  EXPECT_EQ(dds_topic("joy"), "rt/joy");
  EXPECT_EQ(dds_topic("/joy"), "rt/joy");
  EXPECT_EQ(dds_topic("rt/joy"), "rt/joy");
  Participant p;
  std::string error;
  ASSERT_TRUE(p.open(domain_, error)) << error;
  const dds_entity_t t =
      dds_create_topic(p.handle(), &sensor_msgs_msg_dds__Joy__desc, "rt/joy", nullptr, nullptr);
  ASSERT_GT(t, 0);
  char name[128];
  ASSERT_GE(dds_get_type_name(t, name, sizeof name), 0);
  EXPECT_STREQ(name, "sensor_msgs::msg::dds_::Joy_");
  ASSERT_GE(dds_get_name(t, name, sizeof name), 0);
  EXPECT_STREQ(name, "rt/joy");
}

// A Joy from the network drives the sticks exactly as a gamepad's axes would.
TEST_F(Net, JoyAxesMapLikeAGamepad) {
  JoyPeer peer;
  std::string error;
  ASSERT_TRUE(peer.start({domain_, "rt/joy_map"}, error)) << error;
  JoyWriter w;
  ASSERT_TRUE(w.open(domain_, "rt/joy_map", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  ASSERT_TRUE(w.write({0.5f, -1.0f, 0.25f, 0.5f, -1.0f, -1.0f}, {1, 0, 1}, system_ns(), "pad", error));
  ASSERT_TRUE(eventually([&] { return peer.heard(); }));
  const input::StickReading& r = peer.latest();
  EXPECT_TRUE(r.connected);
  EXPECT_DOUBLE_EQ(r.sticks.left_x, 0.5);
  EXPECT_DOUBLE_EQ(r.sticks.left_y, 1.0);   // SDL's y points down: −1 is up
  EXPECT_DOUBLE_EQ(r.sticks.right_x, 0.25);
  EXPECT_DOUBLE_EQ(r.sticks.right_y, -0.5);
  EXPECT_EQ(r.joy.num_axes, 6);
  EXPECT_EQ(r.joy.num_buttons, 3);
  peer.stop();
}

// Each kind of bad sample is rejected, counted under its reason, and never reaches the sticks;
// a second publisher is reported and not mixed in.
TEST_F(Net, MalformedSamplesAndASecondPublisherAreRejectedAndCounted) {
  JoyPeer peer;
  std::string error;
  ASSERT_TRUE(peer.start({domain_, "rt/joy_bad"}, error)) << error;
  JoyWriter w, other;
  ASSERT_TRUE(w.open(domain_, "rt/joy_bad", error)) << error;
  ASSERT_TRUE(other.open(domain_, "rt/joy_bad", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0 && other.matched() > 0; }));
  const std::vector<std::int32_t> none;
  const auto send = [&](JoyWriter& wr, std::vector<float> axes, std::int64_t stamp,
                        std::vector<std::int32_t> buttons = {}) {
    ASSERT_TRUE(wr.write(axes, buttons, stamp, "pad", error)) << error;
    std::this_thread::sleep_for(std::chrono::milliseconds(30));  // one sample per take
  };
  const std::int64_t now = system_ns();
  send(w, {0.1f, 0, 0.2f, 0}, now);  // good: the pilot's writer from now on
  ASSERT_TRUE(eventually([&] { return peer.stats().accepted == 1; }));
  send(w, {NAN, 0, 0, 0}, system_ns());
  send(w, {0, INFINITY, 0, 0}, system_ns());
  send(w, {0, 0, 1.5f, 0}, system_ns());
  send(w, {0, 0, 0}, system_ns());                            // too few axes
  send(w, std::vector<float>(9, 0.0f), system_ns());          // too many axes
  send(w, {0, 0, 0, 0}, system_ns(), std::vector<std::int32_t>(33, 1));  // too many buttons
  send(w, std::vector<float>(100000, 0.0f), system_ns());     // huge
  send(w, {0, 0, 0, 0}, system_ns() - 2'000'000'000);         // 2 s old
  send(w, {0, 0, 0, 0}, system_ns() + 2'000'000'000);         // 2 s ahead
  send(w, {0, 0, 0, 0}, now - 1'000'000);                     // older than the last taken
  send(other, {0.9f, 0.9f, 0.9f, 0.9f}, system_ns());         // a second publisher
  ASSERT_TRUE(eventually([&] {
    const JoyPeerStats s = peer.stats();
    return s.bad_value + s.bad_size + s.stale + s.other_publisher >= 11;
  }));
  const JoyPeerStats s = peer.stats();
  EXPECT_EQ(s.accepted, 1u);
  EXPECT_EQ(s.bad_value, 3u);
  EXPECT_EQ(s.bad_size, 4u);
  EXPECT_EQ(s.stale, 3u);
  EXPECT_EQ(s.other_publisher, 1u);
  EXPECT_EQ(s.publishers, 2u);
  const input::StickReading& r = peer.latest();
  EXPECT_FLOAT_EQ(float(r.sticks.left_x), 0.1f);  // still the one good sample
  EXPECT_FLOAT_EQ(float(r.sticks.right_x), 0.2f);
  peer.stop();
}

// A stamp ahead of this machine's clock by more than the tolerance (50 ms) is stale, as the
// docs say; one within it is taken. And a sample from the future cannot make the honest
// samples after it stale: the order is kept against when it arrived, not what it claims.
TEST_F(Net, JoySamplesFromTheFutureAreStaleAndCannotPoisonLaterOnes) {
  JoyPeer peer;
  std::string error;
  ASSERT_TRUE(peer.start({domain_, "rt/joy_future"}, error)) << error;
  JoyWriter w;
  ASSERT_TRUE(w.open(domain_, "rt/joy_future", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  const auto send = [&](float x, std::int64_t ahead_ns) {
    ASSERT_TRUE(w.write({x, 0, 0, 0}, {}, system_ns() + ahead_ns, "pad", error)) << error;
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  };
  send(0.1f, 300'000'000);  // 0.3 s ahead
  send(0.2f, 450'000'000);  // 0.45 s ahead
  send(0.3f, 40'000'000);   // within the tolerance
  for (int i = 0; i < 20; ++i) send(0.4f, 0);  // honest, within 0.45 s of the one above
  ASSERT_TRUE(eventually([&] { return peer.stats().accepted + peer.stats().stale >= 23; }));
  const JoyPeerStats s = peer.stats();
  std::printf("%llu taken, %llu stale; the newest rejected: %s\n",
              (unsigned long long)s.accepted, (unsigned long long)s.stale,
              s.last_rejection.c_str());
  EXPECT_EQ(s.stale, 2u);
  EXPECT_EQ(s.accepted, 21u);
  // The newest rejected is the one stamped 0.45 s ahead, less however long it took to arrive.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(s.last_rejection, m,
                                std::regex(R"(stale: stamped (\S+) s ahead of this machine's clock)")))
      << s.last_rejection;
  EXPECT_LE(std::stod(m[1]), 0.45);
  EXPECT_GT(std::stod(m[1]), 0.3);
  EXPECT_FLOAT_EQ(float(peer.latest().sticks.left_x), 0.4f);
  peer.stop();
}

// Buttons are 0 or 1 (sensor_msgs/Joy, and the recording's /joy); a stamp's nanoseconds are
// below a second; a frame id is a name, not a payload.
TEST_F(Net, JoyButtonsStampsAndFrameIdsOutsideTheirMeaningAreRejected) {
  JoyPeer peer;
  std::string error;
  ASSERT_TRUE(peer.start({domain_, "rt/joy_fields"}, error)) << error;
  JoyWriter w;
  ASSERT_TRUE(w.open(domain_, "rt/joy_fields", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  const auto send = [&](std::vector<std::int32_t> buttons, std::int64_t stamp,
                        const std::string& frame) {
    ASSERT_TRUE(w.write({0, 0, 0, 0}, buttons, stamp, frame, error)) << error;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  };
  send({0, 1}, system_ns(), "pad");                       // good
  send({0, 2}, system_ns(), "pad");                       // a button of 2
  send({-1, 0}, system_ns(), "pad");                      // a button of -1
  send({}, -1, "pad");                                    // nanoseconds 4294967295
  send({}, system_ns(), std::string(100000, 'f'));        // a 100 kB frame id
  ASSERT_TRUE(eventually([&] {
    const JoyPeerStats s = peer.stats();
    return s.accepted + s.rejected() >= 5;
  }));
  const JoyPeerStats s = peer.stats();
  EXPECT_EQ(s.accepted, 1u);
  EXPECT_EQ(s.bad_value, 3u);
  EXPECT_EQ(s.bad_size, 1u);
  peer.stop();
}

// A peer that stops publishing is an input loss: the planner gets the authority at once.
TEST_F(Net, ASilentPeerIsAnInputLoss) {
  JoyPeer peer;
  std::string error;
  ASSERT_TRUE(peer.start({domain_, "rt/joy_silent"}, error)) << error;
  JoyWriter w;
  ASSERT_TRUE(w.open(domain_, "rt/joy_silent", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  input::InputSettings settings;
  input::DevicePilot pilot(peer, settings, 0.015, models::MikroKopter().hover_speed());
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(16);
  PilotCommand c;
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(w.write({0, 0, 0.3f, 0}, {}, system_ns(), "pad", error));
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  ASSERT_TRUE(pilot.command(0, 0, x, c));
  EXPECT_EQ(c.input, InputState::ok);
  EXPECT_GT(c.roll, 0.0);
  std::this_thread::sleep_for(std::chrono::duration<double>(settings.input_timeout_s + 0.05));
  ASSERT_TRUE(pilot.command(1, 0, x, c));
  EXPECT_EQ(c.input, InputState::lost);
  EXPECT_EQ(c.authority, 0.0);
  peer.stop();
}

// --- Two processes ----------------------------------------------------------------------

// joy-publish sends the novice's sticks from its recording; fly --pilot dds flies them in real
// time in another process. Which step each sample lands in is the machines' timing, so the
// verdicts are those that hold whatever it was: every command flown is one the novice gave
// (through the stick mapping, to float precision), nothing is hit, the flight's recording
// replays to its own live score bit for bit; the end-to-end latency is reported.
TEST_F(Net, TwoProcessesFlyARecordingsSticksOverDds) {
  const fs::path dir = test::fresh_path("net", "two_processes");
  fs::create_directories(dir);
  const fs::path nov = dir / "novice.mcap", local = dir / "local.json", remote = dir / "dds.json";
  ASSERT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot novice --headless "
                "--duration 12 --record " + nov.string() + " --report " + local.string(), dir), 0)
      << read_file(dir / "out.txt");
  const std::string d = std::to_string(domain_);
  const std::string publish = "env XDG_CONFIG_HOME='" + (dir / "config").string() + "' '" +
                              kMixpilot + "' joy-publish --from " + nov.string() + " --domain " +
                              d + " --topic joy_two --wait 20 >'" + (dir / "pub.txt").string() +
                              "' 2>&1 &";
  ASSERT_EQ(std::system(publish.c_str()), 0);
  const fs::path flown = dir / "dds.mcap";
  ASSERT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot dds:joy_two "
                "--domain " + d + " --headless --realtime --duration 11.5 --report " +
                remote.string() + " --record " + flown.string(), dir, "fly.txt"), 0)
      << read_file(dir / "fly.txt") << read_file(dir / "pub.txt");
  const std::string out = read_file(dir / "fly.txt");
  std::printf("%s", out.c_str());
  EXPECT_NE(out.find("0 bad values, 0 bad sizes, 0 stale, 0 of another publisher"),
            std::string::npos);
  EXPECT_NE(out.find("peer latency"), std::string::npos);
  const auto a = numbers(read_file(local)), b = numbers(read_file(remote));
  std::printf("local skill %.2f, over DDS %.2f; mean λ %.4f vs %.4f; max deviation %.4f vs %.4f m\n",
              a.at("skill"), b.at("skill"), a.at("mean_lambda"), b.at("mean_lambda"),
              a.at("max_deviation_m"), b.at("max_deviation_m"));
  EXPECT_EQ(b.at("collisions"), 0.0);
  std::string error;
  const auto novice = read_recording(nov.string(), error);
  ASSERT_TRUE(novice) << error;
  const auto over_dds = read_recording(flown.string(), error);
  ASSERT_TRUE(over_dds) << error;
  int compared = 0;
  for (const PilotCommandMsg& c : over_dds->pilot) {
    if (c.input_state != 0) continue;  // before the stream arrived: no command of the novice's
    double nearest = 1e9;
    for (const PilotCommandMsg& n : novice->pilot)
      nearest = std::min(nearest, std::abs(c.roll - n.roll) + std::abs(c.pitch - n.pitch));
    EXPECT_LE(nearest, 1e-5) << "step " << c.step << ": a command the novice never gave";
    ++compared;
  }
  EXPECT_GT(compared, int(over_dds->pilot.size()) / 2);
  ASSERT_EQ(run("score " + flown.string() + " --json " + (dir / "score.json").string(), dir,
                "score.txt"), 0)
      << read_file(dir / "score.txt");
  const auto scored = numbers(read_file(dir / "score.json"));
  for (const char* k : {"skill", "time_in_ball", "mean_lambda", "max_deviation_m", "collisions"})
    EXPECT_EQ(scored.at(k), b.at(k)) << k;
}

// A publisher whose samples all arrive and are all rejected is not told to start the publisher:
// the flight that gives up says how many arrived, why they were rejected, and the newest's
// reason in numbers.
TEST_F(Net, APilotWhoseSamplesAreAllRejectedIsToldWhy) {
  const fs::path dir = test::fresh_path("net", "joy_rejected");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  start("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot dds:joy_rejected --domain " +
            d + " --headless --realtime --duration 2",
        dir, "fly.txt");
  JoyWriter w;
  std::string error;
  ASSERT_TRUE(w.open(domain_, "rt/joy_rejected", error)) << error;
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }, 10));
  int rc = -1;
  for (int i = 0; i < 1500 && rc < 0; ++i) {  // stamped 2 s ahead, until the flight gives up
    ASSERT_TRUE(w.write({0, 0, 0, 0}, {}, system_ns() + 2'000'000'000, "pad", error)) << error;
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
    rc = exit_status(dir, "fly.txt");
  }
  const std::string out = read_file(dir / "fly.txt");
  std::printf("%s", out.c_str());
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(out.find("start the publisher"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(
      R"(\d+ sensor_msgs/msg/Joy samples arrived on rt/joy_rejected .* none was taken \(\d+ stale; )"
      R"(the newest as stale: stamped [12][.0-9]* s ahead of this machine's clock)")))
      << out;
}

// fly --publish in one process; an independent subscriber (tests/net/dds_echo.c: C, its own
// types from the same IDL, none of mixpilot's code) in another sees the four topics with ROS 2's
// type names and plausible values.
TEST_F(Net, PublishedTelemetryReachesAnIndependentSubscriber) {
  const fs::path dir = test::fresh_path("net", "telemetry");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  const std::string echo = std::string("'") + DDS_ECHO + "' " + d + " 6 >'" +
                           (dir / "echo.txt").string() + "' 2>&1 &";
  ASSERT_EQ(std::system(echo.c_str()), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the subscriber is up
  ASSERT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot novice --headless "
                "--realtime --duration 3 --publish --domain " + d, dir, "fly.txt"), 0)
      << read_file(dir / "fly.txt");
  EXPECT_NE(read_file(dir / "fly.txt").find("published 200 steps on rt/mixpilot/* (domain " + d +
                                            "; 0 dropped)"),
            std::string::npos)
      << read_file(dir / "fly.txt");
  std::this_thread::sleep_for(std::chrono::seconds(4));  // the subscriber's 6 s are over
  const std::string out = read_file(dir / "echo.txt");
  std::printf("%s", out.c_str());
  expect_echoed_telemetry(out);
}

}  // namespace
}  // namespace mixpilot::net
