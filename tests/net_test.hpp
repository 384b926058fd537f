#pragma once
// What the DDS tests share: a domain id of the test process's own, the fixture that refuses to
// run unless CYCLONEDDS_URI keeps DDS on loopback, and running the mixpilot executable.
#include <gtest/gtest.h>

#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <regex>
#include <string>
#include <thread>

#include "input/net/dds.hpp"
#include "run_mixpilot.hpp"

namespace mixpilot::net {

// A domain of this process's own (DDS ids 0-232; 0 is the default, left to users).
inline std::uint32_t my_domain() { return 1 + std::uint32_t(getpid()) % 232; }

class Net : public testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!loopback_only(why)) FAIL() << "refusing to run a DDS test: " << why;
    domain_ = my_domain();
  }
  template <class F>
  static bool eventually(F done, double seconds = 5) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (!done()) {
      if (std::chrono::steady_clock::now() > until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return true;
  }
  std::uint32_t domain_ = 0;
};

inline const std::string kSrc = MIXPILOT_SOURCE_DIR;
inline const std::string kMixpilot = MIXPILOT_BINARY;

inline int run(const std::string& args, const std::filesystem::path& dir,
               const std::string& out = "out.txt") {
  return test::run_mixpilot(kMixpilot, args, dir, out);
}
// The same in the background, after `prefix` (e.g. `ip netns exec NS`): its output in dir/out,
// its exit status in dir/out.rc once it has ended. Returns at once.
inline void start(const std::string& args, const std::filesystem::path& dir,
                  const std::string& out, const std::string& prefix = "") {
  const std::string cmd = "( " + prefix + " env XDG_CONFIG_HOME='" + (dir / "config").string() +
                          "' XDG_DATA_HOME='" + (dir / "data").string() + "' '" + kMixpilot +
                          "' " + args + " >'" + (dir / out).string() +
                          "' 2>&1; echo $? >'" + (dir / out).string() + ".rc' ) &";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
}
// The exit status of a start()ed command if it has ended, else −1 (no wait).
inline int exit_status(const std::filesystem::path& dir, const std::string& out) {
  const std::string text = test::read_file(dir / (out + ".rc"));
  return !text.empty() && text.back() == '\n' ? std::stoi(text) : -1;
}
// The exit status of a start()ed command, waiting up to `seconds` for it to end (−1: still
// running).
inline int finished(const std::filesystem::path& dir, const std::string& out, double seconds) {
  const auto rc = dir / (out + ".rc");
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    const std::string text = test::read_file(rc);
    if (!text.empty() && text.back() == '\n') return std::stoi(text);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1;
}

// What tests/net/dds_echo.c printed of mixpilot's telemetry (mi_helix) after `fly --publish`:
// the four topics with ROS 2's type names and plausible values.
inline void expect_echoed_telemetry(const std::string& out) {
  EXPECT_NE(out.find("pose type geometry_msgs::msg::dds_::PoseStamped_"), std::string::npos);
  EXPECT_NE(out.find("lambda type std_msgs::msg::dds_::Float64_"), std::string::npos);
  EXPECT_NE(out.find("predicted_path type nav_msgs::msg::dds_::Path_"), std::string::npos);
  EXPECT_NE(out.find("reference_path type nav_msgs::msg::dds_::Path_"), std::string::npos);
  // Samples arrived on every topic (best effort: how many of the 200 is the machine's timing;
  // the publisher's own count above is exact) and values: inside the arena, a unit quaternion,
  // λ in (0, 1), paths of N + 1 = 51 nodes (mi_helix: N = 50).
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m, std::regex(
      R"(pose (\d+) samples, last position (\S+) (\S+) (\S+), quaternion (\S+) (\S+) (\S+) (\S+))")))
      << out;
  EXPECT_GE(std::stoi(m[1]), 1);
  const double z = std::stod(m[4]);
  EXPECT_GT(z, 0.0);
  EXPECT_LT(z, 3.0);
  double qn = 0;
  for (int i = 5; i <= 8; ++i) qn += std::stod(m[i]) * std::stod(m[i]);
  EXPECT_NEAR(qn, 1.0, 1e-3);
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(lambda (\d+) samples, last (\S+))"))) << out;
  EXPECT_GE(std::stoi(m[1]), 1);
  EXPECT_GT(std::stod(m[2]), 0.0);
  EXPECT_LT(std::stod(m[2]), 1.0);
  ASSERT_TRUE(std::regex_search(out, m, std::regex(R"(predicted_path (\d+) samples, last (\d+) poses)")))
      << out;
  EXPECT_GE(std::stoi(m[1]), 1);
  EXPECT_EQ(std::stoi(m[2]), 51);
}

}  // namespace mixpilot::net
