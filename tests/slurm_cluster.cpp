#include "slurm_cluster.hpp"

#include "daemon_process.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pwd.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <fstream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

extern char** environ;

namespace mixpilot::test {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr const char* kNode = "localhost";
constexpr const char* kPartition = "test";

// The executable `name` in PATH, or in the system folders where Debian puts daemons.
std::string find_tool(const std::string& name) {
  const char* env_path = std::getenv("PATH");
  std::string dirs = env_path ? env_path : "";
  dirs += ":/usr/sbin:/sbin:/usr/bin:/bin";
  std::stringstream ss(dirs);
  for (std::string dir; std::getline(ss, dir, ':');) {
    if (dir.empty()) continue;
    const fs::path p = fs::path(dir) / name;
    if (::access(p.c_str(), X_OK) == 0 && fs::is_regular_file(p)) return p.string();
  }
  return "";
}

std::string read_all(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<char*> c_strings(const std::vector<std::string>& v) {
  std::vector<char*> out;
  for (const auto& s : v) out.push_back(const_cast<char*>(s.c_str()));
  out.push_back(nullptr);
  return out;
}

// This process's environment with `extra` set.
std::vector<std::string> environment_with(
    const std::vector<std::pair<std::string, std::string>>& extra) {
  std::vector<std::string> out;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string kv = *e;
    bool replaced = false;
    for (const auto& [k, v] : extra)
      if (kv.rfind(k + "=", 0) == 0) replaced = true;
    if (!replaced) out.push_back(kv);
  }
  for (const auto& [k, v] : extra) out.push_back(k + "=" + v);
  return out;
}

// Whether `pid` (a child) has ended; reaps it.
bool ended(pid_t pid) {
  if (pid <= 0) return true;
  int status = 0;
  const pid_t r = ::waitpid(pid, &status, WNOHANG);
  return r == pid || (r < 0 && errno == ECHILD);
}

// Ends the child `pid`: `sig`, then SIGKILL after `grace`; reaps it.
void end_child(pid_t& pid, int sig, std::chrono::milliseconds grace) {
  if (pid <= 0) return;
  ::kill(pid, sig);
  const auto until = Clock::now() + grace;
  while (!ended(pid)) {
    if (Clock::now() >= until) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  pid = -1;
}

// A TCP port on 127.0.0.1 that nothing uses now (the kernel's choice of an ephemeral one).
int free_port() {
  const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (s < 0) return 0;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  int port = 0;
  if (::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
      ::getsockname(s, reinterpret_cast<sockaddr*>(&a), &len) == 0)
    port = ntohs(a.sin_port);
  ::close(s);
  return port;
}

// Runs `argv` with `env` to its end (at most `seconds`): its exit status, or -1 if it did not end
// (it is killed); its stdout and stderr in `output`.
int run_capture(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                std::string& output, double seconds) {
  output.clear();
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) {
    output = std::string("pipe: ") + std::strerror(errno);
    return -1;
  }
  std::vector<char*> args = c_strings(argv);
  std::vector<char*> envp = c_strings(env);
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fds[1], STDOUT_FILENO);
    ::dup2(fds[1], STDERR_FILENO);
    const int null_in = ::open("/dev/null", O_RDONLY);
    if (null_in >= 0) ::dup2(null_in, STDIN_FILENO);
    ::execve(args[0], args.data(), envp.data());
    ::_exit(kDaemonCannotExec);
  }
  ::close(fds[1]);
  if (pid < 0) {
    ::close(fds[0]);
    output = std::string("fork: ") + std::strerror(errno);
    return -1;
  }
  const auto until = Clock::now() + std::chrono::duration<double>(seconds);
  bool timed_out = false;
  char buf[4096];
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int r = ::poll(&p, 1, static_cast<int>(std::min<long>(left.count(), 1000)));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) continue;
    const ssize_t n = ::read(fds[0], buf, sizeof buf);
    if (n > 0) output.append(buf, std::size_t(n));
    else if (n == 0 || errno != EINTR) break;
  }
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (timed_out) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// The node's hardware from `slurmd -C` ("CPUs=2 Boards=1 ... RealMemory=24105"), without its
// name and uptime; "" with `reason` when it cannot tell.
std::string node_hardware(const std::string& slurmd, std::string& reason) {
  std::string out;
  const int rc = run_capture({slurmd, "-C"}, environment_with({}), out, 60);
  std::istringstream first_line(out.substr(0, out.find('\n')));
  std::string line;
  for (std::string tok; first_line >> tok;) {
    const std::string key = tok.substr(0, tok.find('='));
    if (key == "CPUs" || key == "Boards" || key == "SocketsPerBoard" || key == "CoresPerSocket" ||
        key == "ThreadsPerCore" || key == "RealMemory")
      line += " " + tok;
  }
  if (rc != 0 || line.find("CPUs=") == std::string::npos) {
    reason = "`slurmd -C` did not describe this machine (exit " + std::to_string(rc) + "): " + out;
    return "";
  }
  return line.substr(1);
}

