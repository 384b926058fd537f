// The remote vehicle over Cyclone DDS (SPEC §9), on loopback only: malformed states and
// commands rejected and counted; two processes (mixpilot vehicle, fly --vehicle dds) flying
// the tracking smooth step with 30 ms each way, the round-trip estimate against the measured
// round trip, tracking against the simulated plant with the same RTT, the predictor off; a
// vehicle or a controller that goes silent; and, where this machine lets a test make network
// namespaces, vehicle and controller as two hosts joined by a veth pair.
#include <gtest/gtest.h>

#include <dds/dds.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

#include "core/recording/recording.hpp"
#include "input/net/remote_vehicle.hpp"
#include "input/net/vehicle_endpoint.hpp"
#include "models/crazyflie.hpp"
#include "net_test.hpp"
#include "temp_files.hpp"
#include "vehicle_msgs.h"

namespace mixpilot::net {
namespace {

namespace fs = std::filesystem;
using test::numbers;
using test::read_file;

// A raw DDS writer on one of the vehicle's topics, for samples mixpilot would never send.
template <class Msg>
class RawWriter {
 public:
  RawWriter(std::uint32_t domain, const dds_topic_descriptor_t* desc, const char* topic) {
    participant_ = dds_create_participant(domain, nullptr, nullptr);
    const dds_entity_t t = dds_create_topic(participant_, desc, topic, nullptr, nullptr);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    writer_ = dds_create_writer(participant_, t, qos, nullptr);
    dds_delete_qos(qos);
  }
  ~RawWriter() { dds_delete(participant_); }
  bool ok() const { return participant_ > 0 && writer_ > 0; }
  std::uint32_t matched() const {
    dds_publication_matched_status_t st{};
    dds_get_publication_matched_status(writer_, &st);
    return st.current_count;
  }
  void write(const Msg& m) {
    ASSERT_GE(dds_write(writer_, &m), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));  // one sample per take
  }

