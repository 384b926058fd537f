// Sweeps and scoring on a Slurm cluster, against a real single-node cluster that each test starts
// itself (tests/slurm_cluster.hpp): the cluster runs an array and stays on loopback, and leaves
// nothing behind.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "slurm_cluster.hpp"

namespace mixpilot::test {
namespace {

namespace fs = std::filesystem;

std::string slurp_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class Slurm : public ::testing::Test {
 protected:
  void SetUp() override { MIXPILOT_START_SLURM(cluster_); }

  // Submits `script` (its text) with sbatch; the job id.
  std::string submit(const std::string& name, const std::string& script) {
    const fs::path file = cluster_->folder() / (name + ".sh");
    std::ofstream(file) << script;
    std::string out;
    const int rc = cluster_->run({"sbatch", "--parsable", file.string()}, out);
    EXPECT_EQ(rc, 0) << out;
    return out.substr(0, out.find_first_of(";\n"));
  }

  // The state of each task of array `job` that the controller knows ("1" -> "COMPLETED").
  std::map<std::string, std::string> tasks(const std::string& job) {
    std::string out;
    const int rc = cluster_->run({"squeue", "--noheader", "--array", "--states=all", "--jobs",
                                  job, "--format=%K %T"},
                                 out);
    EXPECT_EQ(rc, 0) << out;
    std::map<std::string, std::string> states;
    std::istringstream in(out);
    for (std::string task, state; in >> task >> state;) states[task] = state;
    return states;
  }

  // Waits (up to `seconds`) until no task of `job` is pending or running; its tasks' states.
  std::map<std::string, std::string> wait_for(const std::string& job, double seconds) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    for (;;) {
      const auto states = tasks(job);
      const bool active = std::any_of(states.begin(), states.end(), [](const auto& kv) {
        return kv.second == "PENDING" || kv.second == "RUNNING" || kv.second == "CONFIGURING" ||
               kv.second == "COMPLETING";
      });
      if (!active || std::chrono::steady_clock::now() > until) return states;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  std::unique_ptr<SlurmCluster> cluster_;
};

// An array of three tasks runs, each once with its own index, and the controller and the
// completion log (what `sacct -c` reads without slurmdbd) say each completed.
TEST_F(Slurm, ClusterRunsAnArray) {
  const fs::path out = cluster_->folder() / "out";
  fs::create_directory(out);
  const std::string job = submit("array", "#!/bin/sh\n#SBATCH --array=1-3\n#SBATCH --output=" +
                                              out.string() + "/%A_%a.log\n" +
                                              "echo \"$SLURM_ARRAY_TASK_ID of "
                                              "$SLURM_ARRAY_TASK_COUNT\" > " +
                                              out.string() + "/task-$SLURM_ARRAY_TASK_ID.txt\n");
  ASSERT_FALSE(job.empty());
  const auto states = wait_for(job, 120);
  const std::map<std::string, std::string> completed = {
      {"1", "COMPLETED"}, {"2", "COMPLETED"}, {"3", "COMPLETED"}};
  EXPECT_EQ(states, completed) << cluster_->logs();
  for (int i = 1; i <= 3; ++i)
    EXPECT_EQ(slurp_text(out / ("task-" + std::to_string(i) + ".txt")),
              std::to_string(i) + " of 3\n");
  std::string sacct;
  ASSERT_EQ(cluster_->run({"sacct", "--completion", "--allusers", "--parsable2", "--noheader",
                           "--format=JobName,State"},
                          sacct),
            0)
      << sacct;
  int done = 0;
  std::istringstream in(sacct);
  for (std::string line; std::getline(in, line);) done += line == "array.sh|COMPLETED";
  EXPECT_EQ(done, 3) << sacct;
}

// Listening sockets (TCP, IPv4 and IPv6) of a process: "address:port" as /proc/net shows them.
std::vector<std::string> listening(pid_t pid) {
  std::set<std::string> inodes;
  std::error_code ec;
  for (const auto& fd : fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd", ec)) {
    const std::string target = fs::read_symlink(fd.path(), ec).string();
    if (target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
  }
  std::vector<std::string> out;
  for (const char* table : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::ifstream in(table);
    std::string line;
    std::getline(in, line);  // the header
    while (std::getline(in, line)) {
      std::istringstream f(line);
      std::string slot, local, remote, state, queues, timer, retr, uid, timeout, inode;
      f >> slot >> local >> remote >> state >> queues >> timer >> retr >> uid >> timeout >> inode;
      if (state == "0A" && inodes.count(inode)) out.push_back(local);
    }
  }
  return out;
}

// The controller and slurmd each listen on their own port and on 127.0.0.1 only (/proc/net's
// 0100007F), munged on nothing but its Unix socket.
TEST_F(Slurm, ClusterListensOnLoopbackOnly) {
  const auto d = cluster_->daemons();
  const auto hex_port = [](int port) {
    char buf[8];
    std::snprintf(buf, sizeof buf, "%04X", port);
    return std::string(buf);
  };
  EXPECT_EQ(listening(d[0]), std::vector<std::string>{});
  EXPECT_EQ(listening(d[1]),
            std::vector<std::string>{"0100007F:" + hex_port(cluster_->controller_port())});
  EXPECT_EQ(listening(d[2]),
            std::vector<std::string>{"0100007F:" + hex_port(cluster_->slurmd_port())});
}

// A second cluster starts beside the first; stopped with a job running, it leaves no daemon, no
// job process and no folder.
TEST_F(Slurm, ClusterStopsAndLeavesNothing) {
  SlurmCluster::Start status{};
  std::string reason;
  auto second = SlurmCluster::start(status, reason);
  ASSERT_EQ(status, SlurmCluster::Start::started) << reason;
  EXPECT_NE(second->controller_port(), cluster_->controller_port());
  const fs::path folder = second->folder();
  const fs::path script = folder / "sleep.sh";
  std::ofstream(script) << "#!/bin/sh\n#SBATCH --output=/dev/null\nsleep 600\n";
  std::string out;
  ASSERT_EQ(second->run({"sbatch", "--parsable", script.string()}, out), 0) << out;
  // Its job runs: slurmstepd, the script and sleep.
  std::vector<pid_t> jobs;
  for (int i = 0; i < 600 && jobs.size() < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    jobs = second->job_processes();
  }
  ASSERT_GE(jobs.size(), 3u) << second->logs();
  std::vector<pid_t> all = second->daemons();
  all.insert(all.end(), jobs.begin(), jobs.end());
  second.reset();
  EXPECT_FALSE(fs::exists(folder));
  for (pid_t p : all) {
    // Gone, or a zombie that init has not reaped yet.
    std::ifstream stat("/proc/" + std::to_string(p) + "/stat");
    std::string pid, comm, state;
    stat >> pid >> comm >> state;
    EXPECT_TRUE(!stat || state == "Z") << "process " << p << " still runs (" << comm << ")";
  }
  // The first cluster is untouched.
  ASSERT_EQ(cluster_->run({"sinfo", "--noheader", "--format=%t"}, out), 0) << out;
  EXPECT_EQ(out, "idle\n");
}

}  // namespace
}  // namespace mixpilot::test
