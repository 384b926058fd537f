#pragma once
// A program run as a child process without a shell (posix_spawn, its arguments a vector): its
// standard input a pipe this process writes, or /dev/null; its standard output /dev/null, or a
// pipe this process reads; its standard error a pipe this process reads. The child runs in a process group of its own, so a
// ^C at the terminal reaches this process only, which decides what becomes of the child.
#include <sys/types.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace mixpilot::cli {

// The executable file `name` in the folders of `search_path` (PATH's syntax: folders separated
// by ':', an empty entry meaning the current folder), or "" when none holds one. A name with a
// '/' is taken as it is.
std::string find_program(const std::string& name, const std::string& search_path);

// How a child ended.
struct ChildExit {
  bool exited = false;  // it exited (false: a signal ended it)
  int code = 0;         // its exit status, or the signal's number
  bool ok() const { return exited && code == 0; }
};
// "exit status 1", "killed by signal 9 (Killed)".
std::string to_string(const ChildExit& e);

class ChildProcess {
 public:
  enum class Input { pipe, none };
  enum class Output { none, pipe };
  enum class Write { done, closed, interrupted };

  ChildProcess() = default;
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  // A child still running is killed (SIGKILL) and reaped.
  ~ChildProcess();

  // Starts `program` (a path) with `args` (argv[1...]); false with the reason.
  [[nodiscard]] bool start(const std::string& program, const std::vector<std::string>& args,
                           Input input, std::string& error, Output output = Output::none);
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }

  // Writes all of `bytes` to the child's standard input. `closed`: the child closed it (it
  // ended or failed); `interrupted`: a signal arrived and `stop()` says to stop (^C).
  [[nodiscard]] Write write(const void* data, std::size_t bytes, bool (*stop)());
  // No more input: the child sees the end of its file.
  void close_input();

  // The read end of the child's standard error (-1 when closed).
  int error_fd() const { return err_; }
  // Puts that end in non-blocking mode (read_error() then never waits).
  void error_nonblocking();
  // Reads what the child has written to its standard error into `text`; false at its end (the
  // child closed it), true when there may be more (or, non-blocking, nothing yet).
  bool read_error(std::string& text);

  // The read end of the child's standard output (Output::pipe; -1 otherwise or when closed),
  // and what it has written there, as read_error() reads its standard error.
  int output_fd() const { return out_; }
  bool read_output(std::string& text);

  // Sends `sig` to the child (nothing once it is reaped).
  void signal(int sig);
  // Whether the child has ended, without waiting; reaps it when it has.
  std::optional<ChildExit> poll();
  // Waits for the child to end and reaps it.
  ChildExit wait();

 private:
  void close_fds();

  pid_t pid_ = -1;
  int in_ = -1;   // write end of the child's standard input
  int err_ = -1;  // read end of its standard error
  int out_ = -1;  // read end of its standard output (Output::pipe)
};

// A program run to its end, its standard output and error read (standard input /dev/null).
struct ProgramRun {
  ChildExit exit;
  std::string out;
  std::string err;
  bool timed_out = false;  // it ran longer than allowed and was killed (SIGKILL)
};
// Runs `program` (a path) with `args` for at most `timeout_seconds`; false with the reason when
// it could not be started.
[[nodiscard]] bool run_program(const std::string& program, const std::vector<std::string>& args,
                               double timeout_seconds, ProgramRun& run, std::string& error);

}  // namespace mixpilot::cli