 private:
  dds_entity_t participant_ = 0, writer_ = 0;
};

using StateMsg = mixpilot_msgs_msg_dds__VehicleState_;
using CommandMsg = mixpilot_msgs_msg_dds__RotorCommand_;

TEST_F(Net, VehicleStatesThatAreMalformedStaleOrForeignAreRejectedAndCounted) {
  RemoteVehicle vehicle;
  std::string error;
  ASSERT_TRUE(vehicle.start({domain_, 13, 0.25}, error)) << error;
  RawWriter<StateMsg> w(domain_, &mixpilot_msgs_msg_dds__VehicleState__desc,
                        "rt/mixpilot/vehicle/state");
  RawWriter<StateMsg> other(domain_, &mixpilot_msgs_msg_dds__VehicleState__desc,
                            "rt/mixpilot/vehicle/state");
  ASSERT_TRUE(w.ok() && other.ok());
  ASSERT_TRUE(eventually([&] { return w.matched() > 0 && other.matched() > 0; }));
  const double u[4] = {15, 15, 15, 15};
  vehicle.send(0, 1000, u, 4);  // command 0, stamped 1000
  double x[32] = {0, 0, 0.4, 1};
  std::int64_t stamp = 1;
  const auto state = [&](std::int64_t command, std::int64_t echo, double age, std::uint32_t n) {
    StateMsg m{};
    m.stamp_ns = stamp++;
    m.command_step = command;
    m.command_stamp_ns = echo;
    m.command_age_s = age;
    m.x._length = m.x._maximum = n;
    m.x._buffer = x;
    return m;
  };
  w.write(state(-1, 0, 0.0, 13));  // good: resting, before any command
  w.write(state(0, 1000, 0.0, 13));  // good: command 0 acting
  ASSERT_TRUE(eventually([&] { return vehicle.stats().accepted == 2; }));
  x[5] = NAN;
  w.write(state(0, 1000, 0.01, 13));  // a non-finite state
  x[5] = 0;
  w.write(state(0, 1000, NAN, 13));   // a non-finite age
  w.write(state(0, 1000, -0.5, 13));  // a negative age
  w.write(state(0, 1000, 0.01, 12));  // too short
  w.write(state(0, 1000, 0.01, 32));  // too long
  w.write(state(0, 1000, 0.01, 0));   // empty
  w.write(state(5, 1000, 0.01, 13));  // echoes a command never sent
  w.write(state(0, 999, 0.01, 13));   // echoes command 0 with another stamp
  w.write(state(0, 1000, 0.0, 13));   // measured no later than the last one taken
  stamp = 100;
  w.write(state(-1, 0, 0.0, 13));     // a command older than the one in effect
  other.write(state(0, 1000, 0.03, 13));  // a second vehicle
  ASSERT_TRUE(eventually([&] {
    const RemoteVehicleStats s = vehicle.stats();
    return s.bad_value + s.bad_size + s.unknown_command + s.stale + s.other_publisher >= 11;
  }));
  const RemoteVehicleStats s = vehicle.stats();
  EXPECT_EQ(s.accepted, 2u);
  EXPECT_EQ(s.bad_value, 3u);
  EXPECT_EQ(s.bad_size, 3u);
  EXPECT_EQ(s.unknown_command, 2u);
  EXPECT_EQ(s.stale, 2u);
  EXPECT_EQ(s.other_publisher, 1u);
  EXPECT_EQ(s.publishers, 2u);
  const VehicleSample& v = vehicle.latest();
  EXPECT_EQ(v.serial, 2u);  // still the second good one
  EXPECT_EQ(v.command, 0);
  EXPECT_EQ(v.command_stamp_ns, 1000);
  EXPECT_TRUE(v.x.allFinite());
  vehicle.stop();
}

TEST_F(Net, RotorCommandsThatAreMalformedStaleOrForeignAreRejectedAndCounted) {
  VehicleEndpoint vehicle;
  std::string error;
  ASSERT_TRUE(vehicle.open(domain_, 4, error)) << error;
  RawWriter<CommandMsg> w(domain_, &mixpilot_msgs_msg_dds__RotorCommand__desc,
                          "rt/mixpilot/vehicle/command");
  RawWriter<CommandMsg> other(domain_, &mixpilot_msgs_msg_dds__RotorCommand__desc,
                              "rt/mixpilot/vehicle/command");
  ASSERT_TRUE(w.ok() && other.ok());
  ASSERT_TRUE(eventually([&] { return w.matched() > 0 && other.matched() > 0; }));
  double u[8] = {15, 15, 15, 15, 15, 15, 15, 15};
  const auto command = [&](std::int64_t step, std::uint32_t n, bool end = false) {
    CommandMsg m{};
    m.step = step;
    m.stamp_ns = 1000 + step;
    m.end = end;
    m.u._length = m.u._maximum = n;
    m.u._buffer = u;
    return m;
  };
  std::vector<VehicleCommand> taken;
  const auto take = [&] {
    for (int i = 0; i < 20; ++i) vehicle.wait(DDS_MSECS(5), taken);
  };
  w.write(command(0, 4));   // good: this controller flies from now on
  w.write(command(1, 3));   // too few
  w.write(command(1, 8));   // too many
  u[2] = INFINITY;
  w.write(command(1, 4));   // non-finite
  u[2] = 15;
  w.write(command(0, 4));   // not after the last one taken
  w.write(command(-3, 4));  // nor this
  other.write(command(7, 4));  // a second controller
  w.write(command(1, 4));   // good
  w.write(command(2, 0, true));  // the end of the flight
  take();
  const VehicleEndpointStats s = vehicle.stats();
  EXPECT_EQ(s.accepted, 2u);
  EXPECT_EQ(s.bad_size, 2u);
  EXPECT_EQ(s.bad_value, 1u);
  EXPECT_EQ(s.stale, 2u);
  EXPECT_EQ(s.other_publisher, 1u);
  EXPECT_EQ(s.publishers, 2u);
  ASSERT_EQ(taken.size(), 3u);
  EXPECT_EQ(taken[0].step, 0);
  EXPECT_EQ(taken[1].step, 1);
  EXPECT_TRUE(taken[2].end);
}

// Times and values a vehicle cannot mean are rejected, and none of them can make the honest
// states after it stale: an age longer than the time since its command left; a value no
// vehicle state has (1e300, finite); an unknown status; a stamp far ahead of what its other
// states say of the vehicle's clock (order is kept by the echoed command and its age, which
// the controller can check).
TEST_F(Net, VehicleStatesWithImpossibleTimesOrValuesAreRejectedAndPoisonNothing) {
  RemoteVehicle vehicle;
  std::string error;
  ASSERT_TRUE(vehicle.start({domain_, 13, 0.25}, error)) << error;
  RawWriter<StateMsg> w(domain_, &mixpilot_msgs_msg_dds__VehicleState__desc,
                        "rt/mixpilot/vehicle/state");
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  const double u[4] = {15, 15, 15, 15};
  double x[13] = {0, 0, 0.4, 1};
  const std::int64_t vehicle_clock = 5'000'000'000'000;  // the vehicle's own clock, elsewhere
  std::int64_t sent_stamp = 0;
  const auto send = [&](std::int64_t k) {
    sent_stamp = vehicle_clock_ns();
    vehicle.send(k, sent_stamp, u, 4);
  };
  const auto state = [&](std::int64_t command, double age, std::int64_t stamp = 0) {
    StateMsg m{};
    m.stamp_ns = stamp != 0 ? stamp : vehicle_clock + vehicle_clock_ns();
    m.command_step = command;
    m.command_stamp_ns = sent_stamp;
    m.command_age_s = age;
    m.x._length = m.x._maximum = 13;
    m.x._buffer = x;
    return m;
  };
  for (std::int64_t k = 0; k < 5; ++k) {  // good: five commands acknowledged
    send(k);
    w.write(state(k, 0.0));
  }
  ASSERT_TRUE(eventually([&] { return vehicle.stats().accepted == 5; }));
  w.write(state(4, 10.0));  // command 4 acted 10 s, yet it left 0.1 s ago
  x[0] = 1e300;
  w.write(state(4, 0.001));  // a position of 1e300 m
  x[0] = 0;
  StateMsg odd = state(4, 0.002);
  odd.status = 7;
  w.write(odd);  // no such status
  send(5);
  w.write(state(5, 0.0, INT64_MAX / 2));  // stamped centuries ahead of the vehicle's clock
  w.write(state(5, 0.001));               // honest again
  send(6);
  w.write(state(6, 0.0));
  ASSERT_TRUE(eventually([&] {
    const RemoteVehicleStats s = vehicle.stats();
    return s.accepted + s.bad_value + s.stale >= 11;
  }));
  const RemoteVehicleStats s = vehicle.stats();
  std::printf("%llu taken, %llu bad values, %llu stale; the newest rejected: %s\n",
              (unsigned long long)s.accepted, (unsigned long long)s.bad_value,
              (unsigned long long)s.stale, s.last_rejection.c_str());
  EXPECT_EQ(s.accepted, 7u);
  EXPECT_EQ(s.bad_value, 2u);
  EXPECT_EQ(s.stale, 2u);
  EXPECT_NE(s.last_rejection.find("stale: stamped 4.61e+09 s off the vehicle's clock"),
            std::string::npos) << s.last_rejection;
  const VehicleSample& v = vehicle.latest();
  EXPECT_EQ(v.command, 6);
  EXPECT_EQ(v.x(0), 0.0);
  vehicle.stop();
}

// At the vehicle: one command whose step is far ahead of the controller's pace (INT64_MAX) is
// rejected and cannot make the honest commands after it stale; a rotor value farther outside
// the rotors' limits than their range is not a rotor command.
TEST_F(Net, RotorCommandsFarAheadOrNotRotorCommandsAreRejectedAndPoisonNothing) {
  VehicleEndpoint vehicle;
  std::string error;
  ASSERT_TRUE(vehicle.open(domain_, 4, error)) << error;
  RawWriter<CommandMsg> w(domain_, &mixpilot_msgs_msg_dds__RotorCommand__desc,
                          "rt/mixpilot/vehicle/command");
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }));
  double u[4] = {15, 15, 15, 15};
  const auto command = [&](std::int64_t step) {
    CommandMsg m{};
    m.step = step;
    m.stamp_ns = vehicle_clock_ns();
    m.u._length = m.u._maximum = 4;
    m.u._buffer = u;
    return m;
  };
  std::vector<VehicleCommand> taken;
  for (std::int64_t k : {0, 1}) w.write(command(k));
  w.write(command(INT64_MAX));
  for (std::int64_t k : {2, 3, 4}) w.write(command(k));
  u[1] = 1e300;
  w.write(command(5));
  u[1] = 15;
  w.write(command(6));
  for (int i = 0; i < 20; ++i) vehicle.wait(DDS_MSECS(5), taken);
  const VehicleEndpointStats s = vehicle.stats();
  std::printf("%llu taken, %llu stale, %llu bad values; the newest rejected: %s\n",
              (unsigned long long)s.accepted, (unsigned long long)s.stale,
              (unsigned long long)s.bad_value, s.last_rejection.c_str());
  ASSERT_EQ(taken.size(), 6u);
  const std::int64_t want[] = {0, 1, 2, 3, 4, 6};
  for (std::size_t i = 0; i < taken.size(); ++i) EXPECT_EQ(taken[i].step, want[i]);
  EXPECT_EQ(s.stale, 1u);
  EXPECT_EQ(s.bad_value, 1u);
}

