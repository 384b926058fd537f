#pragma once
// The mixpilot commands (app/mixpilot.cpp dispatches on argv[1]).

namespace mixpilot::cli {

struct FlyOptions;

int fly_command(int argc, char** argv);
int replay_command(int argc, char** argv);
int demo_command();
int score_command(int argc, char** argv);
int recover_command(int argc, char** argv);
int models_command();
int gamepad_script_command(int argc, char** argv);
int joy_publish_command(int argc, char** argv);
int vehicle_command(int argc, char** argv);
int history_command(int argc, char** argv);
int instruct_command(int argc, char** argv);
int lesson_command(int argc, char** argv);
int sweep_command(int argc, char** argv);
int figures_command(int argc, char** argv);
// A flight as `fly` flies it (the window, or headless), from its options.
int run_fly(const FlyOptions& o);

}  // namespace mixpilot::cli
