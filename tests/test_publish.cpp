// `--publish` from the window: the app (app/trainer.hpp) flying in real time through the
// headless renderer sends its telemetry to an independent subscriber (tests/net/dds_echo.c) in
// another process, as `fly --headless --realtime --publish` does (test_net.cpp).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>

#include "app/offscreen.hpp"
#include "app/trainer.hpp"
#include "net_test.hpp"
#include "temp_files.hpp"

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
  ASSERT_TRUE(app.live()->publisher);
  EXPECT_EQ(app.live()->publisher->published(), 200u);  // every step of 3 s at Δt = 15 ms
  EXPECT_EQ(app.live()->publisher->dropped(), 0u);
  EXPECT_EQ(app.finish(), 0);

  std::this_thread::sleep_for(std::chrono::seconds(4));  // the subscriber's 6 s are over
  const std::string out = test::read_file(dir / "echo.txt");
  std::printf("%s", out.c_str());
  expect_echoed_telemetry(out);
}

}  // namespace
}  // namespace mixpilot::net
