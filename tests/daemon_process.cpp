#include "daemon_process.hpp"

#include <fcntl.h>
#include <grp.h>
#include <sys/prctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <deque>
#include <fstream>

namespace mixpilot::test {

namespace {

std::vector<char*> c_strings(const std::vector<std::string>& v) {
  std::vector<char*> out;
  out.reserve(v.size() + 1);
  for (const auto& s : v) out.push_back(const_cast<char*>(s.c_str()));
  out.push_back(nullptr);
  return out;
}

}  // namespace

pid_t spawn_daemon(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                   const std::filesystem::path& log, const DaemonSettings& settings) {
  std::vector<char*> args = c_strings(argv);
  std::vector<char*> envp = c_strings(env);
  const std::string log_path = log.string();
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  // The child: only async-signal-safe calls from here to exec.
  const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0600);
  if (fd >= 0) {
    ::dup2(fd, STDOUT_FILENO);
    ::dup2(fd, STDERR_FILENO);
  }
  const int null_in = ::open("/dev/null", O_RDONLY);
  if (null_in >= 0) ::dup2(null_in, STDIN_FILENO);
  auto say = [](const char* what) { (void)!::write(STDERR_FILENO, what, std::strlen(what)); };
  if (settings.own_process_group) ::setpgid(0, 0);
  if (const auto& a = settings.account) {
    if (::setgroups(0, nullptr) != 0 || ::setgid(a->gid) != 0 || ::setuid(a->uid) != 0 ||
        ::getuid() != a->uid) {
      say("cannot become the unprivileged user: ");
      say(std::strerror(errno));
      say("\n");
      ::_exit(kDaemonCannotDrop);
    }
  }
  // After the change of user, which clears the parent-death signal.
  ::prctl(PR_SET_PDEATHSIG, settings.death_signal);
  if (::getppid() != parent) ::_exit(1);
  ::execve(args[0], args.data(), envp.data());
  say("cannot run ");
  say(args[0]);
  say(": ");
  say(std::strerror(errno));
  say("\n");
  ::_exit(kDaemonCannotExec);
}

std::string tail_of(const std::filesystem::path& file, std::size_t lines) {
  std::ifstream in(file);
  std::deque<std::string> last;
  for (std::string line; std::getline(in, line);) {
    last.push_back(line);
    if (last.size() > lines) last.pop_front();
  }
  std::string out;
  for (const auto& l : last) out += "\n  | " + l;
  return out;
}

}  // namespace mixpilot::test
