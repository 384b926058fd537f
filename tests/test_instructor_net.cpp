// The instructor's network (SPEC §10, docs/instructor-security.md): what a station checks in a
// command (InstructorNetChecks, no DDS); a station's link and an instructor in one process, on
// loopback without DDS Security (InstructorNet); two station processes and `mixpilot instruct`
// processes, unauthenticated on loopback (InstructorNet) and with DDS Security and a test CA
// made by packaging/dds-security-ca.sh (Security).
//
// Every DDS test refuses to run unless CYCLONEDDS_URI keeps DDS on loopback (CTest sets it), and
// each test process uses its own domain id (0-230: Cyclone's access control refuses higher
// ones). Processes are waited for on conditions with generous timeouts, never timed.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>
#include <string>
#include <thread>
#include <vector>

#include "input/net/dds.hpp"
#include "input/net/instructor_checks.hpp"
#include "input/net/instructor_client.hpp"
#include "input/net/instructor_link.hpp"
#include "net_test.hpp"
#include "run_mixpilot.hpp"
#include "spawned.hpp"
#include "temp_files.hpp"

namespace mixpilot::net {
namespace {

namespace fs = std::filesystem;
using test::read_file;
using test::Spawned;

constexpr std::int64_t kSecond = 1'000'000'000;

// --- The checks, on a clock of the test's -----------------------------------------------------

InstructorFields fields(std::uint8_t kind, std::uint64_t sequence, std::int64_t issued) {
  InstructorFields f;
  f.station = "A";
  f.issuer = "teacher";
  f.sequence = sequence;
  f.issued_ns = issued;
  f.kind = kind;
  return f;
}

TEST(InstructorNetChecks, EachKindsFieldsAreCheckedAndTakenExactly) {
  InstructorCheck check;
  check.setup({});
  const std::int64_t now = 1000 * kSecond;
  InstructorCommand out;
  RefusalNote note;
  std::uint64_t seq = 1;
  const auto check_one = [&](InstructorFields f) {
    f.sequence = seq++;
    return check.check(f, now, out, note);
  };
  const auto kind = [](InstructorCommandKind k) { return std::uint8_t(k); };
  InstructorFields f = fields(kind(InstructorCommandKind::bounds), 0, now);
  f.floor = 0.1;
  f.ceiling = 0.3;
  ASSERT_EQ(check_one(f), CommandRefusal::none);
  EXPECT_EQ(out.kind, InstructorCommandKind::bounds);
  EXPECT_EQ(out.bounds, (AuthorityBounds{0.1, 0.3}));
  for (const auto& [fl, ce] : {std::pair{0.4, 0.3}, {-0.1, 0.5}, {0.0, 1.01}, {double(NAN), 0.5}}) {
    f.floor = fl;
    f.ceiling = ce;
    EXPECT_EQ(check_one(f), CommandRefusal::bad_value) << fl << " " << ce;
  }
  f = fields(kind(InstructorCommandKind::gust), 0, now);
  f.force = {2, 0, 0};
  f.duration = 0.5;
  ASSERT_EQ(check_one(f), CommandRefusal::none);
  EXPECT_EQ(out.force, Eigen::Vector3d(2, 0, 0));
  EXPECT_EQ(out.duration, 0.5);
  EXPECT_EQ(out.bounds, AuthorityBounds{});  // another kind's fields keep their defaults
  f.force = {12, 12, 12};  // 20.8 N
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  char text[256];
  describe(note, text, sizeof text);
  EXPECT_STREQ(text, "bad value: a gust of 20.8 N (at most 20 N)");
  f.force = {2, 0, 0};
  for (const double d : {0.0, -1.0, 10.5, double(INFINITY)}) {
    f.duration = d;
    EXPECT_EQ(check_one(f), CommandRefusal::bad_value) << d;
  }
  f = fields(kind(InstructorCommandKind::extra_delay), 0, now);
  f.delay = 0.6;
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  f.delay = 0.5;
  EXPECT_EQ(check_one(f), CommandRefusal::none);
  f = fields(kind(InstructorCommandKind::input_loss), 0, now);
  f.duration = 2;
  EXPECT_EQ(check_one(f), CommandRefusal::none);
  EXPECT_EQ(out.duration, 2.0);
  f = fields(kind(InstructorCommandKind::marker), 0, now);
  f.text = "gust next: watch λ";
  ASSERT_EQ(check_one(f), CommandRefusal::none);
  EXPECT_EQ(out.text.view(), "gust next: watch λ");
  const std::string too_long(96, 'x'), bad_utf8 = "a\xff", control = "a\nb", cut = "\xce";
  for (const std::string* t : {&too_long, &bad_utf8, &control, &cut}) {
    f.text = *t;
    EXPECT_EQ(check_one(f), CommandRefusal::bad_value) << *t;
  }
  f.text = "";
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  f = fields(8, 0, now);  // no such kind
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  f = fields(kind(InstructorCommandKind::pause), 0, now);
  f.issuer = "";
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  f.issuer = std::string(64, 'i');
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
  f.issuer = "teacher";
  f.delay = NAN;  // a field the kind does not use must still be a number
  EXPECT_EQ(check_one(f), CommandRefusal::bad_value);
}

// Age against the station's clock (5 s old, 0.5 s ahead are the limits), order per issuer: a
// replay (the same number) and an older number are refused, another issuer has its own order;
// more issuers than the station keeps within the age window are refused as busy.
TEST(InstructorNetChecks, AgeAndOrderPerIssuer) {
  InstructorCheck check;
  check.setup({5.0, 0.5});
  const std::int64_t now = 1000 * kSecond;
  InstructorCommand out;
  RefusalNote note;
  const auto pause = [&](std::string_view issuer, std::uint64_t seq, std::int64_t issued,
                         std::int64_t at) {
    InstructorFields f = fields(std::uint8_t(InstructorCommandKind::pause), seq, issued);
    f.issuer = issuer;
    return check.check(f, at, out, note);
  };
  EXPECT_EQ(pause("t", 10, now - 5 * kSecond - 1'000'000, now), CommandRefusal::stale);
  EXPECT_EQ(pause("t", 10, now + 600'000'000, now), CommandRefusal::stale);
  EXPECT_EQ(pause("t", 10, now + 400'000'000, now), CommandRefusal::none);
  EXPECT_EQ(pause("t", 10, now, now), CommandRefusal::replayed);
  char text[256];
  describe(note, text, sizeof text);
  EXPECT_STREQ(text, "replayed: number 10 from this issuer, not above the last one taken (10)");
  EXPECT_EQ(pause("t", 9, now, now), CommandRefusal::replayed);
  EXPECT_EQ(pause("u", 9, now, now), CommandRefusal::none);  // another issuer
  EXPECT_EQ(pause("t", 11, now, now), CommandRefusal::none);
  // A stale refusal takes nothing: the number is still free.
  EXPECT_EQ(pause("t", 12, now - 6 * kSecond, now), CommandRefusal::stale);
  EXPECT_EQ(pause("t", 12, now, now), CommandRefusal::none);
  for (int i = 2; i < InstructorCheck::kMaxIssuers; ++i)
    ASSERT_EQ(pause("issuer" + std::to_string(i), 1, now, now), CommandRefusal::none) << i;
  EXPECT_EQ(pause("one too many", 1, now, now), CommandRefusal::busy);
  // Once every issuer's last command is older than any replay could be, a new one fits...
  const std::int64_t later = now + 6 * kSecond;
  EXPECT_EQ(pause("one too many", 1, later, later), CommandRefusal::none);
  // ...and a replay of a forgotten issuer's old command is stale anyway.
  EXPECT_EQ(pause("u", 9, now, later), CommandRefusal::stale);
}

TEST(InstructorNetChecks, PrintableUtf8) {
  EXPECT_TRUE(printable_utf8("λ 0.3 — ok ✓"));
  EXPECT_FALSE(printable_utf8("tab\there"));
  EXPECT_FALSE(printable_utf8("\xc0\xaf"));          // overlong
  EXPECT_FALSE(printable_utf8("\xed\xa0\x80"));      // a surrogate
  EXPECT_FALSE(printable_utf8("\xc2\x85"));          // C1 control
  EXPECT_FALSE(printable_utf8("\xf4\x90\x80\x80"));  // beyond U+10FFFF
  EXPECT_FALSE(printable_utf8("\xe2\x82"));          // cut short
}

// Unauthenticated commands only while DDS stays on loopback; the policy from the choices.
TEST(InstructorNetChecks, UnauthenticatedCommandsOnlyOnLoopback) {
  const char* before = std::getenv("CYCLONEDDS_URI");
  const std::string saved = before ? before : "";
  CommandSecurity s{};
  std::string error;
  setenv("CYCLONEDDS_URI", "<General><AllowMulticast>false</AllowMulticast></General>", 1);
  EXPECT_FALSE(command_security(true, false, true, s, error));
  EXPECT_NE(error.find("accepted only while DDS stays on this machine"), std::string::npos) << error;
  EXPECT_NE(error.find("loopback"), std::string::npos) << error;
  setenv("CYCLONEDDS_URI", loopback_config_uri().c_str(), 1);
  ASSERT_TRUE(command_security(true, false, true, s, error)) << error;
  EXPECT_EQ(s, CommandSecurity::unauthenticated_loopback);
  ASSERT_TRUE(command_security(true, false, false, s, error));
  EXPECT_EQ(s, CommandSecurity::unauthenticated_refused);
  ASSERT_TRUE(command_security(true, true, true, s, error));
  EXPECT_EQ(s, CommandSecurity::dds_security);
  ASSERT_TRUE(command_security(false, true, false, s, error));
  EXPECT_EQ(s, CommandSecurity::no_instructor);
  if (before) setenv("CYCLONEDDS_URI", saved.c_str(), 1);
  else unsetenv("CYCLONEDDS_URI");
}

// --- A link and an instructor in this process, unauthenticated on loopback --------------------

class InstructorNet : public Net {};

// Commands reach the ring exactly as sent; a replay, a stale one, one with a bad value and one
// for another station do not; the station announces its counts and each result, which the
// instructor reads back.
TEST_F(InstructorNet, ALinkTakesCheckedCommandsIntoTheFlightsRing) {
  SpscRing<InstructorCommand> ring;
  ring.setup(8, InstructorCommand{});
  InstructorLink link;
  InstructorLink::Options lo;
  lo.domain = domain_;
  lo.station = {"A", "trainee", "mi_helix", "mixed_initiative", 30.0, 0.175};
  lo.security = CommandSecurity::unauthenticated_loopback;
  std::string error;
  ASSERT_TRUE(link.start(lo, &ring, error)) << error;
  InstructorClient teacher;
  ASSERT_TRUE(teacher.open({domain_, "teacher"}, error)) << error;
  ASSERT_TRUE(eventually([&] {
    teacher.poll(0.01);
    return teacher.station("A") && teacher.matched("A");
  }, 20));
  const std::optional<StationView> a = teacher.station("A");
  EXPECT_EQ(a->trainee, "trainee");
  EXPECT_EQ(a->scenario, "mi_helix");
  EXPECT_EQ(a->security, CommandSecurity::unauthenticated_loopback);
  EXPECT_TRUE(a->accepts_instructor);

  InstructorCommand ceiling;
  ceiling.kind = InstructorCommandKind::bounds;
  ceiling.bounds = {0.0, 0.3};
  InstructorCommand gust;
  gust.kind = InstructorCommandKind::gust;
  gust.force = {2, 0, 0};
  gust.duration = 0.5;
  ASSERT_TRUE(teacher.send("A", ceiling, 1, error)) << error;
  ASSERT_TRUE(teacher.send("A", gust, 2, error)) << error;
  ASSERT_TRUE(teacher.send("A", gust, 2, error)) << error;  // replayed
  ASSERT_TRUE(teacher.send("A", gust, 3, error, system_ns() - 30 * kSecond)) << error;  // stale
  InstructorFields bad;
  bad.station = "A";
  bad.issuer = "teacher";
  bad.sequence = 4;
  bad.issued_ns = system_ns();
  bad.kind = std::uint8_t(InstructorCommandKind::bounds);
  bad.floor = 0.5;
  bad.ceiling = NAN;
  ASSERT_TRUE(teacher.send_fields(bad, error)) << error;
  ASSERT_TRUE(teacher.send("B", ceiling, 5, error)) << error;  // another station's
  ASSERT_TRUE(eventually([&] {
    const InstructorLinkStats s = link.stats();
    return s.accepted + s.refused_total() + s.ignored >= 6;
  }, 20));
  const InstructorLinkStats s = link.stats();
  EXPECT_EQ(s.accepted, 2u);
  EXPECT_EQ(s.refused[std::size_t(CommandRefusal::replayed)], 1u);
  EXPECT_EQ(s.refused[std::size_t(CommandRefusal::stale)], 1u);
  EXPECT_EQ(s.refused[std::size_t(CommandRefusal::bad_value)], 1u);
  EXPECT_EQ(s.refused_total(), 3u);
  EXPECT_EQ(s.ignored, 1u);
  InstructorCommand taken;
  ASSERT_TRUE(ring.pop(taken));
  EXPECT_EQ(taken, ceiling);
  ASSERT_TRUE(ring.pop(taken));
  EXPECT_EQ(taken, gust);
  EXPECT_FALSE(ring.pop(taken));
  // The announcement says the same, and each result.
  ASSERT_TRUE(eventually([&] {
    teacher.poll(0.01);
    const auto v = teacher.station("A");
    return v && v->accepted + v->refused_total() == 5 && teacher.result("A", 4);
  }, 20));
  const StationView v = *teacher.station("A");
  EXPECT_EQ(v.refused, s.refused);
  EXPECT_EQ(teacher.result("A", 1), CommandRefusal::none);
  EXPECT_EQ(teacher.result("A", 3), CommandRefusal::stale);
  EXPECT_EQ(teacher.result("A", 4), CommandRefusal::bad_value);
  EXPECT_NE(v.last_refusal.find("bad value"), std::string::npos) << v.last_refusal;
  link.stop();
}

// What a station announces of its flight's state for an instructor's tile: READY gives the λ
// the first step will use and the bounds (not a λ of 0), and while it flies, what the
// instructor's commands keep in force — bounds, a gust and its time left, an extra delay, an
// input loss — and the instructor's pause, each announced once it starts and once it ends (a
// gust of half a second falls between two of the twice-a-second announcements).
TEST_F(InstructorNet, TheAnnouncementSaysWhatIsInForce) {
  SpscRing<InstructorCommand> ring;
  ring.setup(8, InstructorCommand{});
  InstructorLink link;
  InstructorLink::Options lo;
  lo.domain = domain_;
  lo.station = {"A", "trainee", "mi_helix", "mixed_initiative", 30.0, 0.175};
  lo.security = CommandSecurity::unauthenticated_loopback;
  // Announcements far apart: what is seen soon came from a change, not from the period.
  lo.announce_period_s = 3600.0;
  std::atomic<bool> paused{false};
  lo.paused = [&paused] { return paused.load(); };
  std::string error;
  ASSERT_TRUE(link.start(lo, &ring, error)) << error;
  Telemetry s;
  s.mode = ModeKind::mixed_initiative;
  s.lambda = 0.3;
  s.instructor.bounds = {0.0, 0.3};
  link.ready(s);
  InstructorClient teacher;
  ASSERT_TRUE(teacher.open({domain_, "teacher", nullptr, false}, error)) << error;
  const auto heard = [&](auto done) {
    return eventually([&] {
      teacher.poll(0.01);
      const std::optional<StationView> v = teacher.station("A");
      return v && done(*v);
    }, 30);
  };
  // The first announcement (at start) came before ready(); a change announces again.
  ASSERT_TRUE(heard([](const StationView& v) {
    return v.in_force.bounds == AuthorityBounds{0.0, 0.3};
  }));
  StationView v = *teacher.station("A");
  EXPECT_EQ(v.state, StationState::ready);
  EXPECT_EQ(v.lambda, 0.3);
  EXPECT_EQ(v.mean_lambda, 0.0);  // READY is no sample

  // Flying, a gust starts: announced at once, with its force and time left.
  s.t = 1.0;
  s.lambda = 0.25;
  s.x = Eigen::VectorXd::Zero(16);
  s.reference = Eigen::VectorXd::Zero(3);
  s.instructor.gust = {2.0, 0.0, 0.0};
  s.instructor.gust_left = 0.5;
  link.on_sample(s);
  ASSERT_TRUE(heard([](const StationView& v) { return v.in_force.gust_left > 0.0; }));
  v = *teacher.station("A");
  EXPECT_EQ(v.state, StationState::flying);
  EXPECT_EQ(v.in_force.gust, Eigen::Vector3d(2.0, 0.0, 0.0));
  EXPECT_EQ(v.in_force.gust_left, 0.5);
  EXPECT_EQ(v.in_force.bounds, (AuthorityBounds{0.0, 0.3}));
  // Its time running down is no news; its end, an extra delay and an input loss are.
  const std::uint64_t announced = v.announcements;
  s.t = 1.2;
  s.instructor.gust_left = 0.3;
  link.on_sample(s);
  s.t = 1.6;
  s.instructor.gust = Eigen::Vector3d::Zero();
  s.instructor.gust_left = 0.0;
  s.instructor.extra_delay = 0.1;
  s.instructor.input_loss_left = 0.8;
  s.instructor.bounds = {};
  link.on_sample(s);
  ASSERT_TRUE(heard([](const StationView& v) { return v.in_force.extra_delay > 0.0; }));
  v = *teacher.station("A");
  EXPECT_EQ(v.in_force.gust_left, 0.0);
  EXPECT_EQ(v.in_force.extra_delay, 0.1);
  EXPECT_EQ(v.in_force.input_loss_left, 0.8);
  EXPECT_EQ(v.in_force.bounds, AuthorityBounds{});
  EXPECT_EQ(v.t, 1.6);
  EXPECT_EQ(v.announcements, announced + 1);  // not one for the gust running down at 1.2 s
  // The instructor's pause.
  paused = true;
  ASSERT_TRUE(heard([](const StationView& v) { return v.state == StationState::paused; }));
  link.stop();
}

// A station that obeys no instructor, or has no DDS Security without the explicit permission,
// refuses every command, and says why.
TEST_F(InstructorNet, AStationRefusesWhatItMayNotObey) {
  for (const CommandSecurity policy :
       {CommandSecurity::no_instructor, CommandSecurity::unauthenticated_refused}) {
    SpscRing<InstructorCommand> ring;
    ring.setup(8, InstructorCommand{});
    InstructorLink link;
    InstructorLink::Options lo;
    lo.domain = domain_;
    lo.station.name = policy == CommandSecurity::no_instructor ? "closed" : "insecure";
    lo.security = policy;
    std::string error;
    ASSERT_TRUE(link.start(lo, &ring, error)) << error;
    InstructorClient teacher;
    ASSERT_TRUE(teacher.open({domain_, "teacher"}, error)) << error;
    ASSERT_TRUE(eventually([&] {
      teacher.poll(0.01);
      return teacher.matched(lo.station.name);
    }, 20));
    InstructorCommand pause;
    pause.kind = InstructorCommandKind::pause;
    ASSERT_TRUE(teacher.send(lo.station.name, pause, 1, error)) << error;
    ASSERT_TRUE(eventually([&] {
      teacher.poll(0.01);
      return teacher.result(lo.station.name, 1).has_value();
    }, 20));
    const CommandRefusal expected = policy == CommandSecurity::no_instructor
                                        ? CommandRefusal::not_allowed
                                        : CommandRefusal::unauthenticated;
    EXPECT_EQ(teacher.result(lo.station.name, 1), expected);
    EXPECT_EQ(link.stats().refused[std::size_t(expected)], 1u);
    InstructorCommand none;
    EXPECT_FALSE(ring.pop(none));
    link.stop();
  }
}

// --- Processes ----------------------------------------------------------------------------------

std::vector<std::pair<std::string, std::string>> user_dirs(const fs::path& dir) {
  return {{"XDG_CONFIG_HOME", (dir / "config").string()}, {"XDG_DATA_HOME", (dir / "data").string()}};
}

// A station: the novice flies mi_helix's five-minute variant headless in real time, announced and
// publishing, long enough for any test on a loaded machine (it is interrupted at the end).
std::vector<std::string> station(const std::string& name, std::uint32_t domain,
                                 std::vector<std::string> more) {
  std::vector<std::string> a = {kMixpilot, "fly", "--scenario", kSrc + "/scenarios/mi_helix_endurance.toml",
                                "--pilot", "novice", "--headless", "--realtime", "--publish", "--domain", std::to_string(domain),
                                "--station", name, "--history", "off"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

std::vector<std::string> instruct(std::uint32_t domain, std::vector<std::string> more) {
  std::vector<std::string> a = {kMixpilot, "instruct", "--domain", std::to_string(domain),
                                "--wait", "30"};
  a.insert(a.end(), more.begin(), more.end());
  return a;
}

// Waits until a started station says it is announced (its first line); false when it ended
// first or did not say so in time.
bool announced(Spawned& p, const fs::path& out, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (read_file(out).find("announced on rt/mixpilot/station") == std::string::npos) {
    if (std::chrono::steady_clock::now() > until || p.wait(0) >= 0) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return true;
}

// Two stations (A obeys unauthenticated commands on loopback, B obeys no instructor) and
// `mixpilot instruct` processes: the instructor lists both; A accepts a ceiling, B refuses a
// pause; a replayed number is refused; each station's summary counts what it did.
TEST_F(InstructorNet, TwoStationsAndAnInstructorProcess) {
  const fs::path dir = test::fresh_path("instructor_net", "two_stations");
  fs::create_directories(dir);
  const std::uint32_t d = domain_;
  Spawned a(station("A", d, {"--instructor", "--allow-unauthenticated-commands"}), dir / "a.txt",
            user_dirs(dir));
  Spawned b(station("B", d, {}), dir / "b.txt", user_dirs(dir));
  ASSERT_TRUE(announced(a, dir / "a.txt", 60)) << read_file(dir / "a.txt");
  ASSERT_TRUE(announced(b, dir / "b.txt", 60)) << read_file(dir / "b.txt");
  const auto run = [&](std::vector<std::string> args, const char* out) {
    return test::run_to_end(instruct(d, std::move(args)), dir / out, 90, user_dirs(dir));
  };
  ASSERT_EQ(run({"--list", "--count", "2"}, "list.txt"), 0) << read_file(dir / "list.txt");
  const std::string list = read_file(dir / "list.txt");
  std::printf("%s", list.c_str());
  EXPECT_NE(list.find("2 stations on domain " + std::to_string(d)), std::string::npos);
  EXPECT_TRUE(std::regex_search(list, std::regex(
      R"(A: trainee \S+, mi_helix_endurance \(mixed_initiative\), flying at)")));
  EXPECT_NE(list.find("instructor: unauthenticated, loopback"), std::string::npos);
  EXPECT_NE(list.find("instructor: no instructor"), std::string::npos);
  EXPECT_EQ(run({"--station", "A", "--ceiling", "0.3"}, "ceiling.txt"), 0)
      << read_file(dir / "ceiling.txt");
  EXPECT_NE(read_file(dir / "ceiling.txt").find("station A accepted bounds: λ floor 0, ceiling 0.3"),
            std::string::npos);
  EXPECT_EQ(run({"--station", "B", "--pause"}, "pause.txt"), 4) << read_file(dir / "pause.txt");
  EXPECT_NE(read_file(dir / "pause.txt").find("refused pause"), std::string::npos);
  EXPECT_NE(read_file(dir / "pause.txt").find("instructor not allowed"), std::string::npos);
  EXPECT_EQ(run({"--station", "A", "--issuer", "replayer", "--sequence", "7", "--gust", "2,0,0",
                 "--duration", "0.5"}, "gust.txt"), 0) << read_file(dir / "gust.txt");
  EXPECT_EQ(run({"--station", "A", "--issuer", "replayer", "--sequence", "7", "--gust", "2,0,0",
                 "--duration", "0.5"}, "replay.txt"), 4) << read_file(dir / "replay.txt");
  EXPECT_NE(read_file(dir / "replay.txt").find("replayed: number 7 from this issuer"),
            std::string::npos) << read_file(dir / "replay.txt");
  EXPECT_EQ(run({"--station", "nowhere", "--end", "--wait", "1"}, "nowhere.txt"), 5);
  a.interrupt();
  b.interrupt();
  ASSERT_GE(a.wait(60), 0);
  ASSERT_GE(b.wait(60), 0);
  const std::string sa = read_file(dir / "a.txt"), sb = read_file(dir / "b.txt");
  std::printf("%s%s", sa.c_str(), sb.c_str());
  EXPECT_NE(sa.find("station A: instructor commands obeyed unauthenticated "
                    "(--allow-unauthenticated-commands, loopback only); 2 accepted, 1 refused "
                    "(1 replayed)"), std::string::npos);
  EXPECT_NE(sb.find("station B: instructor commands refused (it obeys no instructor: "
                    "--instructor); 0 accepted, 1 refused (1 instructor not allowed)"),
            std::string::npos);
}

// The command line refuses what no station could obey, before any DDS; a station refuses to
// obey unauthenticated commands when DDS is not bound to loopback, and says so.
TEST_F(InstructorNet, TheCommandLineSaysWhatIsWrong) {
  const fs::path dir = test::fresh_path("instructor_net", "usage");
  fs::create_directories(dir);
  const auto usage = [&](const std::string& args, const std::string& expected) {
    EXPECT_EQ(run("instruct " + args, dir), 2) << args;
    EXPECT_NE(read_file(dir / "out.txt").find(expected), std::string::npos)
        << args << ": " << read_file(dir / "out.txt");
  };
  usage("--headless", "--headless renders only --screenshot");
  usage("--list --headless", "go with the window");
  usage("--pause", "to which station?");
  usage("--station A --gust 2,0,0", "--gust needs --duration");
  usage("--station A --gust 30,0,0 --duration 1", "at most 20 N");
  usage("--station A --floor 0.6 --ceiling 0.4", "the floor must not be above the ceiling");
  usage("--station A --pause --end", "one command per run");
  usage("--list --pause", "--list sends no command");
  usage("--station A --marker ''", "--marker");
  usage("--station A --delay 0.8", "--delay expects seconds from 0 to 0.5");
  EXPECT_EQ(run("fly --scenario " + kSrc + "/scenarios/mi_helix.toml --headless --instructor",
                dir), 2);
  EXPECT_NE(read_file(dir / "out.txt").find("--instructor goes with --publish"), std::string::npos);
  const std::string off_loopback =
      "env CYCLONEDDS_URI='<CycloneDDS><Domain><General><AllowMulticast>false</AllowMulticast>"
      "</General></Domain></CycloneDDS>' '" + kMixpilot + "' fly --scenario " + kSrc +
      "/scenarios/mi_helix.toml --headless --duration 1 --history off --publish --instructor "
      "--allow-unauthenticated-commands >'" + (dir / "off.txt").string() + "' 2>&1";
  const int rc = std::system(off_loopback.c_str());
  EXPECT_EQ(WEXITSTATUS(rc), 1);
  EXPECT_NE(read_file(dir / "off.txt").find("--allow-unauthenticated-commands is accepted only "
                                            "while DDS stays on this machine"),
            std::string::npos) << read_file(dir / "off.txt");
}

// $XDG_CONFIG_HOME/mixpilot/station.toml names the station and lets it obey an instructor for
// every flight that publishes; the command line wins; a broken file is said with its place.
TEST_F(InstructorNet, AStationsSettingsNameItAndAllowAnInstructor) {
  const fs::path dir = test::fresh_path("instructor_net", "settings");
  fs::create_directories(dir / "config" / "mixpilot");
  const fs::path settings = dir / "config" / "mixpilot" / "station.toml";
  std::ofstream(settings) << "name = \"from-settings\"\ninstructor = true\n";
  const std::string fly = "fly --scenario " + kSrc + "/scenarios/mi_helix.toml --pilot novice "
                          "--headless --duration 0.3 --history off --publish --domain " +
                          std::to_string(domain_) + " --allow-unauthenticated-commands";
  ASSERT_EQ(run(fly, dir), 0) << read_file(dir / "out.txt");
  EXPECT_NE(read_file(dir / "out.txt").find("station from-settings announced on "
                                            "rt/mixpilot/station"), std::string::npos)
      << read_file(dir / "out.txt");
  EXPECT_NE(read_file(dir / "out.txt").find("obeyed unauthenticated"), std::string::npos);
  ASSERT_EQ(run(fly + " --station cli-name", dir), 0) << read_file(dir / "out.txt");
  EXPECT_NE(read_file(dir / "out.txt").find("station cli-name announced"), std::string::npos);
  std::ofstream(settings) << "name = \"s\"\ninstructor = \"yes\"\n";
  EXPECT_EQ(run(fly, dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("station.toml:2:14: instructor: expected true or "
                                            "false"), std::string::npos)
      << read_file(dir / "out.txt");
  std::ofstream(settings) << "nmae = \"s\"\n";
  EXPECT_EQ(run(fly, dir), 1);
  EXPECT_NE(read_file(dir / "out.txt").find("nmae: not a station setting"), std::string::npos);
}

// --- DDS Security -------------------------------------------------------------------------------

// A domain of this process's own that Cyclone's access control accepts (0-230).
std::uint32_t secure_domain() { return 1 + std::uint32_t(getpid()) % 230; }

// With a test CA made by the script: two stations (each its trainee's certificate, both obey an
// instructor), an observer in this process with the instructor's identity, and `mixpilot
// instruct` processes as every kind of peer. Only the certified instructor's commands are
// accepted; a trainee's certificate, another CA's, an expired one and a peer without a
// certificate are refused (at the sender, where DDS Security refuses them before anything is
// sent, and counted at the station where its DDS logs the refused handshake), a replayed number
// is refused, a writer without a certificate on the command topic is never matched; telemetry
// flows to the instructor throughout.
class Security : public Net {};

TEST_F(Security, OnlyACertifiedInstructorCommands) {
  const fs::path dir = test::fresh_path("instructor_net", "security");
  fs::create_directories(dir);
  const fs::path ca = dir / "ca";
  ASSERT_EQ(test::run_to_end({"/bin/bash", kSrc + "/packaging/dds-security-ca.sh", ca.string()},
                             dir / "ca.txt", 120), 0) << read_file(dir / "ca.txt");
  const std::uint32_t d = secure_domain();
  const auto id = [&](const char* who) { return (ca / who).string(); };
  Spawned a(station("A", d, {"--instructor", "--dds-security", id("trainee-a")}), dir / "a.txt",
            user_dirs(dir));
  Spawned b(station("B", d, {"--instructor", "--dds-security", id("trainee-b")}), dir / "b.txt",
            user_dirs(dir));
  ASSERT_TRUE(announced(a, dir / "a.txt", 60)) << read_file(dir / "a.txt");
  ASSERT_TRUE(announced(b, dir / "b.txt", 60)) << read_file(dir / "b.txt");
  EXPECT_NE(read_file(dir / "a.txt").find("instructor commands obeyed from a certified "
                                          "instructor (DDS Security)"), std::string::npos);

  // The instructor watches from here: both stations and their telemetry.
  std::string error;
  const std::optional<SecurityFiles> files = security_files(id("instructor"), error);
  ASSERT_TRUE(files) << error;
  InstructorClient watch;
  ASSERT_TRUE(watch.open({d, "", &*files, false}, error)) << error;
  const auto poses = [&](const char* s) {
    const auto v = watch.station(s);
    return v ? v->poses : 0;
  };
  ASSERT_TRUE(eventually([&] {
    watch.poll(0.01);
    return poses("A") > 0 && poses("B") > 0;
  }, 60));
  const std::uint64_t poses_a = poses("A"), poses_b = poses("B");

  const auto run = [&](std::vector<std::string> args, const char* out) {
    return test::run_to_end(instruct(d, std::move(args)), dir / out, 90, user_dirs(dir));
  };
  const auto as = [&](const char* who, std::vector<std::string> args) {
    args.insert(args.begin(), {"--dds-security", id(who)});
    return args;
  };
  // The instructor lists both and is obeyed.
  ASSERT_EQ(run(as("instructor", {"--list", "--count", "2"}), "list.txt"), 0)
      << read_file(dir / "list.txt");
  EXPECT_NE(read_file(dir / "list.txt").find("2 stations on domain"), std::string::npos);
  EXPECT_EQ(run(as("instructor", {"--station", "A", "--ceiling", "0.3"}), "ceiling.txt"), 0)
      << read_file(dir / "ceiling.txt");
  EXPECT_EQ(run(as("instructor", {"--station", "A", "--issuer", "r", "--sequence", "9",
                                  "--marker", "watch the gust"}), "marker.txt"), 0)
      << read_file(dir / "marker.txt");
  // A replay of the same number.
  EXPECT_EQ(run(as("instructor", {"--station", "A", "--issuer", "r", "--sequence", "9",
                                  "--marker", "watch the gust"}), "replay.txt"), 4)
      << read_file(dir / "replay.txt");
  EXPECT_NE(read_file(dir / "replay.txt").find("replayed"), std::string::npos);
  // A trainee's certificate: its permissions do not allow the command writer.
  EXPECT_EQ(run(as("trainee-b", {"--station", "A", "--ceiling", "1"}), "trainee.txt"), 4);
  EXPECT_NE(read_file(dir / "trainee.txt").find("permissions do not allow an instructor's "
                                                "commands"), std::string::npos)
      << read_file(dir / "trainee.txt");
  // An expired certificate: Cyclone refuses it before it joins.
  EXPECT_EQ(run(as("expired", {"--station", "A", "--ceiling", "1"}), "expired.txt"), 4);
  EXPECT_NE(read_file(dir / "expired.txt").find("certificate has expired"), std::string::npos)
      << read_file(dir / "expired.txt");
  // Another CA's certificate: the handshake fails on both sides; the station counts it.
  EXPECT_EQ(run(as("other-ca", {"--station", "A", "--ceiling", "1", "--wait", "5"}),
                "other.txt"), 4);
  EXPECT_NE(read_file(dir / "other.txt").find("unable to get local issuer certificate"),
            std::string::npos) << read_file(dir / "other.txt");
  ASSERT_TRUE(eventually([&] {
    watch.poll(0.01);
    const auto v = watch.station("A");
    return v && v->security_refused > 0;
  }, 30));
  EXPECT_NE(watch.station("A")->security_last.find("unable to get local issuer certificate"),
            std::string::npos) << watch.station("A")->security_last;
  // No certificate: the secured stations are not even heard, and its command writer on the
  // command topic (what would carry an altered command into the station) never matches.
  // (Cyclone 0.10 refuses an unsecured participant beside a secured one in the same domain of
  // one process, so this peer is a process of its own.)
  EXPECT_EQ(run({"--station", "A", "--ceiling", "1", "--wait", "2"}, "none.txt"), 5);
  EXPECT_NE(read_file(dir / "none.txt").find("station A was not heard"), std::string::npos);
  // The instructor is obeyed again after all of them.
  EXPECT_EQ(run(as("instructor", {"--station", "A", "--marker", "after the others"}),
                "after.txt"), 0) << read_file(dir / "after.txt");

  // What the station announced: 3 accepted, 1 replayed, nothing else reached it.
  ASSERT_TRUE(eventually([&] {
    watch.poll(0.01);
    const auto v = watch.station("A");
    return v && v->accepted == 3;
  }, 30));
  const StationView va = *watch.station("A");
  EXPECT_EQ(va.refused_total(), 1u);
  EXPECT_EQ(va.refused[std::size_t(CommandRefusal::replayed)], 1u);
  EXPECT_EQ(watch.station("B")->accepted, 0u);
  // Telemetry kept flowing to the instructor throughout.
  ASSERT_TRUE(eventually([&] {
    watch.poll(0.01);
    return poses("A") > poses_a && poses("B") > poses_b;
  }, 30));
  a.interrupt();
  b.interrupt();
  ASSERT_GE(a.wait(60), 0);
  ASSERT_GE(b.wait(60), 0);
  const std::string sa = read_file(dir / "a.txt");
  std::printf("%s", sa.c_str());
  EXPECT_NE(sa.find("station A: instructor commands obeyed from a certified instructor (DDS "
                    "Security); 3 accepted, 1 refused (1 replayed)"), std::string::npos);
  EXPECT_TRUE(std::regex_search(sa, std::regex(R"(DDS Security refused peers \d+ times)")));
}

}  // namespace
}  // namespace mixpilot::net
