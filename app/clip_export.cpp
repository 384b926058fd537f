#include "app/clip_export.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include "app/cli.hpp"
#include "app/video.hpp"

namespace mixpilot::cli {

namespace {

constexpr std::size_t kSaidBytes = 64 << 10;  // of the child's standard error, the newest kept

std::string own_executable() {
  std::error_code ec;
  const auto p = std::filesystem::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : p.string();
}

// The child's message: its last line that is no progress line ("LABEL: N %").
std::string message_of(const std::string& said) {
  std::string_view rest = said;
  while (!rest.empty()) {
    const std::string line = last_lines(rest, 1);
    if (line.empty()) break;
    if (!(line.size() > 2 && line.compare(line.size() - 2, 2, " %") == 0)) return line;
    const std::size_t at = rest.rfind(line);
    rest = rest.substr(0, at);
  }
  return "";
}

// `decimals` < 0: every digit, so the child reads the very number (a window's end at the
// recording's end stays within it).
std::string seconds(double t, int decimals = -1) {
  char buf[40];
  if (decimals < 0) std::snprintf(buf, sizeof buf, "%.17g", t);
  else std::snprintf(buf, sizeof buf, "%.*f", decimals, t);
  return buf;
}

}  // namespace

ClipExporter::ClipExporter(StatusLine& status) : status_(status), program_(own_executable()) {}

ClipExporter::~ClipExporter() {
  if (!child_.running()) return;
  // The child stops at its next frame and removes its temporary; a child that does not is
  // killed after a while (its temporary then stays, named *.tmp beside the clip).
  child_.signal(SIGTERM);
  for (int i = 0; i < 200 && !child_.poll(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  if (child_.running()) child_.signal(SIGKILL);
}

bool ClipExporter::start(const std::string& recording, double from, double to) {
  if (child_.running()) {
    status_.say("a clip is being exported already (" + path_ + "); wait for it", true);
    return false;
  }
  if (!(to > from)) {
    status_.say("nothing to export: the clip's window is empty", true);
    return false;
  }
  const char* search = std::getenv("PATH");
  if (find_program("ffmpeg", search ? search : "/bin:/usr/bin").empty()) {
    status_.say(std::string("cannot export a clip: ") + kFfmpegMissing, true);
    return false;
  }
  path_ = numbered_clip_path(recording);
  said_.clear();
  percent_ = -1;
  saved_ = false;
  std::string error;
  if (!child_.start(program_,
                    {"replay", recording, "--video", path_, "--from", seconds(from), "--to",
                     seconds(to)},
                    ChildProcess::Input::none, error)) {
    status_.say("cannot export a clip: " + error, true);
    return false;
  }
  child_.error_nonblocking();
  status_.say("exporting t = " + seconds(from, 1) + " to " + seconds(to, 1) + " s to " + path_ +
              ": flying the recording again");
  return true;
}

void ClipExporter::poll() {
  if (!child_.running()) return;
  const auto drain = [&] {
    for (int i = 0; i < 64; ++i) {  // bounded: a frame never waits on a talkative child
      const std::size_t before = said_.size();
      if (!child_.read_error(said_) || said_.size() == before) break;
    }
    if (said_.size() > kSaidBytes) said_.erase(0, said_.size() - kSaidBytes);
  };
  drain();
  if (const int p = last_percent(said_); p != percent_ && p >= 0) {
    percent_ = p;
    status_.say("exporting a clip to " + path_ + ": " + std::to_string(p) + " %");
  }
  if (const auto e = child_.poll()) {
    drain();  // what it said last, before it ended
    ended(*e);
  }
}

void ClipExporter::ended(const ChildExit& e) {
  std::error_code ec;
  saved_ = (e.ok() || (e.exited && e.code == kExitReplayMismatch)) &&
           std::filesystem::is_regular_file(path_, ec);
  if (saved_) {
    status_.say("clip saved: " + path_ +
                (e.ok() ? "" : " (the replay differs from the recording)"));
    return;
  }
  const std::string why = message_of(said_);
  status_.say("clip not saved: " + (why.empty() ? to_string(e) : why), true);
}

}  // namespace mixpilot::cli
