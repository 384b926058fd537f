// mixpilot instruct: the instructor (SPEC §10, docs/instructor-security.md): its window
// (app/instructor_app.hpp), or on the command line the stations announced on the DDS domain, or
// one command to one station, waited for until the station announces what became of it. Both
// are built on net::InstructorClient.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "app/instructor_app.hpp"
#include "app/screenshot.hpp"
#include "app/window.hpp"
#include "core/history/history.hpp"
#include "input/net/dds.hpp"
#include "input/net/instructor_client.hpp"
#include "ui/instructor_hud.hpp"

namespace mixpilot::cli {

namespace {

// instruct's own exit statuses beside 0, 1 and 2.
constexpr int kExitRefused = 4;   // the station, or DDS Security, refused the command
constexpr int kExitNoAnswer = 5;  // the station was not heard, or did not answer in time

constexpr const char* kUsage =
    "usage: mixpilot instruct [--station NAME] [window options] [options]\n"
    "       mixpilot instruct --list [--count N] [options]\n"
    "       mixpilot instruct --station NAME COMMAND [options]\n"
    "\n"
    "The instructor (SPEC §10). Without --list or a command it opens a window: the stations\n"
    "announced on the DDS domain, up to four side by side (a small arena, the λ strip, the\n"
    "deviation and the score so far), one large with its plots (click a tile, or 1-4), and in\n"
    "a pane on the right the commands to the selected station, each with what became of it\n"
    "(F1 lists the keys).\n"
    "--station NAME opens it on that station, large.\n"
    "\n"
    "On the command line, --list prints the stations announced on the DDS\n"
    "domain (every `fly --publish`): trainee, scenario, state, time, λ, deviation, time in B,\n"
    "whether it obeys an instructor, the commands it accepted and refused, and its telemetry\n"
    "heard here. --station sends one command to one station and waits until the station\n"
    "announces what became of it: accepted (handed to its flight) or refused, and why.\n"
    "\n"
    "commands (one per run):\n"
    "  --floor F, --ceiling C  authority bounds: 0 <= F <= C <= 1 (SPEC §10; either or both,\n"
    "                     default floor 0, ceiling 1)\n"
    "  --gust FX,FY,FZ    a gust: a force [N, world frame] on the vehicle, at most 20 N,\n"
    "                     for --duration S (more than 0, at most 10 s)\n"
    "  --input-loss S     the pilot's input is lost for S seconds (at most 10)\n"
    "  --delay S          extra round-trip delay, 0 to 0.5 s (0 removes it)\n"
    "  --marker TEXT      a marker in the debrief: 1 to 95 bytes of UTF-8\n"
    "  --pause, --resume, --end\n"
    "\n"
    "window options:\n"
    "  --headless         no window: render --screenshot's frames offscreen (EGL)\n"
    "  --screenshot T:FILE.png  the window's frame T seconds after it opened (headless: after\n"
    "                     --count stations were heard); repeatable\n"
    "  --count N          headless: wait (up to --wait) for N stations and their telemetry\n"
    "  --size WxH         the window's size (default 1280x720)\n"
    "  --scale S          the UI's display scale (default: the display's; headless 1)\n"
    "  --force            screenshots may replace existing files\n"
    "\n"
    "options:\n"
    "  --domain N         DDS domain (0-232, default 0; 0-230 with DDS Security)\n"
    "  --dds-security FOLDER  authenticate as the identity in FOLDER (identity_ca.pem,\n"
    "                     cert.pem, key.pem, permissions_ca.pem, governance.p7s,\n"
    "                     permissions.p7s; mixpilot-security-ca DIR makes a test set)\n"
    "  --issuer NAME      who commands (default: login@host); a station keeps each issuer's\n"
    "                     commands in order\n"
    "  --count N          --list: stop as soon as N stations, their telemetry and a fresh\n"
    "                     announcement of each are heard\n"
    "  --wait S           how long to wait for the stations, or for the answer (default 10)\n"
    "  --sequence N       number the command N instead of the next number (the system\n"
    "                     clock's microseconds): a number not above the last one a station\n"
    "                     took from this issuer is refused as a replay (for tests)\n"
    "  -h, --help         show this help\n"
    "\n"
    "DDS stays on this machine unless CYCLONEDDS_URI names another configuration\n"
    "(docs/network.md).\n"
    "\n"
    "exit status: 0 listed, the command was accepted, or the window closed; 1 a failure (DDS,\n"
    "unreadable security files, no display: use --list or --headless); 2 usage; 4 refused (by the station, or by DDS Security: this identity may not\n"
    "command, its certificate is not trusted or expired); 5 no answer (the station was not\n"
    "heard, its command reader never matched, or it did not answer within --wait; headless:\n"
    "fewer than --count stations heard)\n";

std::optional<double> parse_number(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string refused_words(const net::StationView& v) {
  std::string out;
  for (int r = 1; r < net::kCommandRefusals; ++r)
    if (v.refused[std::size_t(r)] > 0)
      out += (out.empty() ? "" : ", ") + std::to_string(v.refused[std::size_t(r)]) + " " +
             net::to_string(net::CommandRefusal(r));
  return out;
}

void print_station(const net::StationView& v) {
  std::printf("%s: trainee %s, %s (%s), %s at %.1f of %.1f s, λ %.2f, deviation %.3f m, "
              "in B %.0f %%, mean λ %.2f\n",
              v.station.c_str(), v.trainee.c_str(), v.scenario.c_str(), v.mode.c_str(),
              net::to_string(v.state), v.t, v.duration, v.lambda, v.deviation,
              100.0 * v.time_in_ball, v.mean_lambda);
  // What the instructor's commands keep in force there, as its HUD says it.
  std::string in_force;
  for (const std::string& item :
       ui::instructor_in_force(v.in_force, v.state == net::StationState::paused))
    in_force += in_force.empty() ? item.substr(item.find(": ") + 2) : " " + item;
  if (!in_force.empty()) std::printf("  in force: %s\n", in_force.c_str());
  const std::string refused = refused_words(v);
  std::printf("  instructor: %s; commands %llu accepted, %llu refused%s%s\n",
              net::to_string(v.security), (unsigned long long)v.accepted,
              (unsigned long long)v.refused_total(), refused.empty() ? "" : " (",
              refused.empty() ? "" : (refused + ")").c_str());
  if (!v.last_refusal.empty()) std::printf("  the newest refused: %s\n", v.last_refusal.c_str());
  if (v.security_refused > 0)
    std::printf("  DDS Security refused peers %llu times; the newest: %s\n",
                (unsigned long long)v.security_refused, v.security_last.c_str());
  std::printf("  telemetry heard here: %llu poses, %llu λ\n", (unsigned long long)v.poses,
              (unsigned long long)v.lambdas);
}

// What DDS Security refused here (this process's side of a handshake), for a message.
std::string security_note() {
  const net::SecurityLog log = net::security_log();
  if (log.refused == 0) return {};
  return "; DDS Security refused the handshake " + std::to_string(log.refused) +
         " times, the newest: " + log.last;
}

}  // namespace

int instruct_command(int argc, char** argv) {
  const char* cmd = "instruct";
  bool list = false;
  std::string station, security, issuer;
  std::uint32_t domain = 0;
  double wait_s = 10.0;
  int count = 0;
  std::optional<std::uint64_t> sequence;
  InstructWindowOptions window;
  bool window_option = false;  // an option only the window takes
  std::optional<double> floor, ceiling, duration;
  InstructorCommand c;
  int commands = 0;
  const auto command = [&](InstructorCommandKind k) {
    c.kind = k;
    ++commands;
  };
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return option_value(cmd, argc, argv, i); };
    const auto number = [&](const char* what) {
      const std::string v = value();
      const auto n = parse_number(v);
      if (!n) usage_error(cmd, a + " expects " + what + ", got '" + v + "'");
      return *n;
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    } else if (a == "--headless") {
      window.headless = true;
      window_option = true;
    } else if (a == "--screenshot") {
      const std::string v = value();
      const std::optional<ScreenshotRequest> r = parse_screenshot(v);
      if (!r) usage_error(cmd, "--screenshot expects T:FILE.png with T >= 0 seconds, got '" + v + "'");
      window.screenshots.push_back({r->t, r->path});
      window_option = true;
    } else if (a == "--size") {
      const std::string v = value();
      if (!parse_size(v, window.width, window.height))
        usage_error(cmd, "--size expects WxH from 64 to 8192, got '" + v + "'");
      window_option = true;
    } else if (a == "--scale") {
      const double s = number("a display scale from 0.5 to 4");
      if (s < 0.5 || s > 4) usage_error(cmd, "--scale expects a display scale from 0.5 to 4");
      window.scale = float(s);
      window_option = true;
    } else if (a == "--force") {
      window.overwrite = true;
      window_option = true;
    } else if (a == "--list") {
      list = true;
    } else if (a == "--station") {
      station = value();
      if (const std::string why = net::check_station_name(station); !why.empty())
        usage_error(cmd, "--station: " + why);
    } else if (a == "--domain") {
      domain = parse_domain(cmd, value());
    } else if (a == "--dds-security") {
      security = value();
    } else if (a == "--issuer") {
      issuer = value();
      if (issuer.size() > net::kMaxIssuer || !net::printable_utf8(issuer))
        usage_error(cmd, "--issuer expects 1 to 63 bytes of printable UTF-8");
    } else if (a == "--count") {
      const double n = number("a number of stations from 1 to 100");
      if (n < 1 || n > 100 || n != std::floor(n))
        usage_error(cmd, "--count expects a number of stations from 1 to 100");
      count = int(n);
    } else if (a == "--wait") {
      const std::string v = value();
      const auto s = parse_seconds(v, 3600.0);
      if (!s) usage_error(cmd, "--wait expects seconds up to 3600, got '" + v + "'");
      wait_s = *s;
    } else if (a == "--sequence") {
      const double n = number("a whole number from 1");
      if (n < 1 || n > 9e15 || n != std::floor(n))
        usage_error(cmd, "--sequence expects a whole number from 1");
      sequence = std::uint64_t(n);
    } else if (a == "--floor" || a == "--ceiling") {
      const double v = number("a share of authority from 0 to 1");
      if (v < 0 || v > 1) usage_error(cmd, a + " expects a share of authority from 0 to 1");
      (a == "--floor" ? floor : ceiling) = v;
    } else if (a == "--gust") {
      const std::string v = value();
      double f[3];
      char tail = 0;
      if (std::sscanf(v.c_str(), "%lf,%lf,%lf%c", &f[0], &f[1], &f[2], &tail) != 3 ||
          !std::isfinite(f[0] + f[1] + f[2]))
        usage_error(cmd, "--gust expects FX,FY,FZ in newtons (e.g. 2,0,0), got '" + v + "'");
      c.force = Eigen::Vector3d(f[0], f[1], f[2]);
      if (c.force.norm() > net::kMaxForce)
        usage_error(cmd, "--gust: at most 20 N, got " + std::to_string(c.force.norm()) + " N");
      command(InstructorCommandKind::gust);
    } else if (a == "--duration") {
      duration = number("seconds");
    } else if (a == "--input-loss") {
      duration = number("seconds");
      command(InstructorCommandKind::input_loss);
    } else if (a == "--delay") {
      c.delay = number("seconds from 0 to 0.5");
      if (c.delay < 0 || c.delay > net::kMaxDelay)
        usage_error(cmd, "--delay expects seconds from 0 to 0.5");
      command(InstructorCommandKind::extra_delay);
    } else if (a == "--marker") {
      const std::string v = value();
      if (v.size() > DebriefNote::kCapacity || !net::printable_utf8(v))
        usage_error(cmd, "--marker expects 1 to 95 bytes of printable UTF-8");
      c.text.assign(v);
      command(InstructorCommandKind::marker);
    } else if (a == "--pause") {
      command(InstructorCommandKind::pause);
    } else if (a == "--resume") {
      command(InstructorCommandKind::resume);
    } else if (a == "--end") {
      command(InstructorCommandKind::end);
    } else {
      usage_error(cmd, "unknown option '" + a + "'");
    }
  }
  if (floor || ceiling) {
    command(InstructorCommandKind::bounds);
    c.bounds = {floor.value_or(0.0), ceiling.value_or(1.0)};
    if (!c.bounds.valid())
      usage_error(cmd, "the floor must not be above the ceiling (0 <= floor <= ceiling <= 1)");
  }
  const bool in_window = !list && commands == 0;
  if (list && !station.empty()) usage_error(cmd, "--list or --station NAME, not both");
  if (list && commands > 0) usage_error(cmd, "--list sends no command");
  if (!list && commands > 1) usage_error(cmd, "one command per run");
  if (!in_window && window_option)
    usage_error(cmd, "--headless, --screenshot, --size, --scale and --force go with the window "
                     "(no --list, no command)");
  if (!list && commands == 1 && station.empty())
    usage_error(cmd, "to which station? (--station NAME)");
  if (count > 0 && !list && !(in_window && window.headless))
    usage_error(cmd, "--count goes with --list or --headless");
  if (in_window && window.headless && window.screenshots.empty())
    usage_error(cmd, "--headless renders only --screenshot T:FILE.png frames (or use --list)");
  if (sequence && list) usage_error(cmd, "--sequence goes with a command");
  const bool timed = c.kind == InstructorCommandKind::gust ||
                     c.kind == InstructorCommandKind::input_loss;
  if (!list && timed) {
    if (!duration)
      usage_error(cmd, "--gust needs --duration S (how long the force acts)");
    c.duration = *duration;
    if (!(c.duration > 0 && c.duration <= net::kMaxDuration))
      usage_error(cmd, "--duration expects more than 0 and at most 10 seconds");
  } else if (duration && !list) {
    usage_error(cmd, "--duration goes with --gust");
  }
  if (issuer.empty()) issuer = history::login_name() + "@" + history::host_name();
  if (issuer.size() > net::kMaxIssuer) issuer.resize(net::kMaxIssuer);
  if (!net::printable_utf8(issuer)) issuer = "instructor";