// The processes whose environment holds exactly `entry` ("SLURM_CONF=/tmp/.../slurm.conf").
std::vector<pid_t> processes_with_env(const std::string& entry) {
  std::vector<pid_t> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == ::getpid()) continue;
    std::ifstream in(e.path() / "environ", std::ios::binary);
    std::string var;
    while (std::getline(in, var, '\0'))
      if (var == entry) {
        out.push_back(pid);
        break;
      }
  }
  return out;
}

// The parent of `pid` (its /proc stat's fourth field, after the command's parentheses), or -1.
pid_t parent_of(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  std::getline(in, stat);
  const std::size_t close = stat.rfind(')');
  if (close == std::string::npos) return -1;
  std::istringstream rest(stat.substr(close + 1));
  std::string state;
  long ppid = -1;
  rest >> state >> ppid;
  return static_cast<pid_t>(ppid);
}

// A cluster's folder whose test process is gone: its `owner` file names a process that no longer
// runs (or, without one, the folder is over an hour old).
bool abandoned(const fs::path& folder) {
  pid_t owner = 0;
  if (std::ifstream(folder / "owner") >> owner)
    return owner > 0 && ::kill(owner, 0) != 0 && errno == ESRCH;
  std::error_code ec;
  const auto age = fs::file_time_type::clock::now() - fs::last_write_time(folder, ec);
  return !ec && age > std::chrono::hours(1);
}

// A test process killed by SIGKILL stops its daemons (the death signal) but not the jobs they
// ran, nor can it remove its folder. The processes of such clusters (those whose SLURM_CONF is
// an abandoned mixpilot-slurm folder's) are killed and the folders removed.
void remove_stale_clusters(const fs::path& base) {
  const std::string prefix = "SLURM_CONF=" + (base / "mixpilot-slurm.").string();
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.empty() || name.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t pid = static_cast<pid_t>(std::stol(name));
    if (pid == ::getpid()) continue;
    std::ifstream in(e.path() / "environ", std::ios::binary);
    for (std::string var; std::getline(in, var, '\0');) {
      if (var.rfind(prefix, 0) != 0) continue;
      if (abandoned(fs::path(var.substr(std::strlen("SLURM_CONF="))).parent_path()))
        ::kill(pid, SIGKILL);
      break;
    }
  }
  for (const auto& e : fs::directory_iterator(base, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("mixpilot-slurm.", 0) != 0 || name.size() != 21 || !e.is_directory(ec)) continue;
    if (abandoned(e.path())) fs::remove_all(e.path(), ec);
  }
}

bool write_text(const fs::path& p, const std::string& text, mode_t mode) {
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0) return false;
  const bool ok = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::fchmod(fd, mode);
  return ::close(fd) == 0 && ok;
}

}  // namespace

std::unique_ptr<SlurmCluster> SlurmCluster::start(Start& status, std::string& reason) {
  status = Start::failed;
  for (const char* tool : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "scancel"}) {
    if (find_tool(tool).empty()) {
      status = Start::unavailable;
      reason = std::string("no ") + tool +
               " on this machine (Debian: apt-get install slurm-wlm munge, as "
               "packaging/setup-debian.sh does)";
      return nullptr;
    }
  }
  if (::geteuid() != 0) {
    status = Start::unavailable;
    reason = "slurmd starts each job as its user and must run as root; the tests run as uid " +
             std::to_string(::geteuid());
    return nullptr;
  }

  std::unique_ptr<SlurmCluster> c(new SlurmCluster);
  c->node_line_ = node_hardware(find_tool("slurmd"), reason);
  if (c->node_line_.empty()) return nullptr;

  // /tmp, not $TMPDIR: the munge socket's path must fit in sun_path (107 bytes).
  remove_stale_clusters("/tmp");
  std::string tmpl = "/tmp/mixpilot-slurm.XXXXXX";
  if (::mkdtemp(tmpl.data()) == nullptr) {
    reason = "cannot create a temporary folder in /tmp: " + std::string(std::strerror(errno));
    return nullptr;
  }
  c->folder_ = tmpl;
  const fs::path& dir = c->folder_;
  std::error_code ec;
  std::ofstream(dir / "owner") << ::getpid() << '\n';
  for (const char* sub : {"munge", "state", "spool", "run", "log"}) fs::create_directory(dir / sub, ec);
  fs::create_directory(dir / "spool" / kNode, ec);
  // munged wants its socket's folder open to every user, its key readable by its owner only.
  ::chmod(dir.c_str(), 0755);
  ::chmod((dir / "munge").c_str(), 0755);
  {
    std::random_device rd;
    std::string key;
    for (int i = 0; i < 128; ++i) key += static_cast<char>(rd() & 0xff);  // 1024 bits
    if (!write_text(dir / "munge" / "munge.key", key, 0600)) {
      reason = "cannot write the munge key in " + dir.string() + ": " + std::strerror(errno);
      return nullptr;
    }
  }
  if (!write_text(dir / "plugstack.conf", "", 0644)) {
    reason = "cannot write in " + dir.string() + ": " + std::strerror(errno);
    return nullptr;
  }

  // A port can be taken between choosing it and the daemon's bind: then again with others.
  for (int attempt = 0; attempt < 3; ++attempt) {
    bool port_taken = false;
    if (c->launch(reason, port_taken)) {
      status = Start::started;
      return c;
    }
    c->stop();  // the folder stays: the next launch rewrites its slurm.conf
    if (!port_taken) return nullptr;
  }
  return nullptr;
}

