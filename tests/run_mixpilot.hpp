#pragma once
// Running the mixpilot executable from a test as a user would, and reading what it wrote.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

namespace mixpilot::test {

// `binary args` with the user's folders in `home` (no settings of the machine's user leak in),
// its output (stdout and stderr) in home/out; the exit status (128: killed by a signal).
inline int run_mixpilot(const std::string& binary, const std::string& args,
                        const std::filesystem::path& home, const std::string& out = "out.txt") {
  const std::string cmd = "env XDG_CONFIG_HOME='" + (home / "config").string() +
                          "' XDG_DATA_HOME='" + (home / "data").string() + "' '" + binary +
                          "' " + args + " >'" + (home / out).string() + "' 2>&1";
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The numbers of a flat JSON object ("key": number).
inline std::map<std::string, double> numbers(const std::string& json) {
  std::map<std::string, double> out;
  const std::regex re("\"([a-z_0-9]+)\": (-?[0-9.eE+-]+)");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), re); it != std::sregex_iterator();
       ++it)
    out[(*it)[1]] = std::stod((*it)[2]);
  return out;
}

}  // namespace mixpilot::test
