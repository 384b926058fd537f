// mixpilot gamepad-script: a recording's pilot commands as a virtual gamepad's script, so a
// recorded flight (an emulated pilot's, a person's) can be flown again through the real SDL
// path with `fly --pilot gamepad --gamepad-script`.
#include <array>
#include <cstdio>
#include <string>

#include "app/cli.hpp"
#include "app/commands.hpp"
#include "app/flight.hpp"
#include "core/recording/replay.hpp"
#include "core/base/input_file.hpp"
#include "core/scenario/scenario_toml.hpp"
#include "core/base/output_file.hpp"
#include "core/recording/recording.hpp"
#include "input/mapping.hpp"
#include "models/mikrokopter.hpp"

namespace mixpilot::cli {

namespace {

constexpr const char* kUsage =
    "usage: mixpilot gamepad-script REC.mcap -o OUT.csv [--input-settings FILE] [--force]\n"
    "\n"
    "Writes the pilot commands of a mixed-initiative recording as a virtual gamepad's script\n"
    "(docs/input-settings.md): one row per control step with the stick positions that give\n"
    "each command through the stick mapping of the input settings (the inverse of deadzone,\n"
    "expo and rate; commands beyond full deflection are clamped to it).\n"
    "\n"
    "  -o OUT.csv             where to write\n"
    "  --input-settings FILE  the settings the script will be flown with (default: the\n"
    "                         user's input.toml, or the defaults)\n"
    "  --force                overwrite an existing OUT\n"
    "\n"
    "exit status: 0 written, 1 unreadable recording or settings, 2 usage\n";

}  // namespace

int gamepad_script_command(int argc, char** argv) {
  std::string in, out, settings_path;
  bool force = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return option_value("gamepad-script", argc, argv, i); };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return kExitOk;
    } else if (a == "-o") {
      out = value();
    } else if (a == "--input-settings") {
      settings_path = value();
    } else if (a == "--force") {
      force = true;
    } else if (!a.empty() && a[0] == '-') {
      usage_error("gamepad-script", "unknown option '" + a + "'");
    } else if (in.empty()) {
      in = file_argument("gamepad-script", "a recording", a);
    } else {
      usage_error("gamepad-script", "one recording at a time, got '" + in + "' and '" + a + "'");
    }
  }
  if (in.empty()) usage_error("gamepad-script", "which recording? (mixpilot gamepad-script REC.mcap -o OUT.csv)");
  if (out.empty()) usage_error("gamepad-script", "-o OUT.csv is required");
  check_not_an_input("gamepad-script", "-o", out,
                     {{"the recording", in}, {"--input-settings", settings_path}});
  std::string error;
  const auto settings = command_input_settings("gamepad-script", settings_path, error);
  const auto pr = settings ? read_pilot_recording(in, error) : std::nullopt;
  if (!pr) {
    std::fprintf(stderr, "mixpilot gamepad-script: %s\n", error.c_str());
    return kExitError;
  }
  const RecordingContents* rec = &pr->recording;
  const Scenario* scenario = &pr->scenario;
  const double dt = scenario->controller.dt;
  OutputFile f;
  if (!f.open(out, force, error)) {
    std::fprintf(stderr, "mixpilot gamepad-script: %s\n", error.c_str());
    return kExitError;
  }
  // The name on one comment line, whatever characters it holds.
  std::fprintf(f.stream(), "# mixpilot gamepad-script of %s (stick mode %d)\n",
               escape_controls(in).c_str(), settings->mode);
  std::fprintf(f.stream(), "t,left_x,left_y,right_x,right_y\n");
  for (std::size_t k = 0; k < rec->pilot.size(); ++k) {
    const PilotCommandMsg& m = rec->pilot[k];
    const std::array<double, 4> a = sdl_axes_for(m, *settings);
    std::fprintf(f.stream(), "%.6f,%.6f,%.6f,%.6f,%.6f\n", double(m.step) * dt, a[0], a[1], a[2],
                 a[3]);
  }
  if (!f.commit(error)) {
    std::fprintf(stderr, "mixpilot gamepad-script: %s\n", error.c_str());
    return kExitError;
  }
  std::printf("mixpilot gamepad-script: %zu rows (%.1f s) written to %s\n", rec->pilot.size(),
              double(rec->pilot.size()) * dt, out.c_str());
  return kExitOk;
}

}  // namespace mixpilot::cli
