// mixpilot joy-publish: a recording's sticks as sensor_msgs/msg/Joy over DDS (SPEC §9), paced
// by the wall clock at the recording's control period, for tests and demos of `fly --pilot dds`
// and for ROS 2 tools. The recorded /joy messages are sent when the recording has them; else
// the sticks that give its pilot commands through the input settings (as gamepad-script).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <time.h>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "core/recording/replay.hpp"
#include "core/recording/recording.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "input/net/dds.hpp"
#include "input/net/joy_peer.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kUsage =
    "usage: mixpilot joy-publish --from REC.mcap [--topic NAME] [--domain N] [--wait S]\n"
    "                            [--input-settings FILE]\n"
    "\n"
    "Publishes a mixed-initiative recording's sticks as sensor_msgs/msg/Joy over DDS, one\n"
    "message per control step at the recording's pace, stamped with the time of sending: the\n"
    "recorded /joy messages, or (for an emulated pilot's recording) the stick positions that\n"
    "give its pilot commands through the input settings. `mixpilot fly --pilot dds` flies them.\n"
    "DDS stays on this machine unless CYCLONEDDS_URI names another configuration\n"
    "(docs/network.md).\n"
    "\n"
    "  --from REC.mcap        the recording\n"
    "  --topic NAME           ROS 2 topic (default joy: DDS topic rt/joy)\n"
    "  --domain N             DDS domain id, 0-232 (default 0)\n"
    "  --wait S               wait up to S seconds for a subscriber before sending (default 30)\n"
    "  --input-settings FILE  the settings for recordings without /joy (default: the user's)\n"
    "\n"
    "exit status: 0 sent, 1 unreadable recording, no subscriber or a DDS failure, 2 usage\n";

}  // namespace

int joy_publish_command(int argc, char** argv) {
  std::string from, topic = "joy", settings_path;
  std::uint32_t domain = 0;
  double wait_s = 30;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return option_value("joy-publish", argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    } else if (a == "--from") {
      from = value();
    } else if (a == "--topic") {
      topic = value();
    } else if (a == "--domain") {
      domain = parse_domain("joy-publish", value());
    } else if (a == "--wait") {
      const std::string v = value();
      char* end = nullptr;
      wait_s = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !(wait_s >= 0 && wait_s <= 3600))
        usage_error("joy-publish", "--wait expects seconds from 0 to 3600, got '" + v + "'");
    } else if (a == "--input-settings") {
      settings_path = value();
    } else {
      usage_error("joy-publish", "unknown argument '" + a + "'");
    }
  }
  if (from.empty()) usage_error("joy-publish", "--from REC.mcap is required");
  std::string error;
  const auto settings = command_input_settings("joy-publish", settings_path, error);
  const auto pr = settings ? read_pilot_recording(from, error) : std::nullopt;
  if (!pr) {
    std::fprintf(stderr, "mixpilot joy-publish: %s\n", error.c_str());
    return kExitError;
  }
  const RecordingContents* rec = &pr->recording;
  const Scenario* scenario = &pr->scenario;
  // The messages, all made before the first is sent.
  const bool recorded = rec->joy.size() == rec->pilot.size() && !rec->joy.empty() &&
                        rec->joy.front().axes.size() >= 4;
  std::vector<std::vector<float>> axes(rec->pilot.size());
  std::vector<std::vector<std::int32_t>> buttons(rec->pilot.size());
  for (std::size_t k = 0; k < rec->pilot.size(); ++k) {
    if (recorded) {
      axes[k] = rec->joy[k].axes;
      buttons[k] = rec->joy[k].buttons;
    } else {
      const auto a = sdl_axes_for(rec->pilot[k], *settings);
      axes[k] = {float(a[0]), float(a[1]), float(a[2]), float(a[3]), -1.0f, -1.0f};
      buttons[k].assign(11, 0);
    }
  }

  net::use_loopback_unless_configured();
  net::JoyWriter writer;
  const std::string dds_name = net::dds_topic(topic);
  if (!writer.open(domain, dds_name, error)) {
    std::fprintf(stderr, "mixpilot joy-publish: %s\n", error.c_str());
    return kExitError;
  }
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(wait_s);
  while (writer.matched() == 0 && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (writer.matched() == 0) {
    std::fprintf(stderr, "mixpilot joy-publish: no subscriber on %s in DDS domain %u within "
                 "%.0f s\n", dds_name.c_str(), unsigned(domain), wait_s);
    return kExitError;
  }
  std::printf("mixpilot joy-publish: %zu messages from %s (%s) on %s, domain %u\n", axes.size(),
              from.c_str(), recorded ? "recorded /joy" : "sticks of the pilot commands",
              dds_name.c_str(), unsigned(domain));
  std::fflush(stdout);
  // Paced on the absolute schedule: message k at start + k·Δt.
  const std::int64_t period = std::int64_t(scenario->controller.dt * 1e9);
  timespec start{};
  clock_gettime(CLOCK_MONOTONIC, &start);
  const std::int64_t t0 = std::int64_t(start.tv_sec) * 1'000'000'000 + start.tv_nsec;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    const std::int64_t due = t0 + std::int64_t(k) * period;
    const timespec ts{time_t(due / 1'000'000'000), long(due % 1'000'000'000)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
    if (!writer.write(axes[k], buttons[k], net::system_ns(), "mixpilot", error)) {
      std::fprintf(stderr, "mixpilot joy-publish: %s\n", error.c_str());
      return kExitError;
    }
  }
  std::printf("mixpilot joy-publish: sent %zu messages\n", axes.size());
  return kExitOk;
}

}  // namespace mixpilot::cli