// --- Two processes ----------------------------------------------------------------------

const std::string kStep = kSrc + "/scenarios/tracking_smooth_step.toml";
// Tracking RMS of the uncompensated NMPC on the smooth step at an 18 ms round trip, the edge of
// its delay margin (test_tracking: TrackingDelay.Fig56UncompensatedDegradesWithRtt): a
// compensated remote loop whose estimate errs by less than the margin tracks better than this.
constexpr double kMarginRms = 0.0307;

// The RTT estimate of every step from t = from on, from a recording's channels.
std::vector<double> estimates(const fs::path& recording, double from, double dt) {
  std::string error;
  const auto rec = read_recording(recording.string(), error);
  EXPECT_TRUE(rec) << error;
  std::vector<double> out;
  if (!rec) return out;
  for (const ModeChannelsMsg& c : rec->channels) {
    if (double(c.step) * dt < from) continue;
    for (std::size_t i = 0; i < c.names.size(); ++i)
      if (c.names[i] == "RTT estimate") out.push_back(c.values[i]);
  }
  return out;
}

// mixpilot vehicle with 30 ms each way; fly --vehicle dds flies the smooth step over it. The
// round trip measured from the echoed stamps is 60 ms plus transport and scheduling (the link's
// threads run under SCHED_FIFO, so a busy machine adds little: its median stays within 6 ms);
// the online estimate is within 3 ms of it at every step after 2 s; the vehicle is tracked —
// the predictor leaves at most an error of the estimate, well inside the uncompensated loop's
// ≈ 18 ms delay margin (SPEC §5.2), so the error stays below that of the uncompensated loop at
// its margin (3.07 cm; the simulated plant with a known 60 ms: 0.55 cm; lost without the
// predictor) however the link's jitter fell; the recording says a remote vehicle flew and is not
// flown again.
TEST_F(Net, ARemoteVehicleWithThirtyMillisecondsEachWayIsTrackedAsTheSimulatedOne) {
  const fs::path dir = test::fresh_path("net", "vehicle_latency");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  ASSERT_EQ(run("fly --scenario " + kStep + " --headless --report " + (dir / "local.json").string(),
                dir), 0) << read_file(dir / "out.txt");
  start("vehicle --scenario " + kStep + " --latency 30 --domain " + d + " --wait 30", dir,
        "vehicle.txt");
  const fs::path rec = dir / "remote.mcap";
  ASSERT_EQ(run("fly --scenario " + kStep + " --vehicle dds --domain " + d +
                " --headless --realtime --record " + rec.string() + " --report " +
                (dir / "remote.json").string(), dir, "fly.txt"), 0)
      << read_file(dir / "fly.txt");
  EXPECT_EQ(finished(dir, "vehicle.txt", 10), 0) << read_file(dir / "vehicle.txt");
  const std::string out = read_file(dir / "fly.txt");
  std::printf("%s%s", out.c_str(), read_file(dir / "vehicle.txt").c_str());
  EXPECT_NE(out.find("0 bad values, 0 bad sizes, 0 unknown commands, 0 stale, 0 of another"),
            std::string::npos);
  EXPECT_NE(read_file(dir / "vehicle.txt").find("the controller ended the flight"),
            std::string::npos);
  const auto local = numbers(read_file(dir / "local.json"));
  const auto remote = numbers(read_file(dir / "remote.json"));
  const double measured = remote.at("rtt_s");
  std::printf("RTT measured %.2f ms, estimated %.2f ms; tracking RMS %.5f m over DDS, %.5f m "
              "simulated with 60 ms\n", 1e3 * measured, 1e3 * remote.at("rtt_estimated_s"),
              remote.at("tracking_rms_m"), local.at("tracking_rms_m"));
  EXPECT_GE(measured, 0.060);
  EXPECT_LE(measured, 0.066);
  EXPECT_NEAR(remote.at("rtt_estimated_s"), measured, 0.003);
  const std::vector<double> after2s = estimates(rec, 2.0, 0.015);
  EXPECT_GE(after2s.size(), 390u);
  for (double e : after2s) ASSERT_NEAR(e, measured, 0.003);
  EXPECT_EQ(remote.at("lost"), 0.0);
  EXPECT_LT(remote.at("tracking_rms_m"), kMarginRms);
  // Flown elsewhere: the recording is shown, never flown again here.
  EXPECT_EQ(run("score " + rec.string(), dir, "score.txt"), 1);
  EXPECT_NE(read_file(dir / "score.txt").find("was flown with a remote vehicle"), std::string::npos)
      << read_file(dir / "score.txt");
}

