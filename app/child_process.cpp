#include "app/child_process.hpp"

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>

extern char** environ;

namespace mixpilot::cli {

namespace {

bool executable_file(const std::string& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(path.c_str(), X_OK) == 0;
}

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

}  // namespace

std::string find_program(const std::string& name, const std::string& search_path) {
  if (name.empty()) return "";
  if (name.find('/') != std::string::npos) return executable_file(name) ? name : "";
  std::size_t begin = 0;
  while (begin <= search_path.size()) {
    const std::size_t end = std::min(search_path.find(':', begin), search_path.size());
    const std::string dir = search_path.substr(begin, end - begin);
    const std::string candidate = (dir.empty() ? std::string(".") : dir) + "/" + name;
    if (executable_file(candidate)) return candidate;
    begin = end + 1;
  }
  return "";
}

std::string to_string(const ChildExit& e) {
  if (e.exited) return "exit status " + std::to_string(e.code);
  const char* name = ::strsignal(e.code);
  return "killed by signal " + std::to_string(e.code) + (name ? std::string(" (") + name + ")" : "");
}

ChildProcess::~ChildProcess() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    (void)wait();
  }
  close_fds();
}

void ChildProcess::close_fds() {
  close_fd(in_);
  close_fd(err_);
  close_fd(out_);
}

bool ChildProcess::start(const std::string& program, const std::vector<std::string>& args,
                         Input input, std::string& error, Output output) {
  if (pid_ > 0) {
    error = "a child process is running already";
    return false;
  }
  close_fds();  // a previous child's standard error
  int in[2] = {-1, -1}, err[2] = {-1, -1}, out[2] = {-1, -1};
  if ((input == Input::pipe && ::pipe2(in, O_CLOEXEC) != 0) || ::pipe2(err, O_CLOEXEC) != 0 ||
      (output == Output::pipe && ::pipe2(out, O_CLOEXEC) != 0)) {
    error = std::string("cannot make a pipe: ") + std::strerror(errno);
    for (int fd : {in[0], in[1], err[0], err[1], out[0], out[1]})
      if (fd >= 0) ::close(fd);
    return false;
  }
  // A whole frame fits in fewer writes with a larger pipe (best effort: capped by the system).
  if (input == Input::pipe) (void)::fcntl(in[1], F_SETPIPE_SZ, 1 << 20);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (input == Input::pipe) posix_spawn_file_actions_adddup2(&actions, in[0], STDIN_FILENO);
  else posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  if (output == Output::pipe) posix_spawn_file_actions_adddup2(&actions, out[1], STDOUT_FILENO);
  else posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
  // Nothing else of this process reaches the child (a window's or a library's descriptors).
  posix_spawn_file_actions_addclosefrom_np(&actions, STDERR_FILENO + 1);

  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  sigset_t none, defaults;
  sigemptyset(&none);
  sigemptyset(&defaults);
  // This process may ignore SIGPIPE (it writes to pipes) or catch ^C: the child starts clean.
  for (int s : {SIGPIPE, SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, s);
  posix_spawnattr_setsigmask(&attr, &none);
  posix_spawnattr_setsigdefault(&attr, &defaults);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF |
                                      POSIX_SPAWN_SETPGROUP);

  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(program.c_str()));
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int rc = ::posix_spawn(&pid, program.c_str(), &actions, &attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (in[0] >= 0) ::close(in[0]);
  if (out[1] >= 0) ::close(out[1]);
  ::close(err[1]);
  if (rc != 0) {
    error = "cannot run " + program + ": " + std::strerror(rc);
    if (in[1] >= 0) ::close(in[1]);
    if (out[0] >= 0) ::close(out[0]);
    ::close(err[0]);
    return false;
  }
  pid_ = pid;
  in_ = in[1];
  err_ = err[0];
  out_ = out[0];
  return true;
}

ChildProcess::Write ChildProcess::write(const void* data, std::size_t bytes, bool (*stop)()) {
  const auto* p = static_cast<const char*>(data);
  while (bytes > 0) {
    if (in_ < 0) return Write::closed;
    const ssize_t n = ::write(in_, p, bytes);
    if (n > 0) {
      p += n;
      bytes -= std::size_t(n);
    } else if (n < 0 && errno == EINTR) {
      if (stop && stop()) return Write::interrupted;
    } else {
      return Write::closed;  // EPIPE: the child is gone (this process ignores SIGPIPE)
    }
  }
  return Write::done;
}

void ChildProcess::close_input() { close_fd(in_); }

void ChildProcess::error_nonblocking() {
  if (err_ >= 0) ::fcntl(err_, F_SETFL, ::fcntl(err_, F_GETFL) | O_NONBLOCK);
}

namespace {

// Reads what is there from `fd` into `text`; false at its end.
bool read_some(int fd, std::string& text) {
  char buf[4096];
  while (fd >= 0) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n > 0) {
      text.append(buf, std::size_t(n));
      return true;
    }
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return true;
    return false;
  }
  return false;
}

}  // namespace

bool ChildProcess::read_error(std::string& text) { return read_some(err_, text); }
bool ChildProcess::read_output(std::string& text) { return read_some(out_, text); }

void ChildProcess::signal(int sig) {
  if (pid_ > 0) ::kill(pid_, sig);
}

namespace {

ChildExit exit_of(int status) {
  if (WIFEXITED(status)) return {true, WEXITSTATUS(status)};
  return {false, WIFSIGNALED(status) ? WTERMSIG(status) : 0};
}

}  // namespace

std::optional<ChildExit> ChildProcess::poll() {
  if (pid_ <= 0) return std::nullopt;
  int status = 0;
  pid_t r;
  do r = ::waitpid(pid_, &status, WNOHANG);
  while (r < 0 && errno == EINTR);
  if (r == 0) return std::nullopt;
  pid_ = -1;
  close_fd(in_);
  return r < 0 ? ChildExit{false, 0} : exit_of(status);
}

ChildExit ChildProcess::wait() {
  if (pid_ <= 0) return {};
  int status = 0;
  pid_t r;
  do r = ::waitpid(pid_, &status, 0);
  while (r < 0 && errno == EINTR);
  pid_ = -1;
  close_fd(in_);
  return r < 0 ? ChildExit{false, 0} : exit_of(status);
}

bool run_program(const std::string& program, const std::vector<std::string>& args,
                 double timeout_seconds, ProgramRun& run, std::string& error) {
  run = ProgramRun{};
  ChildProcess child;
  if (!child.start(program, args, ChildProcess::Input::none, error, ChildProcess::Output::pipe))
    return false;
  // Both pipes drained as they fill (a child blocked on a full one would never end), until
  // both end.
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_seconds);
  bool out_open = true, err_open = true;
  while (out_open || err_open) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        until - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      run.timed_out = true;
      child.signal(SIGKILL);
      break;
    }
    // A negative descriptor is skipped by poll().
    pollfd fds[2] = {{out_open ? child.output_fd() : -1, POLLIN, 0},
                     {err_open ? child.error_fd() : -1, POLLIN, 0}};
    const int r = ::poll(fds, 2, static_cast<int>(std::min<long long>(left.count(), 1000)));
    if (r < 0 && errno != EINTR) break;
    if (r <= 0) continue;
    if (fds[0].revents != 0) out_open = child.read_output(run.out);
    if (fds[1].revents != 0) err_open = child.read_error(run.err);
  }
  run.exit = child.wait();
  return true;
}

}  // namespace mixpilot::cli
