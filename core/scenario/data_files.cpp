#include "core/scenario/data_files.hpp"

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

}  // namespace mixpilot