// Without the predictor the loop is past its delay margin (≈ 18 ms, SPEC §5.2) at 60 ms: it
// diverges over DDS as it does in simulation (which loses the vehicle at 4.5 s). When the
// diverging vehicle crosses the 100 m loss radius depends on the link's jitter (seen 4.6 to
// 6.5 s, and once not within the 8 s), so the check is the divergence: errors of metres where
// the predictor keeps them to centimetres.
TEST_F(Net, WithoutThePredictorTheRemoteVehicleDivergesAsTheSimulatedOne) {
  const fs::path dir = test::fresh_path("net", "vehicle_no_predictor");
  fs::create_directories(dir);
  std::string text = read_file(kStep);
  text = std::regex_replace(text, std::regex("compensation = true"), "compensation = false");
  text = std::regex_replace(text, std::regex("file = \"references/"),
                            "file = \"" + kSrc + "/scenarios/references/");
  const fs::path sc = dir / "no_predictor.toml";
  std::ofstream(sc) << text;
  const std::string d = std::to_string(domain_);
  ASSERT_EQ(run("fly --scenario " + sc.string() + " --headless --report " +
                (dir / "local.json").string(), dir), 0) << read_file(dir / "out.txt");
  start("vehicle --scenario " + sc.string() + " --latency 30 --domain " + d, dir, "vehicle.txt");
  ASSERT_EQ(run("fly --scenario " + sc.string() + " --vehicle dds --domain " + d +
                " --headless --realtime --report " + (dir / "remote.json").string(), dir,
                "fly.txt"), 0) << read_file(dir / "fly.txt");
  EXPECT_EQ(finished(dir, "vehicle.txt", 10), 0) << read_file(dir / "vehicle.txt");
  std::printf("%s", read_file(dir / "fly.txt").c_str());
  const auto local = numbers(read_file(dir / "local.json"));
  const auto remote = numbers(read_file(dir / "remote.json"));
  EXPECT_EQ(local.at("lost"), 1.0);
  std::printf("max error %.1f m simulated (lost at %.2f s), %.1f m over DDS (lost %g at %.2f s)\n",
              local.at("max_error_m"), local.at("lost_at_s"), remote.at("max_error_m"),
              remote.at("lost"), remote.at("lost_at_s"));
  EXPECT_GT(local.at("max_error_m"), 1.0);
  EXPECT_GT(remote.at("max_error_m"), 1.0);
}

