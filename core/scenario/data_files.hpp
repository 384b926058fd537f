#pragma once
// Where mixpilot's shipped data is found at run time: the scenarios with their reference
// trajectories (scenarios/) and the DDS configuration (assets/). Looked up in order:
//   1. $MIXPILOT_DATA_DIR, when set (it must hold scenarios/);
//   2. <folder of the executable>/../share/mixpilot: the install prefix (/usr/bin/mixpilot →
//      /usr/share/mixpilot); a build tree has the same layout (CMake links
//      <build>/share/mixpilot/{scenarios,assets} to the checkout), so developers need nothing.
// No path into the source tree is compiled in. User data (recordings, settings, gamepad
// mappings) is elsewhere: the XDG directories.
#include <string>

namespace mixpilot {

// The data folder, or "" with `why` (what was tried) when there is none.
std::string data_dir(std::string* why = nullptr);
// data_dir()/relative, or "" when there is no data folder.
std::string data_file(const std::string& relative);

// The user's home folder: $HOME when it is an absolute path, else the account's (getpwuid);
// "" with `why` when neither is one. Never the current folder: a relative or empty HOME would
// scatter settings and recordings over whatever folder the program was started in.
std::string home_dir(std::string* why = nullptr);
// A user folder of the XDG base directories: $<variable> (XDG_CONFIG_HOME, XDG_DATA_HOME) when it
// is an absolute path (the specification ignores a relative or empty one), else
// home_dir()/<under_home> (".config", ".local/share"); "" with `why` when there is no home.
std::string xdg_dir(const char* variable, const char* under_home, std::string* why = nullptr);

}  // namespace mixpilot