bool SlurmCluster::launch(std::string& reason, bool& port_taken) {
  port_taken = false;
  const fs::path& dir = folder_;
  const std::string d = dir.string();
  ctld_port_ = free_port();
  do slurmd_port_ = free_port();
  while (slurmd_port_ == ctld_port_);
  if (ctld_port_ == 0 || slurmd_port_ == 0) {
    reason = "no free TCP port on 127.0.0.1";
    return false;
  }

  const std::string socket = d + "/munge/munge.socket";
  std::ostringstream text;
  text << "# A single-node test cluster (tests/slurm_cluster.hpp): loopback only, no cgroups,\n"
          "# no slurmdbd; everything in this folder.\n"
       << "ClusterName=mixpilot-test\n"
       << "SlurmctldHost=" << kNode << "(127.0.0.1)\n"
       << "SlurmctldPort=" << ctld_port_ << "\n"
       << "SlurmdPort=" << slurmd_port_ << "\n"
       << "CommunicationParameters=NoCtldInAddrAny,NoInAddrAny\n"
       << "AuthType=auth/munge\nCredType=cred/munge\n"
       << "AuthInfo=socket=" << socket << "\n"
       << "SlurmUser=root\nSlurmdUser=root\n"
       << "StateSaveLocation=" << d << "/state\n"
       << "SlurmdSpoolDir=" << d << "/spool/%n\n"
       << "SlurmctldPidFile=" << d << "/run/slurmctld.pid\n"
       << "SlurmdPidFile=" << d << "/run/slurmd.pid\n"
       << "SlurmctldLogFile=" << d << "/log/slurmctld.log\n"
       << "SlurmdLogFile=" << d << "/log/slurmd.log\n"
       << "PlugStackConfig=" << d << "/plugstack.conf\n"
       << "MailProg=/bin/true\n"
       << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n"
       << "JobAcctGatherType=jobacct_gather/none\n"
       << "AccountingStorageType=accounting_storage/none\n"
       << "JobCompType=jobcomp/filetxt\nJobCompLoc=" << d << "/log/jobcomp.txt\n"
       << "SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\n"
       << "SchedulerType=sched/backfill\nMpiDefault=none\n"
       << "ReturnToService=2\nSlurmctldTimeout=30\nSlurmdTimeout=30\nInactiveLimit=0\n"
       << "MinJobAge=300\nKillWait=2\nWaittime=0\n"
       << "NodeName=" << kNode << " NodeAddr=127.0.0.1 " << node_line_ << " State=UNKNOWN\n"
       << "PartitionName=" << kPartition << " Nodes=" << kNode
       << " Default=YES MaxTime=INFINITE State=UP\n";
  if (!write_text(conf(), text.str(), 0644)) {
    reason = "cannot write " + conf().string() + ": " + std::strerror(errno);
    return false;
  }

  const std::vector<std::string> daemon_env = {"PATH=/usr/sbin:/usr/bin:/sbin:/bin", "LC_ALL=C",
                                        "HOME=" + d, "SLURM_CONF=" + conf().string()};
  const auto alive = [](pid_t pid) { return !ended(pid); };
  DaemonSettings daemon;
  daemon.own_process_group = true;

  if (munged_ <= 0) {
    munged_ = spawn_daemon({find_tool("munged"), "--foreground", "--force",
                            "--socket=" + socket, "--key-file=" + d + "/munge/munge.key",
                            "--pid-file=" + d + "/munge/munged.pid",
                            "--seed-file=" + d + "/munge/munged.seed",
                            "--log-file=" + d + "/log/munged.log", "--num-threads=2"},
                           daemon_env, dir / "log" / "munged.out", daemon);
    const auto until = Clock::now() + std::chrono::seconds(30);
    while (!fs::exists(socket)) {
      if (!alive(munged_)) {
        munged_ = -1;
        reason = "munged exited at start:" + tail_of(dir / "log" / "munged.out", 15);
        return false;
      }
      if (Clock::now() >= until) {
        reason = "munged made no socket within 30 s:" + tail_of(dir / "log" / "munged.out", 15);
        return false;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }

  slurmctld_ = spawn_daemon({find_tool("slurmctld"), "-D", "-i", "-f", conf().string()},
                            daemon_env, dir / "log" / "slurmctld.out", daemon);
  slurmd_ = spawn_daemon({find_tool("slurmd"), "-D", "-N", kNode, "-f", conf().string()},
                         daemon_env, dir / "log" / "slurmd.out", daemon);
  if (slurmctld_ < 0 || slurmd_ < 0) {
    reason = std::string("fork: ") + std::strerror(errno);
    return false;
  }

  // Ready when the node is idle: both daemons up and the node registered.
  const std::string sinfo = find_tool("sinfo");
  const auto until = Clock::now() + std::chrono::seconds(90);
  for (;;) {
    std::string state;
    if (run_capture({sinfo, "--noheader", "--Node", "--nodes", kNode, "--format=%t"},
                    environment_with(env()), state, 30) == 0 &&
        state.rfind("idle", 0) == 0)
      return true;
    for (pid_t* daemon : {&slurmctld_, &slurmd_}) {
      if (alive(*daemon)) continue;
      *daemon = -1;
      const std::string name = daemon == &slurmctld_ ? "slurmctld" : "slurmd";
      port_taken = read_all(dir / "log" / (name + ".out")).find("Address already in use") !=
                   std::string::npos;
      reason = name + " exited at start:" + logs();
      return false;
    }
    if (Clock::now() >= until) {
      reason = "the node is not idle after 90 s (sinfo: '" + state + "'):" + logs();
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

int SlurmCluster::run(const std::vector<std::string>& argv, std::string& output,
                      double seconds) const {
  std::vector<std::string> a = argv;
  if (!a.empty() && a[0].find('/') == std::string::npos) {
    const std::string tool = find_tool(a[0]);
    if (tool.empty()) {
      output = "no " + a[0] + " in PATH";
      return -1;
    }
    a[0] = tool;
  }
  return run_capture(a, environment_with(env()), output, seconds);
}

std::string SlurmCluster::logs(std::size_t lines) const {
  std::string out;
  for (const char* f : {"munged.out", "slurmctld.out", "slurmd.out"}) {
    const fs::path p = folder_ / "log" / f;
    if (fs::exists(p) && fs::file_size(p) > 0) out += std::string("\n ") + f + ":" + tail_of(p, lines);
  }
  return out;
}

std::vector<pid_t> SlurmCluster::job_processes() const {
  std::vector<pid_t> out;
  for (pid_t p : processes_with_env("SLURM_CONF=" + conf().string())) {
    // The daemons and their helpers (slurmctld's slurmscriptd); slurmstepd is started through
    // a double fork, so its parent is init.
    const pid_t parent = parent_of(p);
    const auto daemon = [this](pid_t q) { return q == munged_ || q == slurmctld_ || q == slurmd_; };
    if (!daemon(p) && !daemon(parent)) out.push_back(p);
  }
  return out;
}

void SlurmCluster::stop() {
  if (slurmctld_ > 0 && !ended(slurmctld_)) {
    // Every job of this cluster is ours: cancel them and let their processes end.
    const passwd* pw = ::getpwuid(::geteuid());
    std::string out;
    if (pw != nullptr) (void)run({"scancel", "--user", pw->pw_name}, out, 30);
    const auto until = Clock::now() + std::chrono::seconds(20);
    while (!job_processes().empty() && Clock::now() < until)
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  end_child(slurmd_, SIGTERM, std::chrono::seconds(10));
  end_child(slurmctld_, SIGTERM, std::chrono::seconds(10));
  // What the cancellation did not end (the daemons gone, slurmstepd and its job are orphans of
  // this cluster, not children of this process).
  if (!folder_.empty())
    for (pid_t p : job_processes()) ::kill(p, SIGKILL);
  end_child(munged_, SIGTERM, std::chrono::seconds(5));
}

SlurmCluster::~SlurmCluster() {
  stop();
  if (!folder_.empty()) {
    std::error_code ec;
    fs::remove_all(folder_, ec);
  }
}

}  // namespace mixpilot::test