// A vehicle that stops (SIGTERM after 3 s) leaves the controller without states: the flight
// ends as lost, "it went silent", about the link's timeout later. A controller that is killed
// leaves the vehicle without commands: it ends the flight, says why and exits 1.
TEST_F(Net, APeerThatGoesSilentEndsTheFlightOnTheOtherSide) {
  const fs::path dir = test::fresh_path("net", "vehicle_silent");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  start("vehicle --scenario " + kStep + " --domain " + d, dir, "vehicle.txt", "timeout 4");
  EXPECT_EQ(run("fly --scenario " + kStep + " --vehicle dds --domain " + d +
                " --headless --realtime --report " + (dir / "silent.json").string(), dir,
                "fly.txt"), 0) << read_file(dir / "fly.txt");
  const std::string out = read_file(dir / "fly.txt");
  std::printf("%s", out.c_str());
  EXPECT_NE(out.find("the vehicle was lost: it went silent"), std::string::npos) << out;
  const auto silent = numbers(read_file(dir / "silent.json"));
  EXPECT_EQ(silent.at("lost"), 1.0);
  EXPECT_GT(silent.at("lost_at_s"), 1.0);
  EXPECT_LT(silent.at("lost_at_s"), 4.5);
  EXPECT_EQ(finished(dir, "vehicle.txt", 5), 124);  // timeout's status: the vehicle was stopped

  start("vehicle --scenario " + kStep + " --domain " + d + " --timeout 0.5", dir, "vehicle2.txt");
  start("fly --scenario " + kStep + " --vehicle dds --domain " + d + " --headless --realtime", dir,
        "fly2.txt", "timeout -s KILL 3");
  EXPECT_EQ(finished(dir, "vehicle2.txt", 15), 1) << read_file(dir / "vehicle2.txt");
  const std::string vout = read_file(dir / "vehicle2.txt");
  std::printf("%s", vout.c_str());
  EXPECT_NE(vout.find("the controller went silent for 0.50 s"), std::string::npos) << vout;
  EXPECT_EQ(finished(dir, "fly2.txt", 5), 137);  // SIGKILL
}

