// The PostgreSQL backend of the history against a real server that the test run starts itself
// (tests/postgres_server.hpp): the server helper, the store's contract, hostile names, writers
// at once, a newer schema, credentials kept out of every message, and `history push`.
#include <gtest/gtest.h>
#include <signal.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "postgres_server.hpp"

namespace mixpilot::test {
namespace {

namespace fs = std::filesystem;

[[maybe_unused]] const auto* const kEnvironment =
    ::testing::AddGlobalTestEnvironment(new PostgresEnvironment);

// The run's server is reachable with its password, private (no TCP listener), and not root's.
TEST(Postgres, ServerStartsPrivateWithPassword) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  std::string error;
  ASSERT_TRUE(server->exec("postgres", "SELECT 1", error)) << error;
  ASSERT_TRUE(server->exec("postgres",
                           "DO $$ BEGIN IF current_setting('listen_addresses') <> '' THEN "
                           "RAISE EXCEPTION 'listens on %', current_setting('listen_addresses'); "
                           "END IF; END $$",
                           error))
      << error;
  ASSERT_TRUE(server->exec("postgres",
                           "DO $$ BEGIN IF current_setting('password_encryption') <> "
                           "'scram-sha-256' THEN RAISE EXCEPTION 'no scram'; END IF; END $$",
                           error))
      << error;
  EXPECT_TRUE(fs::exists(server->folder() / ".s.PGSQL.5432"));
  EXPECT_EQ(fs::status(server->folder()).permissions() & fs::perms::others_all, fs::perms::none);
}

// A second server starts beside the first, and once gone leaves no process and no folder.
TEST(Postgres, ServerStopsAndRemovesItsFolder) {
  MIXPILOT_REQUIRE_POSTGRES(server);
  PostgresServer::Start status{};
  std::string reason;
  auto second = PostgresServer::start(status, reason);
  ASSERT_EQ(status, PostgresServer::Start::started) << reason;
  const fs::path folder = second->folder();
  std::string error;
  ASSERT_TRUE(second->create_database("scratch", error)) << error;
  ASSERT_TRUE(second->exec("scratch", "CREATE TABLE t (x INTEGER)", error)) << error;
  const fs::path pid_file = folder / "data" / "postmaster.pid";
  ASSERT_TRUE(fs::exists(pid_file));
  pid_t pid = 0;
  {
    std::ifstream in(pid_file);
    in >> pid;
  }
  ASSERT_GT(pid, 0);
  second.reset();
  EXPECT_FALSE(fs::exists(folder));
  EXPECT_NE(::kill(pid, 0), 0) << "the postmaster " << pid << " still runs";
  // The first server is untouched.
  EXPECT_TRUE(server->exec("postgres", "SELECT 1", error)) << error;
}

}  // namespace
}  // namespace mixpilot::test
