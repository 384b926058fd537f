#pragma once
// A process a test starts and owns: fork + exec (no shell), its output into a file, its own
// environment additions, waited for on a condition with a generous timeout (never a timed
// verdict), interrupted like ^C, and killed and reaped if the test leaves early, so a failing
// test on a loaded machine leaves nothing running.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <fcntl.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace mixpilot::test {

class Spawned {
 public:
  Spawned() = default;
  // Starts `argv` with `env` added to this process's environment, stdout and stderr into `out`.
  Spawned(const std::vector<std::string>& argv, const std::filesystem::path& out,
          const std::vector<std::pair<std::string, std::string>>& env = {}) {
    start(argv, out, env);
  }
  ~Spawned() {
    if (pid_ > 0 && status_ < 0) {
      ::kill(pid_, SIGKILL);
      int st = 0;
      ::waitpid(pid_, &st, 0);
    }
  }
  Spawned(const Spawned&) = delete;
  Spawned& operator=(const Spawned&) = delete;

  bool start(const std::vector<std::string>& argv, const std::filesystem::path& out,
             const std::vector<std::pair<std::string, std::string>>& env = {}) {
    pid_ = ::fork();
    if (pid_ == 0) {
      const int fd = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        ::dup2(fd, 1);
        ::dup2(fd, 2);
        ::close(fd);
      }
      for (const auto& [k, v] : env) ::setenv(k.c_str(), v.c_str(), 1);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    return pid_ > 0;
  }
  pid_t pid() const { return pid_; }
  // The exit status once it has ended (128 + signal when killed), waiting up to `seconds`;
  // −1 while it runs.
  int wait(double seconds) {
    if (status_ >= 0 || pid_ <= 0) return status_;
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      int st = 0;
      const pid_t r = ::waitpid(pid_, &st, WNOHANG);
      if (r == pid_) {
        status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        return status_;
      }
      if (std::chrono::steady_clock::now() > until) return -1;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  // ^C: a flight ends at its next step, its summary printed.
  void interrupt() {
    if (pid_ > 0 && status_ < 0) ::kill(pid_, SIGINT);
  }

 private:
  pid_t pid_ = -1;
  int status_ = -1;
};

// Runs `argv` to its end (up to `seconds`): its exit status, −1 if it did not end in time (it is
// then killed).
inline int run_to_end(const std::vector<std::string>& argv, const std::filesystem::path& out,
                      double seconds,
                      const std::vector<std::pair<std::string, std::string>>& env = {}) {
  Spawned p(argv, out, env);
  return p.wait(seconds);
}

}  // namespace mixpilot::test
