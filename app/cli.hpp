#pragma once
// What the mixpilot commands share: exit codes, usage errors, interrupts, progress, output.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace mixpilot::cli {

// Exit codes of every command (documented in `mixpilot --help` and the README).
enum ExitCode : int {
  kExitOk = 0,
  kExitError = 1,           // bad input (file, scenario, recording) or a failure on the way
  kExitUsage = 2,           // bad command line
  kExitReplayMismatch = 3,  // a replay differs from its recording
  kExitInterrupted = 130,   // SIGINT or SIGTERM ended the flight (what shells report for ^C)
};

[[noreturn]] void usage_error(const char* command, const std::string& message);

// A positive, finite number of seconds no larger than `max`, or nullopt.
std::optional<double> parse_seconds(std::string_view text, double max);

// Writes `text` to `path` through a unique temporary in the same directory, moved into place
// (core/recording/output_file.hpp: never over a special file, over an existing file only with
// `overwrite`).
bool write_file(const std::string& path, const std::string& text, bool overwrite,
                std::string& error);

// SIGINT and SIGTERM set a flag that long loops poll (interrupted()); the handler then resets
// itself, so a second ^C ends the process at once.
void catch_interrupts();
bool interrupted();

// A progress bar on stderr when it is a terminal (nothing otherwise): "label [#####   ] 42%".
class Progress {
 public:
  Progress(std::string label, std::int64_t total);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(std::int64_t done);  // redraws at most every 100 ms
  void finish();                   // clears the line

 private:
  std::string label_;
  std::int64_t total_;
  bool tty_;
  bool drawn_ = false;
  std::int64_t last_ns_ = 0;
};

}  // namespace mixpilot::cli