// mixpilot vehicle commanded rotor speed 0 (a legal command: the rotors stop) falls. Through the
// floor it has left its world: the plant stops there, every later state says so (status 1)
// with the last state inside, and the vehicle says so when the flight ends.
TEST_F(Net, AVehicleThatFallsThroughTheFloorSaysSo) {
  const fs::path dir = test::fresh_path("net", "vehicle_floor");
  fs::create_directories(dir);
  start("vehicle --scenario " + kStep + " --domain " + std::to_string(domain_) + " --wait 30",
        dir, "vehicle.txt");
  RemoteVehicle controller;
  std::string error;
  ASSERT_TRUE(controller.start({domain_, 13, 5.0}, error)) << error;
  ASSERT_TRUE(controller.wait_for_vehicle(30));
  const double stopped[4] = {0, 0, 0, 0};
  const auto t0 = std::chrono::steady_clock::now();
  for (std::int64_t k = 0; k < 100; ++k) {  // 1.5 s: free fall from 0.4 m would reach -10.6 m
    std::this_thread::sleep_until(t0 + std::chrono::milliseconds(15 * k));
    controller.send(k, vehicle_clock_ns(), stopped, 4);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  const VehicleSample v = controller.latest();
  controller.finish();
  EXPECT_EQ(finished(dir, "vehicle.txt", 10), 0) << read_file(dir / "vehicle.txt");
  const std::string out = read_file(dir / "vehicle.txt");
  std::printf("%sthe newest state: z = %.3f m, left its world %d\n", out.c_str(), v.x(2),
              int(v.left_world));
  EXPECT_TRUE(v.left_world);
  EXPECT_GT(v.x(2), -1.0);
  EXPECT_LT(v.x(2), -0.9);
  EXPECT_TRUE(std::regex_search(
      out, std::regex(R"(the vehicle left its world at t = 0\.[56]\d s \(it fell below the floor\))")))
      << out;
}

// The controller's side of a vehicle whose states arrive and are all rejected: before the
// flight (16 state values for a 13-state scenario: another scenario's vehicle) it is not told
// to start a vehicle, and in flight (echoes of commands it never sent) the vehicle is not "silent":
// both say how many states arrived and why the newest was rejected.
TEST_F(Net, AControllerWhoseVehicleStatesAreAllRejectedIsToldWhy) {
  const fs::path dir = test::fresh_path("net", "vehicle_rejected");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  {
    start("fly --scenario " + kStep + " --vehicle dds --vehicle-wait 1.5 --domain " + d +
              " --headless --realtime",
          dir, "fly.txt");
    RawWriter<StateMsg> w(domain_, &mixpilot_msgs_msg_dds__VehicleState__desc,
                          "rt/mixpilot/vehicle/state");
    ASSERT_TRUE(w.ok());
    double x[16] = {0, 0, 0.4};
    int rc = -1;
    for (std::int64_t i = 1; i < 500 && rc < 0; ++i) {
      StateMsg m{};
      m.stamp_ns = i;
      m.command_step = -1;
      m.x._length = m.x._maximum = 16;
      m.x._buffer = x;
      w.write(m);
      rc = exit_status(dir, "fly.txt");
    }
    const std::string out = read_file(dir / "fly.txt");
    std::printf("%s", out.c_str());
    EXPECT_EQ(rc, 1);
    EXPECT_EQ(out.find("start `mixpilot vehicle"), std::string::npos) << out;
    EXPECT_TRUE(std::regex_search(out, std::regex(
        R"(\d+ states arrived on rt/mixpilot/vehicle/state .* none was taken \(the newest as bad )"
        R"(size: 16 state values, this scenario's model has 13)")))
        << out;
  }
  {
    start("fly --scenario " + kStep + " --vehicle dds --domain " + d +
              " --headless --realtime --duration 3 --report " + (dir / "r.json").string(),
          dir, "fly2.txt");
    // A vehicle that echoes the commands for 0.3 s, then echoes stamps never sent.
    VehicleEndpoint fake;
    std::string error;
    ASSERT_TRUE(fake.open(domain_, 4, error)) << error;
    const models::Crazyflie model;
    models::Crazyflie::State x = model.hover_state({0.0, 0.0, 0.4});
    std::vector<VehicleCommand> taken;
    std::int64_t first = 0, last_rest = 0;
    int rc = -1;
    for (int i = 0; i < 3000 && rc < 0; ++i) {
      taken.clear();
      fake.wait(DDS_MSECS(5), taken);
      const std::int64_t now = vehicle_clock_ns();
      if (first == 0 && now - last_rest > 15'000'000) {  // at rest until the first command
        fake.publish({now, -1, 0, 0.0, 0, x.data(), 13});
        last_rest = now;
      }
      for (const VehicleCommand& c : taken) {
        if (c.end) continue;
        if (first == 0) first = now;
        x(0) += 1e-6;  // it moves, a little
        const bool lying = now - first > 300'000'000;
        fake.publish({now, c.step, c.stamp_ns + (lying ? 1 : 0), 0.0, 0, x.data(), 13});
      }
      rc = exit_status(dir, "fly2.txt");
    }
    if (rc < 0) rc = finished(dir, "fly2.txt", 10);
    const std::string out = read_file(dir / "fly2.txt");
    std::printf("%s", out.c_str());
    EXPECT_EQ(rc, 0) << out;
    EXPECT_EQ(out.find("it went silent"), std::string::npos) << out;
    EXPECT_TRUE(std::regex_search(out, std::regex(
        R"(the vehicle was lost: no state taken for 0\.2\d s: \d+ arrived and were rejected )"
        R"(\(the newest as unknown command: echoes step \d+ stamped)")))
        << out;
  }
}

// The vehicle's side of a controller whose commands arrive and are all rejected (the same step
// again and again): the flight ends as with a silent controller, and the vehicle says how many
// commands arrived and why the newest was rejected.
TEST_F(Net, AVehicleWhoseCommandsAreAllRejectedSaysWhy) {
  const fs::path dir = test::fresh_path("net", "vehicle_commands_rejected");
  fs::create_directories(dir);
  start("vehicle --scenario " + kStep + " --domain " + std::to_string(domain_) +
            " --timeout 0.5 --wait 30",
        dir, "vehicle.txt");
  RawWriter<CommandMsg> w(domain_, &mixpilot_msgs_msg_dds__RotorCommand__desc,
                          "rt/mixpilot/vehicle/command");
  ASSERT_TRUE(w.ok());
  ASSERT_TRUE(eventually([&] { return w.matched() > 0; }, 30));
  double u[4] = {15.8, 15.8, 15.8, 15.8};
  const auto command = [&](std::int64_t step) {
    CommandMsg m{};
    m.step = step;
    m.stamp_ns = vehicle_clock_ns();
    m.u._length = m.u._maximum = 4;
    m.u._buffer = u;
    return m;
  };
  for (std::int64_t k = 0; k < 10; ++k) w.write(command(k));
  int rc = -1;
  for (int i = 0; i < 200 && rc < 0; ++i) {
    w.write(command(5));
    rc = exit_status(dir, "vehicle.txt");
  }
  if (rc < 0) rc = finished(dir, "vehicle.txt", 5);
  const std::string out = read_file(dir / "vehicle.txt");
  std::printf("%s", out.c_str());
  EXPECT_EQ(rc, 1);
  EXPECT_EQ(out.find("went silent"), std::string::npos) << out;
  EXPECT_TRUE(std::regex_search(out, std::regex(
      R"(no command taken for 0\.50 s: \d+ commands arrived and were rejected \(the )"
      R"(newest as stale: step 5 is not after the last one taken \(9\)\))")))
      << out;
}

// Refused before anything flies: a mode without a remote vehicle, no vehicle at all, a replay.
TEST_F(Net, FlyRefusesWhatARemoteVehicleCannotDo) {
  const fs::path dir = test::fresh_path("net", "vehicle_refusals");
  fs::create_directories(dir);
  const std::string d = std::to_string(domain_);
  EXPECT_EQ(run("fly --scenario " + kSrc + "/scenarios/pendubot_swingup.toml --vehicle dds "
                "--domain " + d + " --headless --realtime", dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("mode pendubot_swingup has no remote vehicle"),
            std::string::npos) << read_file(dir / "out.txt");
  EXPECT_EQ(run("fly --scenario " + kStep + " --vehicle dds --vehicle-wait 0.5 --domain " + d +
                " --headless --realtime", dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("no vehicle heard on rt/mixpilot/vehicle/state"),
            std::string::npos) << read_file(dir / "out.txt");
  EXPECT_EQ(run("fly --scenario " + kStep + " --vehicle dds --headless", dir), 2);
  EXPECT_NE(read_file(dir / "out.txt").find("needs --realtime"), std::string::npos);
  EXPECT_EQ(run("fly --scenario " + kStep + " --vehicle radio --headless --realtime", dir), 2);
  EXPECT_EQ(run("vehicle --scenario " + kSrc + "/scenarios/pendubot_swingup.toml", dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("has no remote vehicle"), std::string::npos);
  EXPECT_EQ(run("vehicle --scenario " + kStep + " --latency -3", dir), 2);
  EXPECT_EQ(run("vehicle --scenario " + kStep + " --wait 0.3 --domain " + d, dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("no controller within"), std::string::npos);
}


// Two hosts: vehicle and controller in two network namespaces this test creates, joined by a
// veth pair and nothing else (no route out of either), each with a Cyclone configuration bound
// to its end of the pair, multicast off, the other end as its peer. Needs root (CAP_SYS_ADMIN);
// skipped with the reason otherwise.
TEST_F(Net, VehicleAndControllerInTwoNetworkNamespacesJoinedByAVethPair) {
  if (geteuid() != 0) GTEST_SKIP() << "creating network namespaces needs root";
  const fs::path dir = test::fresh_path("net", "netns");
  fs::create_directories(dir);
  const std::string id = std::to_string(getpid() % 100000);
  const std::string a = "mpveh" + id, b = "mpctl" + id;  // namespaces
  const std::string va = "mpv" + id, vb = "mpc" + id;    // veth ends (≤ 15 characters)
  const std::string net = "10.213." + std::to_string(getpid() % 250) + ".";
  const auto sh = [](const std::string& cmd) { return std::system((cmd + " 2>&1").c_str()); };
  if (sh("ip netns add " + a) != 0) GTEST_SKIP() << "ip netns add failed: no namespaces here";
  struct Cleanup {
    std::string a, b;
    ~Cleanup() {
      std::system(("ip netns del " + a + " 2>/dev/null").c_str());
      std::system(("ip netns del " + b + " 2>/dev/null").c_str());
    }
  } cleanup{a, b};
  ASSERT_EQ(sh("ip netns add " + b), 0);
  ASSERT_EQ(sh("ip link add " + va + " type veth peer name " + vb), 0);
  ASSERT_EQ(sh("ip link set " + va + " netns " + a + " && ip link set " + vb + " netns " + b), 0);
  ASSERT_EQ(sh("ip -n " + a + " addr add " + net + "1/24 dev " + va + " && ip -n " + a +
               " link set " + va + " up && ip -n " + a + " link set lo up"), 0);
  ASSERT_EQ(sh("ip -n " + b + " addr add " + net + "2/24 dev " + vb + " && ip -n " + b +
               " link set " + vb + " up && ip -n " + b + " link set lo up"), 0);
  const auto config = [&](const std::string& name, const std::string& itf,
                          const std::string& peer) {
    const fs::path p = dir / name;
    std::ofstream(p) << "<CycloneDDS xmlns=\"https://cdds.io/config\"><Domain Id=\"any\"><General>"
                        "<Interfaces><NetworkInterface name=\"" << itf << "\"/></Interfaces>"
                        "<AllowMulticast>false</AllowMulticast></General><Discovery>"
                        "<ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\""
                     << peer << "\"/></Peers></Discovery></Domain></CycloneDDS>\n";
    return "ip netns exec " + name.substr(0, name.size() - 4) + " env CYCLONEDDS_URI=file://" +
           p.string();
  };
  const std::string in_a = config(a + ".xml", va, net + "2");
  const std::string in_b = config(b + ".xml", vb, net + "1");
  const std::string d = std::to_string(domain_);
  start("vehicle --scenario " + kStep + " --latency 30 --domain " + d, dir, "vehicle.txt", in_a);
  const std::string fly = in_b + " env XDG_CONFIG_HOME='" + (dir / "config").string() +
                          "' XDG_DATA_HOME='" + (dir / "data").string() + "' '" + kMixpilot +
                          "' fly --scenario " + kStep + " --vehicle dds --domain " + d +
                          " --headless --realtime --duration 3 --report '" +
                          (dir / "netns.json").string() + "' >'" + (dir / "fly.txt").string() +
                          "' 2>&1";
  EXPECT_EQ(std::system(fly.c_str()), 0) << read_file(dir / "fly.txt");
  EXPECT_EQ(finished(dir, "vehicle.txt", 10), 0) << read_file(dir / "vehicle.txt");
  std::printf("%s%s", read_file(dir / "fly.txt").c_str(), read_file(dir / "vehicle.txt").c_str());
  const auto r = numbers(read_file(dir / "netns.json"));
  EXPECT_EQ(r.at("lost"), 0.0);
  EXPECT_GE(r.at("rtt_s"), 0.060);
  EXPECT_LE(r.at("rtt_s"), 0.066);
  EXPECT_NEAR(r.at("rtt_estimated_s"), r.at("rtt_s"), 0.003);
  EXPECT_LT(r.at("tracking_rms_m"), kMarginRms);  // tracked, as above
  // It all went through the pair: both ends carried every command and state.
  const std::string counts = dir / "veth.txt";
  ASSERT_EQ(sh("ip netns exec " + a + " cat /sys/class/net/" + va + "/statistics/rx_packets "
               "/sys/class/net/" + va + "/statistics/tx_packets > '" + counts + "'"), 0);
  std::istringstream in(read_file(counts));
  long rx = 0, tx = 0;
  in >> rx >> tx;
  std::printf("veth %s: %ld packets in, %ld out\n", va.c_str(), rx, tx);
  EXPECT_GE(rx, 200);
  EXPECT_GE(tx, 200);
}

}  // namespace
}  // namespace mixpilot::net
