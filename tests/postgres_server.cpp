#include "postgres_server.hpp"

#include "daemon_process.hpp"

#include <fcntl.h>
#include <grp.h>
#include <libpq-fe.h>
#include <pwd.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>
#include <vector>

namespace mixpilot::test {

namespace fs = std::filesystem;

namespace {

constexpr const char* kSuperuser = "mixpilot";
constexpr const char* kPort = "5432";  // only names the socket file: nothing listens on TCP

using Account = DaemonSettings::Account;

std::string random_password() {
  static const char alphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789";
  std::random_device rd;
  std::string out;
  for (int i = 0; i < 32; ++i) out += alphabet[rd() % (sizeof alphabet - 1)];
  return out;
}

std::string percent_encode(const std::string& s) {
  std::string out;
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += static_cast<char>(c);
    } else {
      char buf[4];
      std::snprintf(buf, sizeof buf, "%%%02X", c);
      out += buf;
    }
  }
  return out;
}


// Waits for `pid` at most `timeout`; its status, or nullopt if it still runs.
std::optional<int> wait_for(pid_t pid, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return status;
    if (r < 0) return -1;
    if (std::chrono::steady_clock::now() >= until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::string conninfo_of(const fs::path& folder, const std::string& db, const std::string& pw) {
  return "host='" + folder.string() + "' port=" + kPort + " user=" + kSuperuser + " dbname='" + db +
         "' password='" + pw + "' connect_timeout=5";
}

// A run killed by SIGKILL stops its server (the death signal) but cannot remove its folder:
// folders of ours in `base` older than an hour whose postmaster no longer runs are removed.
void remove_stale_folders(const fs::path& base) {
  std::error_code ec;
  const auto now = fs::file_time_type::clock::now();
  for (const auto& e : fs::directory_iterator(base, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("mixpilot-pg.", 0) != 0 || name.size() != 18 || !e.is_directory(ec)) continue;
    if (now - e.last_write_time(ec) < std::chrono::hours(1) || ec) continue;
    pid_t pid = 0;
    std::ifstream(e.path() / "data" / "postmaster.pid") >> pid;
    if (pid > 0 && (::kill(pid, 0) == 0 || errno == EPERM)) continue;
    fs::remove_all(e.path(), ec);
  }
}

}  // namespace

std::unique_ptr<PostgresServer> PostgresServer::start(Start& status, std::string& reason) {
  status = Start::failed;
  const char* bin_env = std::getenv("MIXPILOT_TEST_PG_BIN");
  const fs::path bin =
      bin_env && *bin_env ? fs::path(bin_env) : fs::path("/usr/lib/postgresql/15/bin");
  for (const char* tool : {"initdb", "postgres"}) {
    if (::access((bin / tool).c_str(), X_OK) != 0) {
      status = Start::unavailable;
      reason = "no PostgreSQL server binaries: " + (bin / tool).string() +
               " is missing (Debian: apt-get install postgresql, packaging/setup-debian.sh)";
      return nullptr;
    }
  }

  // initdb and postgres refuse to run as root: as root, the cluster belongs to `nobody`.
  std::optional<Account> account;
  if (::geteuid() == 0) {
    const passwd* pw = ::getpwnam("nobody");
    if (pw == nullptr || pw->pw_uid == 0) {
      status = Start::unavailable;
      reason = "running as root and there is no unprivileged user `nobody` to run the server as";
      return nullptr;
    }
    account = Account{pw->pw_uid, pw->pw_gid};
  }

  // A short folder name: the socket's path must fit in sun_path (107 bytes). As root the
  // folder's parents must be open to `nobody`, which /tmp is.
  fs::path base = "/tmp";
  if (!account) {
    std::error_code ec;
    const fs::path t = fs::temp_directory_path(ec);
    if (!ec && t.string().size() < 60) base = t;
  }
  remove_stale_folders(base);
  std::string tmpl = (base / "mixpilot-pg.XXXXXX").string();
  if (::mkdtemp(tmpl.data()) == nullptr) {
    reason = "cannot create a temporary folder in " + base.string() + ": " + std::strerror(errno);
    return nullptr;
  }
  std::unique_ptr<PostgresServer> server(new PostgresServer);
  server->folder_ = tmpl;
  server->password_ = random_password();
  const fs::path& dir = server->folder_;
  const fs::path log = dir / "server.log";
  const fs::path pwfile = dir / "pwfile";
  {
    std::ofstream out(pwfile);
    out << server->password_ << '\n';
  }
  if (account && (::chown(dir.c_str(), account->uid, account->gid) != 0 ||
                  ::chown(pwfile.c_str(), account->uid, account->gid) != 0)) {
    status = Start::unavailable;
    reason = "running as root and cannot give the server's folder to `nobody`: " +
             std::string(std::strerror(errno));
    return nullptr;
  }
  ::chmod(pwfile.c_str(), 0600);

  const std::vector<std::string> env = {"LC_ALL=C", "LANG=C", "TZ=UTC", "PATH=/usr/bin:/bin",
                                        "HOME=" + dir.string()};
  const pid_t initdb = spawn_daemon({(bin / "initdb").string(), "-D", (dir / "data").string(), "-U",
                              kSuperuser, "--auth=scram-sha-256", "--pwfile=" + pwfile.string(),
                              "--no-sync", "--encoding=UTF8", "--locale=C", "--no-instructions"},
                             env, log, {.account = account, .own_process_group = false, .death_signal = SIGKILL});
  if (initdb < 0) {
    reason = std::string("fork: ") + std::strerror(errno);
    return nullptr;
  }
  const auto initdb_status = wait_for(initdb, std::chrono::seconds(120));
  fs::remove(pwfile);
  if (!initdb_status) {
    ::kill(initdb, SIGKILL);
    ::waitpid(initdb, nullptr, 0);
    reason = "initdb did not finish in 120 s:" + tail_of(log, 20);
    return nullptr;
  }
  if (!WIFEXITED(*initdb_status) || WEXITSTATUS(*initdb_status) != 0) {
    if (WIFEXITED(*initdb_status) && WEXITSTATUS(*initdb_status) == kDaemonCannotDrop)
      status = Start::unavailable;
    reason = "initdb failed:" + tail_of(log, 20);
    return nullptr;
  }

  server->bin_ = bin;
  if (account) server->account_ = {account->uid, account->gid};
  if (!server->launch(reason)) return nullptr;
  status = Start::started;
  return server;
}

bool PostgresServer::launch(std::string& reason) {
  const fs::path& dir = folder_;
  const fs::path log = dir / "server.log";
  const std::vector<std::string> env = {"LC_ALL=C", "LANG=C", "TZ=UTC", "PATH=/usr/bin:/bin",
                                        "HOME=" + dir.string()};
  std::optional<Account> account;
  if (account_) account = Account{account_->first, account_->second};
  // Only the Unix socket in the folder; durability is not what these tests measure.
  postmaster_ = spawn_daemon(
      {(bin_ / "postgres").string(), "-D", (dir / "data").string(), "-k", dir.string(), "-p", kPort,
       "-c", "listen_addresses=", "-c", "fsync=off", "-c", "full_page_writes=off", "-c",
       "max_connections=60", "-c", "shared_buffers=16MB", "-c", "logging_collector=off"},
      env, log, {.account = account, .own_process_group = false, .death_signal = SIGQUIT});
  if (postmaster_ < 0) {
    reason = std::string("fork: ") + std::strerror(errno);
    return false;
  }
  const std::string ping = conninfo_of(dir, "postgres", password_);
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  for (;;) {
    if (PQping(ping.c_str()) == PQPING_OK) return true;
    if (wait_for(postmaster_, std::chrono::milliseconds(0))) {
      postmaster_ = -1;
      reason = "the server exited at start:" + tail_of(log, 20);
      return false;
    }
    if (std::chrono::steady_clock::now() >= until) {
      reason = "the server did not accept connections within 60 s:" + tail_of(log, 20);
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  }
}

void PostgresServer::stop_postmaster() {
  if (postmaster_ > 0) {
    // Immediate shutdown: the postmaster ends its backends and exits without a checkpoint.
    ::kill(postmaster_, SIGQUIT);
    if (!wait_for(postmaster_, std::chrono::seconds(10))) {
      ::kill(postmaster_, SIGKILL);
      ::waitpid(postmaster_, nullptr, 0);
    }
    postmaster_ = -1;
  }
}

bool PostgresServer::restart(std::string& error) {
  stop_postmaster();
  return launch(error);
}

void PostgresServer::stop() {
  stop_postmaster();
  if (!folder_.empty()) {
    std::error_code ec;
    fs::remove_all(folder_, ec);
    folder_.clear();
  }
}

PostgresServer::~PostgresServer() { stop(); }

std::string PostgresServer::url_with_password(const std::string& db,
                                              const std::string& password) const {
  return std::string("postgresql://") + kSuperuser + ":" + percent_encode(password) + "@/" +
         percent_encode(db) + "?host=" + percent_encode(folder_.string()) + "&port=" + kPort;
}

std::string PostgresServer::url(const std::string& db) const {
  return url_with_password(db, password_);
}

bool PostgresServer::exec(const std::string& db, const std::string& sql, std::string& error) const {
  PGconn* c = PQconnectdb(conninfo_of(folder_, db, password_).c_str());
  PQsetNoticeReceiver(
      c, [](void*, const PGresult*) {}, nullptr);
  bool ok = false;
  if (PQstatus(c) != CONNECTION_OK) {
    error = PQerrorMessage(c);
  } else {
    PGresult* r = PQexec(c, sql.c_str());
    const auto st = PQresultStatus(r);
    ok = st == PGRES_COMMAND_OK || st == PGRES_TUPLES_OK;
    if (!ok) error = PQresultErrorMessage(r);
    PQclear(r);
  }
  PQfinish(c);
  return ok;
}

std::optional<std::string> PostgresServer::scalar(const std::string& db, const std::string& sql,
                                                  std::string& error) const {
  PGconn* c = PQconnectdb(conninfo_of(folder_, db, password_).c_str());
  std::optional<std::string> out;
  if (PQstatus(c) != CONNECTION_OK) {
    error = PQerrorMessage(c);
  } else {
    PGresult* r = PQexec(c, sql.c_str());
    if (PQresultStatus(r) == PGRES_TUPLES_OK && PQntuples(r) > 0 && PQnfields(r) > 0)
      out = std::string(PQgetvalue(r, 0, 0));
    else
      error = std::string("no answer: ") + PQresultErrorMessage(r);
    PQclear(r);
  }
  PQfinish(c);
  return out;
}

bool PostgresServer::create_database(const std::string& name, std::string& error) const {
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) {
      error = "not a plain identifier: " + name;
      return false;
    }
  return exec("postgres", "DROP DATABASE IF EXISTS " + name + " WITH (FORCE)", error) &&
         exec("postgres", "CREATE DATABASE " + name, error);
}

std::string PostgresServer::log_tail(std::size_t lines) const {
  return tail_of(folder_ / "server.log", lines);
}

std::unique_ptr<PostgresServer>& PostgresEnvironment::instance() {
  static std::unique_ptr<PostgresServer> s;
  return s;
}

namespace {
PostgresServer::Start g_status = PostgresServer::Start::failed;
std::string g_reason = "the test environment was not set up";
}  // namespace

void PostgresEnvironment::SetUp() { instance() = PostgresServer::start(g_status, g_reason); }
void PostgresEnvironment::TearDown() { instance().reset(); }
PostgresServer* PostgresEnvironment::server() { return instance().get(); }
bool PostgresEnvironment::unavailable() { return g_status == PostgresServer::Start::unavailable; }
const std::string& PostgresEnvironment::reason() { return g_reason; }

}  // namespace mixpilot::test
