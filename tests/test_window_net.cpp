// The window's network paths: the app (app/trainer.hpp) driven through the headless renderer.
// `--publish` sends its telemetry to an independent subscriber (tests/net/dds_echo.c) in another
// process, as `fly --headless --realtime --publish` does (test_net.cpp); `--vehicle dds` waits
// for its vehicle while the window keeps drawing, and the wait can be cancelled.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "net_test.hpp"
#include "temp_files.hpp"

// LeakSanitizer (the sanitize preset): Mesa and fontconfig keep allocations until exit, in
// modules it cannot name for a suppression; test_app turns it off the same way.
extern "C" const char* __asan_default_options() { return "detect_leaks=0"; }

namespace mixpilot::net {
namespace {

TEST_F(Net, PublishFromTheWindowReachesAnIndependentSubscriber) {
  cli::Offscreen screen;
  std::string error;
  if (!screen.open(800, 450, error)) GTEST_SKIP() << "no EGL device: " << error;
  const std::filesystem::path dir = test::fresh_path("net", "window_publish");
  std::filesystem::create_directories(dir);
  setenv("XDG_CONFIG_HOME", (dir / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (dir / "data").c_str(), 1);
  const std::string echo = std::string("'") + DDS_ECHO + "' " + std::to_string(domain_) +
                           " 6 >'" + (dir / "echo.txt").string() + "' 2>&1 &";
  ASSERT_EQ(std::system(echo.c_str()), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the subscriber is up

  cli::FlyOptions o;
  o.scenario_path = kSrc + "/scenarios/mi_helix.toml";
  o.pilot = "novice";
  o.duration = 3.0;
  o.publish = true;
  o.domain = domain_;
  cli::Trainer app(o);
  int status = 0;
  ASSERT_TRUE(app.open_live(error, status)) << error;
  app.ui_state().score_card_closed = true;
  app.start();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (!app.over() && std::chrono::steady_clock::now() < deadline) {
    screen.frame([&] { app.build_frame(1.0 / 60.0); }, 1.0f / 60.0f);
    std::this_thread::sleep_for(std::chrono::milliseconds(15));
  }
  ASSERT_TRUE(app.over());
  ASSERT_NE(app.live(), nullptr);
  const cli::FlightRig::Closed& closed = app.live()->closing;
  ASSERT_TRUE(closed.published);
  EXPECT_EQ(closed.published_steps, 200u);  // every step of 3 s at Δt = 15 ms
  EXPECT_EQ(closed.publish_dropped, 0u);
  EXPECT_EQ(app.finish(), 0);

  std::this_thread::sleep_for(std::chrono::seconds(4));  // the subscriber's 6 s are over
  const std::string out = test::read_file(dir / "echo.txt");
  std::printf("%s", out.c_str());
  expect_echoed_telemetry(out);
}

// Frames of the app for `seconds` of wall time; returns the longest [ms].
double frames_for(cli::Offscreen& screen, cli::Trainer& app, double seconds) {
  double longest = 0.0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    const auto t0 = std::chrono::steady_clock::now();
    screen.frame([&] { app.build_frame(1.0 / 60.0); }, 1.0f / 60.0f);
    longest = std::max(longest, std::chrono::duration<double, std::milli>(
                                    std::chrono::steady_clock::now() - t0).count());
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return longest;
}

// No vehicle in the domain: the window opens at once and keeps drawing while it waits (each
// frame under 50 ms; it used to block for the whole --vehicle-wait), Restart waits again
// without freezing, Esc's request cancels, and a wait that runs out says so. No flight starts.
TEST_F(Net, TheWindowWaitsForTheVehicleWithoutFreezingAndCanCancel) {
  cli::Offscreen screen;
  std::string error;
  if (!screen.open(800, 450, error)) GTEST_SKIP() << "no EGL device: " << error;
  const std::filesystem::path dir = test::fresh_path("net", "window_vehicle_wait");
  std::filesystem::create_directories(dir);
  setenv("XDG_CONFIG_HOME", (dir / "config").c_str(), 1);
  setenv("XDG_DATA_HOME", (dir / "data").c_str(), 1);
  cli::FlyOptions o;
  o.scenario_path = kSrc + "/scenarios/tracking_helix.toml";
  o.vehicle = "dds";
  o.vehicle_wait_s = 2.0;
  o.domain = domain_;
  cli::Trainer app(o);
  int status = 0;
  const auto opened = std::chrono::steady_clock::now();
  ASSERT_TRUE(app.open_live(error, status)) << error;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - opened).count(), 1.0);
  for (int i = 0; i < 3; ++i) screen.frame([&] { app.build_frame(0.0); }, 1e-4f);  // warm-up
  const double first = frames_for(screen, app, 0.8);
  EXPECT_EQ(app.run_info().state, ui::RunState::waiting);
  EXPECT_NE(app.run_info().message.find("waiting for the vehicle in DDS domain"), std::string::npos)
      << app.run_info().message;
  // To look at: MIXPILOT_SHOT_DIR/waiting_for_vehicle.png.
  if (const char* shots = std::getenv("MIXPILOT_SHOT_DIR"); shots && *shots)
    std::ofstream(std::string(shots) + "/waiting_for_vehicle.png", std::ios::binary) << screen.png();
  app.start();  // Start while waiting does nothing
  EXPECT_FALSE(app.live()->started());

  const ui::Request restart = ui::RestartFlight{};
  const auto t0 = std::chrono::steady_clock::now();
  app.act(restart);
  const double restart_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const double again = frames_for(screen, app, 0.8);
  EXPECT_EQ(app.run_info().state, ui::RunState::waiting);
  app.act(ui::CancelVehicleWait{});
  screen.frame([&] { app.build_frame(0.0); }, 1e-4f);
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  EXPECT_NE(app.run_info().message.find("the wait was cancelled"), std::string::npos)
      << app.run_info().message;
  app.start();
  EXPECT_FALSE(app.live()->started());

  app.act(restart);  // waits again, and this time runs out
  const double out = frames_for(screen, app, 2.6);
  EXPECT_EQ(app.run_info().state, ui::RunState::ready);
  EXPECT_TRUE(app.run_info().message_is_error);
  EXPECT_NE(app.run_info().message.find("no vehicle heard on rt/mixpilot/vehicle/state"),
            std::string::npos)
      << app.run_info().message;
  std::printf("longest frame while waiting: %.1f, %.1f, %.1f ms; Restart took %.1f ms\n", first,
              again, out, restart_ms);
  EXPECT_LT(first, 50.0);
  EXPECT_LT(again, 50.0);
  EXPECT_LT(out, 50.0);
  EXPECT_LT(restart_ms, 1000.0);  // a new flight is made; it used to wait the whole 2 s here
  EXPECT_EQ(app.finish(), 0);
}

}  // namespace
}  // namespace mixpilot::net
