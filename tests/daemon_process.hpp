#pragma once
// Starting the servers a test needs (PostgreSQL, munge and Slurm's daemons): fork + exec with
// exactly the environment given, output appended to a log, stdin from /dev/null, optionally as
// another user, and a signal to the daemon when the starting thread ends, so a test that dies
// leaves no server behind.
#include <sys/types.h>

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace mixpilot::test {

// Exit codes of a daemon's child that never reached exec.
inline constexpr int kDaemonCannotDrop = 120;  // could not become the unprivileged user
inline constexpr int kDaemonCannotExec = 121;

struct DaemonSettings {
  struct Account {
    uid_t uid;
    gid_t gid;
  };
  std::optional<Account> account;  // run as this user (the caller is root)
  bool own_process_group = false;  // a ^C at the terminal reaches only the test, which stops it
  int death_signal = 15;           // SIGTERM when the starting thread ends
};

// Starts `argv` (argv[0] a full path) with exactly `env` (KEY=VALUE), stdout and stderr
// appended to `log`. The pid, or -1 if fork failed.
[[nodiscard]] pid_t spawn_daemon(const std::vector<std::string>& argv,
                                 const std::vector<std::string>& env,
                                 const std::filesystem::path& log, const DaemonSettings& settings);

// The last `lines` lines of `file`, each on its own line after "  | ", for a failure's reason.
[[nodiscard]] std::string tail_of(const std::filesystem::path& file, std::size_t lines);

}  // namespace mixpilot::test