  if (in_window) {
    // Before anything is opened: a window needs a display.
    std::string error;
    if (!window.headless && !window_available(error)) {
      std::fprintf(stderr, "mixpilot %s: %s (or --list)\n", cmd, error.c_str());
      return kExitError;
    }
  }
  net::use_loopback_unless_configured();
  if (!security.empty()) {
    std::string error;
    const std::optional<net::SecurityFiles> files = net::security_files(security, error);
    if (!files) {
      std::fprintf(stderr, "mixpilot %s: %s\n", cmd, error.c_str());
      return kExitError;
    }
    net::use_security(*files);
  }
  if (in_window) {
    window.app.domain = domain;
    window.app.issuer = issuer;
    window.app.security = security;
    window.app.select = station;
    window.count = count;
    window.wait_s = wait_s;
    catch_interrupts();
    std::string error;
    const int status = run_instruct_window(window, error);
    if (status != kExitOk) std::fprintf(stderr, "mixpilot %s: %s\n", cmd, error.c_str());
    return status;
  }
  net::InstructorClient client;
  std::string error;
  if (!client.open({domain, issuer, nullptr, !list}, error)) {
    std::fprintf(stderr, "mixpilot %s: %s\n", cmd, error.c_str());
    // DDS Security refused this identity here: its files, its certificate or its permissions.
    return net::security_configured() ? kExitRefused : kExitError;
  }
  using clock = std::chrono::steady_clock;
  const auto deadline = clock::now() + std::chrono::duration_cast<clock::duration>(
                                           std::chrono::duration<double>(wait_s));
  if (list) {
    // Until --count stations with telemetry are heard, or --wait is over.
    while (clock::now() < deadline) {
      client.poll(0.05);
      if (count > 0) {
        int heard = 0;
        // Its telemetry, and an announcement newer than the one kept for late joiners.
        for (const net::StationView& v : client.stations())
          heard += v.poses > 0 && v.announcements >= 2 ? 1 : 0;
        if (heard >= count) break;
      }
    }
    const std::vector<net::StationView> stations = client.stations();
    std::printf("%zu station%s on domain %u\n", stations.size(), stations.size() == 1 ? "" : "s",
                unsigned(domain));
    for (const net::StationView& v : stations) print_station(v);
    if (count > 0 && int(stations.size()) < count) {
      std::fprintf(stderr, "mixpilot %s: %zu of %d stations heard within %g s%s\n", cmd,
                   stations.size(), count, wait_s, security_note().c_str());
      return kExitNoAnswer;
    }
    return kExitOk;
  }
  // The station heard and its command reader matched: a command sent earlier would be lost.
  while (clock::now() < deadline && !(client.station(station) && client.matched(station)))
    client.poll(0.05);
  if (!client.station(station) || !client.matched(station)) {
    const net::SecurityLog log = net::security_log();
    std::fprintf(stderr, "mixpilot %s: station %s %s within %g s on domain %u%s\n", cmd,
                 station.c_str(),
                 client.station(station) ? "was heard but never matched this command writer"
                                         : "was not heard",
                 wait_s, unsigned(domain), security_note().c_str());
    return log.refused > 0 ? kExitRefused : kExitNoAnswer;
  }
  const std::uint64_t number = sequence ? *sequence : client.next_sequence();
  if (!client.send(station, c, number, error)) {
    std::fprintf(stderr, "mixpilot %s: %s\n", cmd, error.c_str());
    return kExitError;
  }
  std::optional<net::CommandRefusal> result;
  const std::int64_t issued = client.last_issued_ns();
  while (clock::now() < deadline && !(result = client.result(station, number, issued)))
    client.poll(0.05);
  const std::string what = net::describe(c);
  if (!result) {
    std::fprintf(stderr, "mixpilot %s: station %s did not say what became of %s (number %llu) "
                 "within %g s\n", cmd, station.c_str(), what.c_str(), (unsigned long long)number,
                 wait_s);
    return kExitNoAnswer;
  }
  if (*result == net::CommandRefusal::none) {
    std::printf("station %s accepted %s (number %llu from %s)\n", station.c_str(), what.c_str(),
                (unsigned long long)number, issuer.c_str());
    return kExitOk;
  }
  const std::optional<net::StationView> v = client.station(station);
  std::printf("station %s refused %s (number %llu from %s): %s\n", station.c_str(), what.c_str(),
              (unsigned long long)number, issuer.c_str(),
              v && !v->last_refusal.empty() ? v->last_refusal.c_str() : net::to_string(*result));
  return kExitRefused;
}

}  // namespace mixpilot::cli
