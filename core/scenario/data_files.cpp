#include "core/scenario/data_files.hpp"

#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>

namespace mixpilot {

namespace fs = std::filesystem;

namespace {

bool holds_scenarios(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir / "scenarios", ec);
}

}  // namespace

std::string data_dir(std::string* why) {
  if (const char* env = std::getenv("MIXPILOT_DATA_DIR"); env && *env) {
    if (holds_scenarios(env)) return fs::path(env).lexically_normal().string();
    if (why) *why = std::string("MIXPILOT_DATA_DIR=") + env + " holds no scenarios/ folder";
    return "";
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  const fs::path share = (exe.parent_path() / ".." / "share" / "mixpilot").lexically_normal();
  if (!ec && holds_scenarios(share)) return share.string();
  if (why)
    *why = "no mixpilot data in " + share.string() +
           " (set MIXPILOT_DATA_DIR to the folder holding scenarios/)";
  return "";
}

std::string data_file(const std::string& relative) {
  const std::string dir = data_dir();
  return dir.empty() ? "" : (fs::path(dir) / relative).string();
}

std::string home_dir(std::string* why) {
  const char* home = std::getenv("HOME");
  if (home && *home == '/') return home;
  // getpwuid_r: the environment may not say, the account database does.
  struct passwd pw {};
  struct passwd* found = nullptr;
  std::string buf(16384, '\0');
  if (::getpwuid_r(::getuid(), &pw, buf.data(), buf.size(), &found) == 0 && found &&
      found->pw_dir && found->pw_dir[0] == '/')
    return found->pw_dir;
  if (why) {
    *why = std::string(home == nullptr ? "HOME is not set"
                       : *home == '\0' ? "HOME is empty"
                                        : "HOME is not an absolute path") +
           " and the account of user id " + std::to_string(::getuid()) +
           " names no home folder";
  }
  return "";
}

std::string xdg_dir(const char* variable, const char* under_home, std::string* why) {
  if (const char* x = std::getenv(variable); x && *x == '/') return x;
  std::string reason;
  const std::string home = home_dir(&reason);
  if (home.empty()) {
    if (why) *why = reason + ", and " + variable + " is not an absolute path";
    return "";
  }
  return (fs::path(home) / under_home).string();
}

}  // namespace mixpilot
