#pragma once
// A real PostgreSQL 15 server for a test run: Debian's binaries (/usr/lib/postgresql/15/bin, or
// the folder in MIXPILOT_TEST_PG_BIN), a cluster initdb'd into a fresh temporary folder by an
// unprivileged user (the current one; `nobody` when the tests run as root, since initdb and
// postgres refuse root), listening only on a Unix socket in that folder (listen_addresses=''),
// password (SCRAM) authentication with a password generated for the run. The server is stopped
// (immediate shutdown, then SIGKILL) and the folder removed when the object goes; if the test
// process dies first, the kernel sends the postmaster SIGQUIT (PR_SET_PDEATHSIG), so no server
// outlives its test.
//
// PostgresEnvironment is the gtest Environment that starts one server per test binary run;
// a test asks it for the server and skips (with the reason) only where no server can be
// started on this machine: no binaries, or root without a way to become an unprivileged user.
// Any other failure to start is a test failure.
#include <gtest/gtest.h>
#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>

namespace mixpilot::test {

class PostgresServer {
 public:
  enum class Start { started, unavailable, failed };

  // Starts a server; on `unavailable` or `failed`, `reason` says why (with the server's log).
  static std::unique_ptr<PostgresServer> start(Start& status, std::string& reason);
  ~PostgresServer();
  PostgresServer(const PostgresServer&) = delete;
  PostgresServer& operator=(const PostgresServer&) = delete;

  // A libpq URL of database `db` as the cluster's superuser, with its password.
  [[nodiscard]] std::string url(const std::string& db = "postgres") const;
  // The same with another password (for tests of a wrong one).
  [[nodiscard]] std::string url_with_password(const std::string& db,
                                              const std::string& password) const;
  [[nodiscard]] const std::string& password() const { return password_; }
  [[nodiscard]] const std::filesystem::path& folder() const { return folder_; }

  // Runs one SQL command as the superuser on `db` (no parameters: the tests' own statements).
  [[nodiscard]] bool exec(const std::string& db, const std::string& sql, std::string& error) const;
  // The first column of the first row of `sql`'s answer ("" for NULL); nullopt with `error`.
  [[nodiscard]] std::optional<std::string> scalar(const std::string& db, const std::string& sql,
                                                  std::string& error) const;
  // A fresh, empty database (dropped first if it exists); its name must be a plain identifier.
  [[nodiscard]] bool create_database(const std::string& name, std::string& error) const;
  // Stops the server at once (as a crash or a power cut would) and starts it again on the same
  // cluster: clients' connections break.
  [[nodiscard]] bool restart(std::string& error);
  // The last lines of the server's log.
  [[nodiscard]] std::string log_tail(std::size_t lines = 20) const;

 private:
  PostgresServer() = default;
  bool launch(std::string& reason);  // the postmaster, until it accepts connections
  void stop_postmaster();
  void stop();

  std::filesystem::path folder_;  // the socket, the cluster (data/), the log
  std::string password_;
  std::filesystem::path bin_;
  std::optional<std::pair<uid_t, gid_t>> account_;  // the server's user, when not ours
  pid_t postmaster_ = -1;
};

class PostgresEnvironment : public ::testing::Environment {
 public:
  void SetUp() override;
  void TearDown() override;
  // The run's server, or null (then `skip_reason()` or a failure said why).
  static PostgresServer* server();
  static bool unavailable();
  static const std::string& reason();

 private:
  static std::unique_ptr<PostgresServer>& instance();
};

}  // namespace mixpilot::test

// In a test: the run's server, skipping the test where none can start here and failing it
// where one should have started and did not.
#define MIXPILOT_REQUIRE_POSTGRES(server_var)                                                     \
  ::mixpilot::test::PostgresServer* server_var = ::mixpilot::test::PostgresEnvironment::server(); \
  if (server_var == nullptr) {                                                                    \
    if (::mixpilot::test::PostgresEnvironment::unavailable())                                     \
      GTEST_SKIP() << ::mixpilot::test::PostgresEnvironment::reason();                            \
    FAIL() << "the test PostgreSQL server did not start: "                                        \
           << ::mixpilot::test::PostgresEnvironment::reason();                                    \
  }
