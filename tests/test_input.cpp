// The input layer (SPEC §6): the stick mapping and its inverse, the settings file, the
// wait-free hand-over, the input-loss rule, the keyboard's ramp, the haptic cue, and SDL's real
// path through a virtual gamepad (no hardware, no display).
#include <gtest/gtest.h>

#include <SDL2/SDL.h>
#include <pwd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <cmath>
#include <numbers>
#include <thread>

#include "input/device_pilot.hpp"
#include "input/gamepad.hpp"
#include "input/mapping_wizard.hpp"
#include "input/keyboard.hpp"
#include "core/base/latest.hpp"
#include "input/mapping.hpp"
#include "input/settings.hpp"
#include "input/virtual_gamepad.hpp"
#include "models/mikrokopter.hpp"
#include "temp_files.hpp"

namespace mixpilot::input {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180.0;

TEST(Shape, DeadzoneExpoRateAndInversion) {
  const AxisSettings a{0.1, 0.5, 1.0, false};
  EXPECT_EQ(shape(0.0, a), 0.0);
  EXPECT_EQ(shape(0.1, a), 0.0);  // the deadzone's edge
  EXPECT_EQ(shape(-0.05, a), 0.0);
  EXPECT_DOUBLE_EQ(shape(1.0, a), 1.0);
  EXPECT_DOUBLE_EQ(shape(-1.0, a), -1.0);
  // Half-way past the deadzone: r = 0.5 → (1 − e) r + e r³ = 0.25 + 0.0625.
  EXPECT_DOUBLE_EQ(shape(0.55, a), 0.3125);
  EXPECT_DOUBLE_EQ(shape(-0.55, a), -0.3125);
  // Odd and non-decreasing.
  for (double x = -1; x <= 1; x += 0.01) {
    EXPECT_DOUBLE_EQ(shape(-x, a), -shape(x, a));
    EXPECT_LE(shape(x, a), shape(x + 0.01, a) + 1e-15);
  }
  AxisSettings inv = a;
  inv.invert = true;
  EXPECT_DOUBLE_EQ(shape(0.55, inv), -0.3125);
  AxisSettings fast = a;
  fast.rate = 2.0;
  EXPECT_DOUBLE_EQ(shape(0.55, fast), 0.625);
  EXPECT_EQ(shape(1.0, fast), 1.0);  // clamped
  EXPECT_EQ(shape(3.0, a), 1.0);     // raw values beyond ±1 are clamped first
}

TEST(Shape, UnshapeIsItsInverse) {
  for (const AxisSettings a : {AxisSettings{}, AxisSettings{0.2, 0.9, 0.7, true},
                               AxisSettings{0.0, 0.0, 1.0, false}}) {
    for (double y = -0.99 * a.rate; y <= 0.99 * a.rate; y += 0.013) {
      if (std::abs(y) > 1) continue;
      EXPECT_NEAR(shape(unshape(y, a), a), y, 1e-12) << y;
    }
    EXPECT_EQ(unshape(0.0, a), 0.0);
  }
}

TEST(StickModes, EachModePlacesTheControlsAndUnassignInvertsIt) {
  const StickAxes s{0.1, 0.2, 0.3, 0.4};  // left x, left y, right x, right y
  // Mode 2 (SPEC §6): left vertical = thrust, left horizontal = yaw, right = pitch + roll.
  const Controls m2 = assign(s, 2);
  EXPECT_EQ(m2.thrust, 0.2);
  EXPECT_EQ(m2.yaw, 0.1);
  EXPECT_EQ(m2.pitch, 0.4);
  EXPECT_EQ(m2.roll, 0.3);
  const Controls m1 = assign(s, 1);  // left: pitch + yaw; right: thrust + roll
  EXPECT_EQ(m1.pitch, 0.2);
  EXPECT_EQ(m1.yaw, 0.1);
  EXPECT_EQ(m1.thrust, 0.4);
  EXPECT_EQ(m1.roll, 0.3);
  const Controls m3 = assign(s, 3);  // left: pitch + roll; right: thrust + yaw
  EXPECT_EQ(m3.pitch, 0.2);
  EXPECT_EQ(m3.roll, 0.1);
  EXPECT_EQ(m3.thrust, 0.4);
  EXPECT_EQ(m3.yaw, 0.3);
  const Controls m4 = assign(s, 4);  // left: thrust + roll; right: pitch + yaw
  EXPECT_EQ(m4.thrust, 0.2);
  EXPECT_EQ(m4.roll, 0.1);
  EXPECT_EQ(m4.pitch, 0.4);
  EXPECT_EQ(m4.yaw, 0.3);
  for (int mode = 1; mode <= 4; ++mode) {
    const StickAxes back = unassign(assign(s, mode), mode);
    EXPECT_EQ(back.left_x, s.left_x);
    EXPECT_EQ(back.left_y, s.left_y);
    EXPECT_EQ(back.right_x, s.right_x);
    EXPECT_EQ(back.right_y, s.right_y);
  }
}

// Angle mode and Remark 3: full stick = max tilt; centre thrust = hover; F_z,h = 4 C_T Ω_h².
TEST(Command, AngleModeAndThrustAroundHover) {
  const models::MikroKopter model;
  const double hover = model.hover_speed();
  InputSettings s;
  PilotCommand c;
  to_command(Controls{1.0, -0.5, 0.0, 0.7}, s, hover, c);
  EXPECT_DOUBLE_EQ(c.roll, 30 * kDeg);
  EXPECT_DOUBLE_EQ(c.pitch, -15 * kDeg);
  EXPECT_DOUBLE_EQ(c.rotor_speed(0), hover);  // yaw does not enter ν^r
  const double hover_thrust = model.p.m * model.p.g;
  for (const double thrust : {-1.0, -0.3, 0.4, 1.0}) {
    to_command(Controls{0, 0, thrust, 0}, s, hover, c);
    const double F = 4 * model.p.C_T * c.rotor_speed(0) * c.rotor_speed(0);
    EXPECT_NEAR(F, hover_thrust * (1 + s.thrust_range * thrust), 1e-12 * hover_thrust);
    EXPECT_EQ(c.rotor_speed(1), c.rotor_speed(0));
    const Controls back = controls_for(c, s, hover);
    EXPECT_NEAR(back.thrust, thrust, 1e-12);
  }
}

TEST(Haptic, IntensityGrowsAsLambdaFallsBelowTheThreshold) {
  const HapticSettings h{true, 0.5, 0.8};
  EXPECT_EQ(rumble_intensity(0.9, h), 0.0);
  EXPECT_EQ(rumble_intensity(0.5, h), 0.0);
  EXPECT_DOUBLE_EQ(rumble_intensity(0.25, h), 0.4);
  EXPECT_DOUBLE_EQ(rumble_intensity(0.0, h), 0.8);
  EXPECT_EQ(rumble_intensity(0.1, HapticSettings{false, 0.5, 0.8}), 0.0);
}

TEST(Settings, DefaultsRoundTripThroughTheFile) {
  InputSettings s;
  s.mode = 1;
  s.roll.expo = 0.55;
  s.yaw.invert = true;
  s.haptic.enabled = false;
  s.gamepad = "Pad \"X\"";
  std::string error;
  const auto back = parse_settings(to_toml(s), "x.toml", error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(back->mode, 1);
  EXPECT_EQ(back->roll.expo, 0.55);
  EXPECT_TRUE(back->yaw.invert);
  EXPECT_FALSE(back->haptic.enabled);
  EXPECT_EQ(back->gamepad, "Pad \"X\"");
  EXPECT_EQ(back->thrust.expo, 0.0);
}

TEST(Settings, EveryBadValueIsReportedWithItsPosition) {
  std::string error;
  const auto bad = [&](const std::string& text) {
    error.clear();
    EXPECT_FALSE(parse_settings(text, "in.toml", error));
    return error;
  };
  EXPECT_EQ(bad("mode = 5\n"), "in.toml:1:8: mode: value outside [1, 4], got 5");
  EXPECT_EQ(bad("max_tilt_deg = 90\n"), "in.toml:1:16: max_tilt_deg: value outside (0, 60], got 90");
  EXPECT_EQ(bad("max_tilt_deg = nan\n"),
            "in.toml:1:16: max_tilt_deg: expected a finite number, got nan");
  EXPECT_EQ(bad("[axes.roll]\ndeadzone = 0.7\n"),
            "in.toml:2:12: axes.roll.deadzone: value outside [0, 0.5], got 0.7");
  EXPECT_EQ(bad("[axes.pitch]\ninvert = 1\n"),
            "in.toml:2:10: axes.pitch.invert: expected true or false, got 1");
  EXPECT_EQ(bad("[haptic]\nthreshold = 0\n"),
            "in.toml:2:13: haptic.threshold: value outside (0, 1], got 0");
  EXPECT_EQ(bad("input_timeout_s = \"fast\"\n"),
            "in.toml:1:19: input_timeout_s: expected a number, got the string \"fast\"");
  EXPECT_NE(bad("[axes.rol]\n").find("in.toml:1:7: axes.rol: unknown key (did you mean \"roll\"?)"),
            std::string::npos)
      << error;
  EXPECT_NE(bad("mode = \n").find("in.toml:1:"), std::string::npos) << error;  // TOML syntax
}

// Every key of the file, each given a value it must refuse: the error names the key, its line
// and column, and what was expected.
TEST(Settings, EveryKeyRefusesWhatIsOutsideItsRange) {
  struct Case {
    std::string table, key, value, expected;
  };
  std::vector<Case> cases = {
      {"", "mode", "0", "value outside [1, 4]"},
      {"", "max_tilt_deg", "0", "value outside (0, 60]"},
      {"", "thrust_range", "1.5", "value outside (0, 1]"},
      {"", "input_timeout_s", "0.01", "value outside [0.02, 5]"},
      {"", "recentre_tolerance", "0", "value outside (0, 0.5]"},
      {"", "return_time_s", "11", "value outside [0, 10]"},
      {"", "keyboard_ramp_s", "0.01", "value outside [0.05, 5]"},
      {"", "gamepad", "5", "expected a string"},
      {"haptic", "enabled", "3", "expected true or false"},
      {"haptic", "threshold", "1.5", "value outside (0, 1]"},
      {"haptic", "strength", "-0.5", "value outside [0, 1]"},
  };
  for (const char* axis : {"roll", "pitch", "thrust", "yaw"}) {
    const std::string t = std::string("axes.") + axis;
    cases.push_back({t, "deadzone", "0.6", "value outside [0, 0.5]"});
    cases.push_back({t, "expo", "-0.1", "value outside [0, 1]"});
    cases.push_back({t, "rate", "3", "value outside [0.1, 2]"});
    cases.push_back({t, "invert", "\"yes\"", "expected true or false"});
  }
  for (const Case& c : cases) {
    const std::string text =
        (c.table.empty() ? "" : "[" + c.table + "]\n") + c.key + " = " + c.value + "\n";
    const int line = c.table.empty() ? 1 : 2;
    const std::string where = "in.toml:" + std::to_string(line) + ":" +
                              std::to_string(c.key.size() + 4) + ": " +
                              (c.table.empty() ? "" : c.table + ".") + c.key + ": " + c.expected;
    std::string error;
    EXPECT_FALSE(parse_settings(text, "in.toml", error)) << text;
    EXPECT_NE(error.find(where), std::string::npos) << "wanted: " << where << "\ngot: " << error;
  }
}

// The settings file is TOML too: nesting beyond the bound is refused at its position (a key of
// 50 000 parts crashed the reader), and a byte-order mark or CR line ends are read as written.
TEST(InputSettings, DeepNestingIsRefusedAndEditorsLineEndsAreRead) {
  std::string key = "a";
  for (int i = 0; i < 50000; ++i) key += ".a";
  std::string error;
  EXPECT_FALSE(parse_settings("mode = 2\n" + key + " = 1\n", "in.toml", error));
  EXPECT_NE(error.find("in.toml:2:"), std::string::npos) << error;
  EXPECT_NE(error.find("nested more than"), std::string::npos) << error;
  const auto s = parse_settings("\xEF\xBB\xBFmode = 3\rmax_tilt_deg = 20\r", "in.toml", error);
  ASSERT_TRUE(s) << error;
  EXPECT_EQ(s->mode, 3);
  EXPECT_EQ(s->max_tilt_deg, 20.0);
}

TEST(Settings, AMissingFileGivesTheDefaultsAndSavedFilesLoad) {
  const std::string dir = test::fresh_path("input", "settings").string();
  bool exists = true;
  std::string error;
  const auto none = load_settings(dir + "/none.toml", exists, error);
  ASSERT_TRUE(none) << error;
  EXPECT_FALSE(exists);
  InputSettings s;
  s.max_tilt_deg = 20;
  const std::string path = dir + "/sub/input.toml";
  ASSERT_TRUE(save_settings(path, s, error)) << error;
  const auto back = load_settings(path, exists, error);
  ASSERT_TRUE(back) << error;
  EXPECT_TRUE(exists);
  EXPECT_EQ(back->max_tilt_deg, 20.0);
}

// Only a name with nothing behind it is a missing settings file (the defaults); a symbolic-link
// loop or a dangling link is an error that says what it is.
TEST(Settings, LinksThatLeadNowhereAreErrorsNotMissingFiles) {
  const fs::path dir = test::fresh_path("input", "links");
  fs::create_directories(dir);
  const fs::path loop = dir / "loop.toml", dangling = dir / "dangling.toml";
  fs::create_symlink(loop, loop);
  fs::create_symlink(dir / "nothing.toml", dangling);
  bool exists = false;
  std::string error;
  EXPECT_FALSE(load_settings(loop.string(), exists, error));
  EXPECT_EQ(error, loop.string() + ": cannot open file (" + std::strerror(ELOOP) + ")");
  EXPECT_FALSE(load_settings(dangling.string(), exists, error));
  EXPECT_EQ(error, dangling.string() + ": cannot open file (a symbolic link to a missing file)");
}

// The user's folders never default to the current folder: HOME unset, empty or relative gives
// the account's home (or no folder at all, said as such); a relative or empty XDG_CONFIG_HOME
// is ignored, as the XDG base directory specification says.
TEST(Settings, TheConfigFolderIsNeverTheCurrentFolder) {
  const auto restore = [](const char* name, const char* old) {
    if (old) ::setenv(name, old, 1);
    else ::unsetenv(name);
  };
  const std::string home = std::getenv("HOME") ? std::getenv("HOME") : "";
  const std::string xdg = std::getenv("XDG_CONFIG_HOME") ? std::getenv("XDG_CONFIG_HOME") : "";
  const bool had_home = std::getenv("HOME"), had_xdg = std::getenv("XDG_CONFIG_HOME");
  struct passwd* pw = ::getpwuid(::getuid());
  ASSERT_TRUE(pw && pw->pw_dir && pw->pw_dir[0] == '/') << "this account has no home folder";
  const std::string account = pw->pw_dir;
  for (const char* h : {static_cast<const char*>(nullptr), "", "relative/home", "."}) {
    for (const char* x : {static_cast<const char*>(nullptr), "", "relative/config"}) {
      h ? ::setenv("HOME", h, 1) : ::unsetenv("HOME");
      x ? ::setenv("XDG_CONFIG_HOME", x, 1) : ::unsetenv("XDG_CONFIG_HOME");
      std::string why;
      EXPECT_EQ(config_dir(&why), account + "/.config/mixpilot")
          << "HOME=" << (h ? h : "(unset)") << " XDG_CONFIG_HOME=" << (x ? x : "(unset)");
      EXPECT_EQ(default_settings_path(), account + "/.config/mixpilot/input.toml");
    }
  }
  ::setenv("HOME", "/home/someone", 1);
  ::setenv("XDG_CONFIG_HOME", "/etc/xdg-test", 1);
  EXPECT_EQ(config_dir(), "/etc/xdg-test/mixpilot");
  ::unsetenv("XDG_CONFIG_HOME");
  EXPECT_EQ(user_mappings_path(), "/home/someone/.config/mixpilot/gamecontrollerdb.txt");
  restore("HOME", had_home ? home.c_str() : nullptr);
  restore("XDG_CONFIG_HOME", had_xdg ? xdg.c_str() : nullptr);
}

TEST(Latest, TheReaderAlwaysSeesAWholeAndNewerValue) {
  struct Pair {
    std::uint64_t a = 0, b = 0;
  };
  Latest<Pair> l;
  EXPECT_EQ(l.read().a, 0u);
  l.publish({1, 1});
  l.publish({2, 2});
  EXPECT_EQ(l.read().a, 2u);
  EXPECT_EQ(l.read().a, 2u);
  constexpr std::uint64_t kLast = 200000;
  std::thread writer([&] {
    for (std::uint64_t i = 3; i <= kLast; ++i) l.publish({i, i});
  });
  std::uint64_t seen = 2;
  while (seen < kLast) {
    const Pair p = l.read();
    ASSERT_EQ(p.a, p.b);  // never torn
    ASSERT_GE(p.a, seen);  // never older
    seen = p.a;
  }
  writer.join();
}

// A stick source the test sets by hand.
struct FakeSource : StickSource {
  StickReading r;
  std::string name() const override { return "fake"; }
  const StickReading& latest() override { return r; }
};

TEST(DevicePilot, LossGivesThePlannerTheAuthorityAtOnceAndItReturnsGradually) {
  FakeSource src;
  src.r.connected = true;
  src.r.alive_ns = steady_ns() + 3'600'000'000'000;  // alive throughout
  InputSettings s;
  s.return_time_s = 0.15;  // 10 steps of 15 ms
  const double hover = models::MikroKopter().hover_speed();
  DevicePilot pilot(src, s, 0.015, hover);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(16);
  PilotCommand c;
  src.r.sticks.right_x = 0.5;
  ASSERT_TRUE(pilot.command(0, 0, x, c));
  EXPECT_EQ(c.input, InputState::ok);
  EXPECT_EQ(c.authority, 1.0);
  EXPECT_GT(c.roll, 0.0);

  src.r.connected = false;  // unplugged
  ASSERT_TRUE(pilot.command(1, 0, x, c));
  EXPECT_EQ(c.input, InputState::lost);
  EXPECT_EQ(c.authority, 0.0);
  EXPECT_EQ(c.roll, 0.0);
  EXPECT_EQ(c.rotor_speed(0), hover);

  src.r.connected = true;  // back, but the stick is still deflected
  for (int k = 2; k < 5; ++k) {
    ASSERT_TRUE(pilot.command(k, 0, x, c));
    EXPECT_EQ(c.input, InputState::recentre);
    EXPECT_EQ(c.authority, 0.0);
  }
  src.r.sticks.right_x = 0.04;  // inside the deadzone: centred
  // Held centred for kRecentreHoldS (7 steps of 15 ms) before the return starts; one read of
  // a deflected stick in between starts the count again.
  for (int k = 5; k < 8; ++k) {
    ASSERT_TRUE(pilot.command(k, 0, x, c));
    EXPECT_EQ(c.input, InputState::recentre) << k;
  }
  src.r.sticks.right_x = 0.5;
  ASSERT_TRUE(pilot.command(8, 0, x, c));
  EXPECT_EQ(c.input, InputState::recentre);
  src.r.sticks.right_x = 0.04;
  for (int k = 9; k < 15; ++k) {
    ASSERT_TRUE(pilot.command(k, 0, x, c));
    EXPECT_EQ(c.input, InputState::recentre) << k;
    EXPECT_EQ(c.authority, 0.0);
  }
  double previous = 0.0;
  for (int k = 15; k < 24; ++k) {
    ASSERT_TRUE(pilot.command(k, 0, x, c));
    EXPECT_EQ(c.input, InputState::returning) << k;
    EXPECT_NEAR(c.authority - previous, 0.1, 1e-12) << k;
    previous = c.authority;
  }
  ASSERT_TRUE(pilot.command(24, 0, x, c));
  EXPECT_EQ(c.input, InputState::ok);
  EXPECT_EQ(c.authority, 1.0);
}

TEST(DevicePilot, ASilentDeviceIsLostAfterTheTimeout) {
  FakeSource src;
  src.r.connected = true;
  InputSettings s;
  DevicePilot pilot(src, s, 0.015, models::MikroKopter().hover_speed());
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(16);
  PilotCommand c;
  src.r.alive_ns = steady_ns();
  ASSERT_TRUE(pilot.command(0, 0, x, c));
  EXPECT_EQ(c.input, InputState::ok);
  src.r.alive_ns = steady_ns() - std::int64_t(1.5 * s.input_timeout_s * 1e9);
  ASSERT_TRUE(pilot.command(1, 0, x, c));
  EXPECT_EQ(c.input, InputState::lost);
  EXPECT_EQ(c.authority, 0.0);
}

TEST(Keyboard, KeysRampTheControlsInEveryStickMode) {
  for (int mode = 1; mode <= 4; ++mode) {
    InputSettings s;
    s.mode = mode;
    s.keyboard_ramp_s = 0.3;  // 20 steps of 15 ms to full deflection
    KeyboardSource k(s);
    k.set_key(Key::roll_right, true);
    k.set_key(Key::thrust_down, true);
    for (int i = 1; i <= 25; ++i) {
      k.advance(0.015);
      const Controls c = assign(k.latest().sticks, mode);
      EXPECT_NEAR(c.roll, std::min(1.0, i / 20.0), 1e-12) << "mode " << mode << " step " << i;
      EXPECT_NEAR(c.thrust, -std::min(1.0, i / 20.0), 1e-12);
      EXPECT_EQ(c.pitch, 0.0);
      EXPECT_EQ(c.yaw, 0.0);
    }
    k.set_key(Key::roll_right, false);
    k.advance(0.015);
    EXPECT_NEAR(assign(k.latest().sticks, mode).roll, 0.95, 1e-12);  // back, ramped too
    EXPECT_TRUE(k.latest().connected);
  }
}

TEST(Script, RowsAndTheirErrors) {
  std::string error;
  const auto ok = parse_script("# a script\nt,left_x,left_y,right_x,right_y\n0,0,0,0,0\n"
                               "0.5,0,-1,0.25,0\n1.0,unplug\n2.0,plug\n", "s.csv", error);
  ASSERT_TRUE(ok) << error;
  ASSERT_EQ(ok->size(), 4u);
  EXPECT_EQ((*ok)[1].values[1], -1.0f);
  EXPECT_EQ((*ok)[2].kind, ScriptRow::unplug);
  EXPECT_EQ((*ok)[3].kind, ScriptRow::plug);
  EXPECT_FALSE(parse_script("0,0,0,0,0\n0.1,0,0,2,0\n", "s.csv", error));
  EXPECT_EQ(error, "s.csv:2: column 4: expected a number in [-1, 1], got \"2\"");
  EXPECT_FALSE(parse_script("1,0,0,0,0\n0.5,0,0,0,0\n", "s.csv", error));
  EXPECT_EQ(error, "s.csv:2: time 0.5 is earlier than the row before");
  EXPECT_FALSE(parse_script("0,0,0\n", "s.csv", error));
  EXPECT_NE(error.find("s.csv:1: expected t,left_x"), std::string::npos) << error;
  EXPECT_FALSE(parse_script("# nothing\n", "s.csv", error));
  // Times become int64 nanoseconds: 1e300 s wrapped around and played at the first step.
  for (const char* t : {"1e300", "9.3e9", "86400.5"}) {
    EXPECT_FALSE(parse_script(std::string("0,0,0,0,0\n") + t + ",0,0,0.5,0\n", "s.csv", error)) << t;
    EXPECT_EQ(error, std::string("s.csv:2: expected a time in seconds from 0 to 86400 first, got \"") +
                         t + "\"");
  }
}

// A script as any editor writes it (byte-order mark, CR LF, old Mac CR), and errors that never
// pass a cell's terminal escape sequences on.
TEST(Script, EditorsLineEndsAndNoEscapesInErrors) {
  std::string error;
  for (const std::string nl : {"\n", "\r\n", "\r"}) {
    const auto rows = parse_script("\xEF\xBB\xBFt,left_x,left_y,right_x,right_y" + nl +
                                       "0,0,0,0,0" + nl + "0.5,0,-1,0.25,0" + nl + "1,unplug" + nl,
                                   "s.csv", error);
    ASSERT_TRUE(rows) << error;
    ASSERT_EQ(rows->size(), 3u);
    EXPECT_EQ((*rows)[1].values[1], -1.0f);
    EXPECT_EQ((*rows)[2].kind, ScriptRow::unplug);
  }
  EXPECT_FALSE(parse_script("0,0,0,0,0\n0.1,\x1b[2J,0,0,0\n", "s.csv", error));
  EXPECT_EQ(error, "s.csv:2: column 2: expected a number in [-1, 1], got \"\\x1B[2J\"");
  EXPECT_FALSE(parse_script("\x1b]0;owned\x07,0,0,0,0\n", "s.csv", error));
  EXPECT_EQ(error, "s.csv:1: expected a time in seconds from 0 to 86400 first, got "
                   "\"\\x1B]0;owned\\x07\"");
}

// Waits (up to 2 s) for `done`.
template <class F>
bool eventually(F done) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

// SDL's whole path without hardware: the virtual pad is found as a game controller, its axes
// arrive (up and right positive), unplugging and plugging are seen, and the rumble the
// Gamepad plays reaches the pad's callback.
TEST(Gamepad, AVirtualPadThroughSdl) {
  VirtualGamepad pad;
  std::string error;
  ASSERT_TRUE(pad.plug(error)) << error;
  Gamepad g;
  ASSERT_TRUE(g.start({}, error)) << error;
  ASSERT_TRUE(eventually([&] { return g.connected(); }));
  EXPECT_EQ(g.active_name(), "mixpilot virtual gamepad");
  pad.set_axis(SDL_CONTROLLER_AXIS_RIGHTX, 0.5);
  pad.set_axis(SDL_CONTROLLER_AXIS_LEFTY, -1.0);  // SDL: up is negative
  ASSERT_TRUE(eventually([&] { return g.latest().sticks.right_x > 0.49; }));
  EXPECT_NEAR(g.latest().sticks.right_x, 0.5, 1e-4);
  EXPECT_NEAR(g.latest().sticks.left_y, 1.0, 1e-4);
  EXPECT_NEAR(g.latest().joy.axes[1], -1.0, 1e-4);
  EXPECT_EQ(g.latest().joy.num_axes, 6);

  g.set_rumble(0.5);
  ASSERT_TRUE(eventually([&] { return !pad.rumbles().empty(); }));
  EXPECT_NEAR(pad.rumbles().back().intensity, 0.5, 1.0 / 256);

  pad.unplug();
  ASSERT_TRUE(eventually([&] { return !g.connected(); }));
  EXPECT_FALSE(g.latest().connected);
  ASSERT_TRUE(pad.plug(error)) << error;
  ASSERT_TRUE(eventually([&] { return g.connected(); }));
  g.stop();
}

// The wizard from made-up readings: sticks (one inverted), a button, a hat, a trigger resting
// at −1, a skipped step, a control bound twice, and the line SDL gets.
TEST(MappingWizard, BuildsTheSdlLineFromWhatMoved) {
  MappingWizard w(2, "03000000aaaa0000bbbb000000000000", "Odd, Stick");
  RawJoystick rest;
  rest.num_axes = 6;
  rest.num_buttons = 4;
  rest.num_hats = 1;
  rest.axes[5] = -1.0f;  // a trigger at rest
  w.feed(rest);
  const auto move = [&](auto change) {
    RawJoystick r = rest;
    change(r);
    w.feed(r);
    w.feed(rest);  // let go
  };
  ASSERT_EQ(w.steps()[0].target, "lefty");  // Mode 2: thrust on the left stick
  EXPECT_NE(w.steps()[0].prompt.find("thrust stick up"), std::string::npos);
  EXPECT_FALSE(w.skip()) << "a stick cannot be skipped";
  move([](RawJoystick& r) { r.axes[1] = -1.0f; });  // up is negative: plain
  move([](RawJoystick& r) { r.axes[0] = 0.9f; });   // right is positive: plain
  EXPECT_EQ(w.current(), 2u);
  move([](RawJoystick& r) { r.axes[0] = 0.9f; });   // already the yaw: refused
  EXPECT_EQ(w.current(), 2u);
  EXPECT_NE(w.hint().find("already leftx"), std::string::npos) << w.hint();
  move([](RawJoystick& r) { r.axes[3] = 1.0f; });   // pitch up grows: inverted
  move([](RawJoystick& r) { r.axes[2] = -0.8f; });  // roll right shrinks: inverted
  EXPECT_TRUE(w.mapping().find("rightx:a2~") != std::string::npos);
  move([](RawJoystick& r) { r.buttons[1] = true; });  // a
  EXPECT_TRUE(w.skip());                              // b skipped
  move([](RawJoystick& r) { r.hats[0] = 1; });        // x on the hat's up
  // A half-moved axis is not a press; nothing happens.
  RawJoystick half = rest;
  half.axes[4] = 0.3f;
  w.feed(half);
  EXPECT_EQ(w.steps()[w.current()].target, "y");
  while (w.steps()[w.current()].target != "lefttrigger") ASSERT_TRUE(w.skip());
  move([](RawJoystick& r) { r.axes[5] = 1.0f; });  // from −1: the whole axis
  move([](RawJoystick& r) { r.axes[4] = 0.9f; });  // from 0: the positive half
  EXPECT_TRUE(w.done());
  EXPECT_EQ(w.mapping(),
            "03000000aaaa0000bbbb000000000000,Odd  Stick,lefty:a1,leftx:a0,righty:a3~,rightx:a2~,"
            "a:b1,x:h0.1,lefttrigger:a5,righttrigger:+a4,platform:Linux,");
  w.back();
  EXPECT_FALSE(w.done());
  EXPECT_EQ(w.mapping().find("righttrigger"), std::string::npos);
}

TEST(MappingWizard, TheLineIsUnfinishedUntilEveryStickIsBound) {
  MappingWizard w(1, "03000000cccc", "pad");
  RawJoystick rest;
  rest.num_axes = 4;
  w.feed(rest);
  EXPECT_EQ(w.steps()[0].target, "righty");  // Mode 1: thrust on the right stick
  EXPECT_EQ(w.mapping(), "");
}

// The mappings file keeps other pads' lines and replaces this pad's.
TEST(MappingWizard, SaveReplacesThePadsLineOnly) {
  const auto dir = test::fresh_path("input", "mappings");
  const std::string path = (dir / "sub" / "gamecontrollerdb.txt").string();
  std::string error;
  ASSERT_TRUE(save_mapping(path, "0300aaaa,one,a:b0,platform:Linux,", error)) << error;
  ASSERT_TRUE(save_mapping(path, "0300bbbb,two,a:b1,platform:Linux,", error)) << error;
  ASSERT_TRUE(save_mapping(path, "0300aaaa,one,a:b2,platform:Linux,", error)) << error;
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(ss.str(), "0300bbbb,two,a:b1,platform:Linux,\n0300aaaa,one,a:b2,platform:Linux,\n");
}

// The user's mappings file: read in one pass by GUID (this platform's lines, the last line of a
// GUID winning, comments and CR line ends as written, malformed lines counted).
TEST(GamepadMappings, ParsedByGuidInOnePass) {
  const std::string platform = SDL_GetPlatform();
  const MappingFile m = parse_mappings(
      "\xEF\xBB\xBF# comment\r\n"
      "0300aaaa,one,a:b0,platform:" + platform + ",\r\n"
      "0300bbbb,two,a:b1,platform:Windows,\r\n"
      "0300aaaa,one again,a:b2,platform:" + platform + ",\r\n"
      "0300cccc,no platform,a:b3,\r"
      "just some words\n,,\n  \n");
  ASSERT_EQ(m.by_guid.size(), 2u);
  EXPECT_EQ(m.by_guid.at("0300aaaa"), "0300aaaa,one again,a:b2,platform:" + platform + ",");
  EXPECT_EQ(m.by_guid.at("0300cccc"), "0300cccc,no platform,a:b3,");
  EXPECT_EQ(m.malformed, 2);
}

// The mappings file is an input like any other: a FIFO there no longer blocks the start (a test
// that hangs is a failure), a directory or an oversized file is said in words and left out while
// the pads still start; a long file is not handed to SDL line by line (SDL's loader searched its
// whole list for every line: 100 000 lines did not start within 40 s), only the line of a pad
// that is present.
TEST(GamepadMappings, TheFileIsCheckedAndNotHandedToSdlWhole) {
  const auto dir = test::fresh_path("input", "mapping_files");
  std::filesystem::create_directories(dir);
  const std::string fifo = (dir / "fifo.txt").string(), folder = (dir / "folder").string(),
                    big = (dir / "big.txt").string(), loop = (dir / "loop.txt").string();
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::filesystem::create_directories(folder);
  std::filesystem::create_symlink(loop, loop);
  {
    std::ofstream out(big);
    char line[160];
    for (int i = 0; i < 100000; ++i) {
      std::snprintf(line, sizeof line,
                    "03000000%08x0000000000000000,pad %d,a:b0,b:b1,leftx:a0,lefty:a1,platform:%s,\n",
                    i, i, SDL_GetPlatform());
      out << line;
    }
  }
  ASSERT_EQ(SDL_InitSubSystem(SDL_INIT_GAMECONTROLLER), 0) << SDL_GetError();
  const int before = SDL_GameControllerNumMappings();
  for (const auto& [file, why] : std::vector<std::pair<std::string, std::string>>{
           {fifo, "expected a regular file, got a named pipe"},
           {folder, "expected a regular file, got a directory"},
           {loop, "Too many levels of symbolic links"},
           {big, ""}}) {
    SCOPED_TRACE(file);
    Gamepad g;
    Gamepad::Options o;
    o.mappings_file = file;
    std::string error;
    ASSERT_TRUE(g.start(o, error)) << error;
    if (why.empty()) {
      EXPECT_EQ(g.mappings_note(), "");
    } else {
      EXPECT_NE(g.mappings_note().find(why), std::string::npos) << g.mappings_note();
      EXPECT_NE(g.mappings_note().find("SDL's built-in ones apply"), std::string::npos);
    }
    ASSERT_TRUE(eventually([&] { return g.polls() > 5; }));
    EXPECT_LE(SDL_GameControllerNumMappings(), before + 4) << "the file went to SDL whole";
  }
  SDL_QuitSubSystem(SDL_INIT_GAMECONTROLLER);
}

// End to end through SDL: a virtual joystick SDL has no mapping for is watched raw, mapped by
// the wizard, and from then on reads as a gamepad with its axes where the wizard put them.
TEST(MappingWizard, AJoystickSdlDoesNotKnowBecomesAGamepad) {
  ASSERT_EQ(SDL_InitSubSystem(SDL_INIT_JOYSTICK), 0) << SDL_GetError();
  SDL_VirtualJoystickDesc desc{};
  desc.version = SDL_VIRTUAL_JOYSTICK_DESC_VERSION;
  desc.type = SDL_JOYSTICK_TYPE_UNKNOWN;
  desc.naxes = 5;
  desc.nbuttons = 8;
  desc.nhats = 1;
  desc.name = "mixpilot odd joystick";
  // USB ids, as every real USB joystick has (SDL 2.26 matches no added mapping to a GUID
  // made from the name alone, which is what a virtual joystick without ids gets).
  desc.vendor_id = 0x1209;
  desc.product_id = 0x0001;
  const int index = SDL_JoystickAttachVirtualEx(&desc);
  ASSERT_GE(index, 0) << SDL_GetError();
  SDL_Joystick* js = SDL_JoystickOpen(index);
  ASSERT_TRUE(js) << SDL_GetError();
  const auto set = [&](int axis, double v) {
    SDL_JoystickSetVirtualAxis(js, axis, Sint16(std::lround(std::clamp(v, -1.0, 1.0) * 32767)));
  };
  for (int a = 0; a < 5; ++a) set(a, 0.0);

  Gamepad g;
  std::string error;
  ASSERT_TRUE(g.start({}, error)) << error;
  std::optional<GamepadInfo> odd;
  ASSERT_TRUE(eventually([&] {
    for (const GamepadInfo& d : g.devices())
      if (d.name == "mixpilot odd joystick") odd = d;
    return odd.has_value();
  }));
  EXPECT_FALSE(odd->controller) << "SDL knows this joystick already";
  EXPECT_FALSE(g.connected());

  g.watch(odd->instance);
  ASSERT_TRUE(eventually([&] { return g.raw().instance == odd->instance && g.raw().num_axes == 5; }));
  MappingWizard w(2, odd->guid, odd->name);
  // The sticks on odd axes: thrust a4 (up grows), yaw a3, pitch a1, roll a0 (right shrinks).
  const std::pair<int, double> moves[] = {{4, 1.0}, {3, 1.0}, {1, -1.0}, {0, -1.0}};
  w.feed(g.raw());
  for (const auto& [axis, v] : moves) {
    set(axis, v);
    ASSERT_TRUE(eventually([&] {
      w.feed(g.raw());
      return !w.hint().empty();
    })) << w.steps()[w.current()].prompt;
    set(axis, 0.0);
    const std::size_t step = w.current();
    ASSERT_TRUE(eventually([&] {
      w.feed(g.raw());
      return w.current() == step + 1;
    }));
  }
  const std::string line = w.mapping();
  ASSERT_FALSE(line.empty());
  EXPECT_NE(line.find("lefty:a4~,leftx:a3,righty:a1,rightx:a0~,"), std::string::npos) << line;

  g.watch(-1);
  g.add_mapping(line);
  ASSERT_TRUE(eventually([&] { return g.mapping_status(error) != 0; }));
  ASSERT_EQ(g.mapping_status(error), 1) << error;
  ASSERT_TRUE(eventually([&] { return g.connected(); })) << line;
  EXPECT_EQ(g.active_name(), "mixpilot odd joystick");
  set(0, -0.5);  // roll half right (inverted raw axis)
  set(4, 0.5);   // thrust half up
  ASSERT_TRUE(eventually([&] { return g.latest().sticks.right_x > 0.45; }));
  EXPECT_NEAR(g.latest().sticks.right_x, 0.5, 1e-3);
  EXPECT_NEAR(g.latest().sticks.left_y, 0.5, 1e-3);
  g.stop();
  SDL_JoystickClose(js);
  SDL_JoystickDetachVirtual(index);
  SDL_QuitSubSystem(SDL_INIT_JOYSTICK);
}

}  // namespace
}  // namespace mixpilot::input
