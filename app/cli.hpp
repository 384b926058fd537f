#pragma once
// What the mixpilot commands share: exit codes, usage errors, interrupts, progress, output.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mixpilot::cli {

// Exit codes of every command (documented in `mixpilot --help` and the README).
enum ExitCode : int {
  kExitOk = 0,
  kExitError = 1,           // bad input (file, scenario, recording) or a failure on the way
  kExitUsage = 2,           // bad command line
  kExitReplayMismatch = 3,  // a replay differs from its recording
  kExitStepFailed = 4,      // `lesson`: the step was flown and judged, and it did not pass
  kExitInterrupted = 130,   // SIGINT or SIGTERM ended the flight (what shells report for ^C)
};

// A bad command line: main() prints "mixpilot COMMAND: MESSAGE (see 'mixpilot COMMAND --help')"
// and exits with kExitUsage. Nothing below main exits: the error unwinds through the command,
// whose outputs close on the way (every command checks its whole command line before it opens
// any output, so none is left behind).
struct UsageError {
  std::string command;
  std::string message;
};
[[noreturn]] void usage_error(const char* command, const std::string& message);
// What main() prints for it.
void print_usage_error(const UsageError& e);
// "MESSAGE (see 'mixpilot COMMAND --help')": a usage error returned rather than thrown.
std::string usage_message(const char* command, const std::string& message);

// The value of the option argv[i] (i moves past it). A missing value, or an empty one, is a
// usage error naming the option: an empty file name would otherwise read as "none", the
// defaults, or the current folder.
std::string option_value(const char* command, int argc, char** argv, int& i);
// A positional argument (a file the command reads): an empty one is a usage error.
std::string file_argument(const char* command, const char* what, std::string_view arg);

// Outputs never replace an input of the same run: a usage error when `output` (given as
// option `option`) is, by device and inode, the same file as one of `inputs` (option, path),
// whatever names, links or folders lead to them.
void check_not_an_input(const char* command, const std::string& option, const std::string& output,
                        const std::vector<std::pair<std::string, std::string>>& inputs);

// A positive, finite number of seconds no larger than `max`, or nullopt.
std::optional<double> parse_seconds(std::string_view text, double max);

// Writes `text` to `path` through a unique temporary in the same directory, moved into place
// (core/base/output_file.hpp: never over a special file or an input, over an existing file
// only with `overwrite`). A failed write leaves nothing; a complete file that cannot be moved
// into place stays in its temporary, and the message says where.
bool write_file(const std::string& path, const std::string& text, bool overwrite,
                std::string& error);

// SIGINT and SIGTERM set a flag that long loops poll (interrupted()); the handler then resets
// itself, so a second ^C ends the process at once.
void catch_interrupts();
bool interrupted();

// A progress bar on stderr when it is a terminal: "label [#####   ] 42%". Otherwise nothing,
// or with `Piped::tenths` a line "label: N %" at every tenth (for a log, or a parent process
// that shows the progress itself).
class Progress {
 public:
  enum class Piped { silent, tenths };
  Progress(std::string label, std::int64_t total, Piped piped = Piped::silent);
  ~Progress() { finish(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  void update(std::int64_t done);  // redraws at most every 100 ms
  void finish();                   // clears the line

 private:
  std::string label_;
  std::int64_t total_;
  bool tty_;
  Piped piped_;
  int tenths_said_ = 0;  // Piped::tenths: the last tenth printed
  bool drawn_ = false;
  std::int64_t last_ns_ = 0;
};

}  // namespace mixpilot::cli
