// Sweeps and scoring on a Slurm cluster (app/slurm.hpp, SPEC §11), against a real single-node
// cluster that each test starts itself (tests/slurm_cluster.hpp): the cluster runs an array,
// stays on loopback and leaves nothing behind; the array of shards is submitted, followed,
// not submitted twice, and a cancelled task's shard alone submitted again; Slurm's answers
// read as they are written.
#include <fcntl.h>
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

#include "app/slurm.hpp"
#include "slurm_cluster.hpp"
#include "spawned.hpp"
#include "sweep_table.hpp"
#include "temp_files.hpp"

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

// ---- Slurm's answers and the job script -------------------------------------------------

namespace sl = mixpilot::cli::slurm;

std::vector<int> indices(const std::string& text) {
  std::vector<int> out;
  EXPECT_TRUE(sl::parse_indices(text, out)) << text;
  return out;
}

TEST(SlurmParse, ArrayIndices) {
  EXPECT_EQ(indices("3"), (std::vector<int>{3}));
  EXPECT_EQ(indices("1-3,5"), (std::vector<int>{1, 2, 3, 5}));
  EXPECT_EQ(indices("[4-6%2]"), (std::vector<int>{4, 5, 6}));
  EXPECT_EQ(indices("1-9:4,2"), (std::vector<int>{1, 2, 5, 9}));
  std::vector<int> out;
  for (const char* bad : {"", "N/A", "3-1", "1-", "a", "1,,2", "1%", "-2"})
    EXPECT_FALSE(sl::parse_indices(bad, out)) << bad;
  EXPECT_EQ(sl::array_spec({1, 2, 3, 5, 7, 8}), "1-3,5,7-8");
  EXPECT_EQ(sl::array_spec({2}), "2");
  EXPECT_EQ(indices(sl::array_spec({1, 2, 4, 9, 10, 11})), (std::vector<int>{1, 2, 4, 9, 10, 11}));
}

TEST(SlurmParse, SqueueRows) {
  std::vector<sl::TaskRecord> rows;
  std::string error;
  // What 22.05 prints for `--array --states=all --format=%F|%K|%T|%r|%j`, a job that is no
  // array among them, and a name holding the separator.
  ASSERT_TRUE(sl::parse_squeue("12|3|PENDING|Resources|mixpilot-sweep-out\n"
                               "12|[5-6]|PENDING|JobArrayTaskLimit|mixpilot-sweep-out\n"
                               "12|1|RUNNING|None|mixpilot-sweep-out\n"
                               "12|2|CANCELLED|None|mixpilot-sweep-out\n"
                               "40|N/A|RUNNING|None|someone-else\n"
                               "41|1|COMPLETED|None|a|b\n",
                               rows, error))
      << error;
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[0].job, "12");
  EXPECT_EQ(rows[0].tasks, (std::vector<int>{3}));
  EXPECT_EQ(rows[0].detail, "Resources");
  EXPECT_EQ(rows[1].tasks, (std::vector<int>{5, 6}));
  EXPECT_EQ(rows[3].state, "CANCELLED");
  EXPECT_EQ(rows[4].name, "a|b");
  EXPECT_FALSE(sl::parse_squeue("slurm_load_jobs error: Socket timed out\n", rows, error));
  EXPECT_NE(error.find("Socket timed out"), std::string::npos) << error;
}

TEST(SlurmParse, SacctRows) {
  // `sacct --noheader --parsable2 --allocations --format=JobID,State,ExitCode` with slurmdbd.
  const auto rows = sl::parse_sacct(
      "12_1|COMPLETED|0:0\n12_2|CANCELLED by 0|0:15\n12_[3-4%2]|PENDING|0:0\n"
      "12_1.batch|COMPLETED|0:0\n99|COMPLETED|0:0\n");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1].state, "CANCELLED");
  EXPECT_EQ(rows[1].detail, "0:15");
  EXPECT_EQ(rows[2].tasks, (std::vector<int>{3, 4}));
  EXPECT_EQ(sl::classify("CANCELLED by 1000"), sl::TaskState::failed);
  EXPECT_EQ(sl::classify("COMPLETED"), sl::TaskState::done);
  for (const char* w : {"FAILED", "TIMEOUT", "NODE_FAIL", "OUT_OF_MEMORY", "PREEMPTED"})
    EXPECT_EQ(sl::classify(w), sl::TaskState::failed) << w;
  for (const char* w : {"PENDING", "REQUEUED", "REQUEUE_HOLD"})
    EXPECT_EQ(sl::classify(w), sl::TaskState::pending) << w;
  for (const char* w : {"RUNNING", "COMPLETING", "CONFIGURING", "SUSPENDED", "SOMETHING_NEW"})
    EXPECT_EQ(sl::classify(w), sl::TaskState::running) << w;
}

// The script asks for what was given, its paths survive spaces, quotes and '%', and its task
// runs the command with the shard of its array index.
TEST(SlurmParse, JobScriptRunsTheShardOfItsIndex) {
  const fs::path dir = fs::temp_directory_path() / ("mixpilot_slurm_script." + std::to_string(::getpid())) / "out 50% 'a'";
  fs::create_directories(dir);
  const fs::path echo = dir.parent_path() / "args.sh";
  std::ofstream(echo) << "#!/bin/sh\nfor a in \"$@\"; do printf '<%s>' \"$a\"; done\n";
  fs::permissions(echo, fs::perms::owner_all);
  sl::ArrayRequest r;
  r.kind = "sweep";
  r.dir = dir;
  r.task = {echo.string(), "sweep", "/data/my sweep's.toml", "--out", dir.string()};
  r.tasks = 4;
  r.cpus_per_task = 2;
  r.partition = "short";
  EXPECT_EQ(sl::job_name(r), "mixpilot-sweep-out_50___a_");
  EXPECT_EQ(sl::unscriptable_path(dir), "");
  EXPECT_NE(sl::unscriptable_path("/a/b\"c"), "");
  const std::string script = sl::job_script(r, {1, 2, 4}, sl::job_name(r));
  for (const std::string& line : std::vector<std::string>{
           "#SBATCH --array=1-2,4\n", "#SBATCH --cpus-per-task=2\n", "#SBATCH --partition=short\n",
        "#SBATCH --job-name=mixpilot-sweep-out_50___a_\n",
        "#SBATCH --output=\"" + dir.parent_path().string() + "/out 50%% 'a'/slurm/%A_%a.out\"\n",
        "#SBATCH --chdir=\"" + dir.string() + "\"\n"})
    EXPECT_NE(script.find(line), std::string::npos) << line << "\nin\n" << script;
  const fs::path file = dir / "job.sh";
  std::ofstream(file) << script;
  ::setenv("JOB_SCRIPT", file.c_str(), 1);
  ::setenv("JOB_SAID", (dir / "said").c_str(), 1);
  ASSERT_EQ(std::system("env -u SLURM_CPUS_PER_TASK SLURM_ARRAY_TASK_ID=4 sh \"$JOB_SCRIPT\" > "
                        "\"$JOB_SAID\""),
            0);
  EXPECT_EQ(slurp_text(dir / "said"), "<sweep></data/my sweep's.toml><--out><" + dir.string() +
                                          "><--shard><4/4><--jobs><2>");
  fs::remove_all(dir.parent_path());
}

// Without sbatch, --slurm says so before anything is written.
TEST(SlurmArray, SaysWhenSbatchIsMissing) {
  const fs::path dir = fs::temp_directory_path() / ("mixpilot_slurm_nosbatch." + std::to_string(::getpid()));
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", "/nonexistent", 1);
  sl::ArrayRequest r;
  r.kind = "sweep";
  r.dir = dir;
  r.task = {"/bin/true"};
  r.missing = [] { return std::vector<std::size_t>{0}; };
  const auto outcome = sl::run_array(r);
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(outcome.end, sl::ArrayEnd::error);
  EXPECT_NE(outcome.message.find("sbatch is not in PATH"), std::string::npos) << outcome.message;
  EXPECT_FALSE(fs::exists(dir));
}

// ---- Arrays of shards on the cluster --------------------------------------------------------

// Stderr into a file while the object lives.
class CapturedStderr {
 public:
  explicit CapturedStderr(const fs::path& file) : file_(file) {
    std::fflush(stderr);
    saved_ = ::dup(STDERR_FILENO);
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
    ::dup2(fd, STDERR_FILENO);
    ::close(fd);
  }
  ~CapturedStderr() {
    std::fflush(stderr);
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
  }
  std::string text() const {
    std::fflush(stderr);
    return slurp_text(file_);
  }

 private:
  fs::path file_;
  int saved_ = -1;
};

// A stand-in for `mixpilot sweep --shard i/n`: writes DIR/runs/<k>.json for each missing k of
// its shard, noting each k in DIR/flown-<i>; after its first run it waits while DIR/hold-<i>
// exists.
constexpr const char* kWorker = R"(#!/bin/sh
dir=$1; total=$2; i=${4%/*}; n=${4#*/}
mkdir -p "$dir/runs"
k=0; flown=0
while [ $k -lt $total ]; do
  if [ $((k % n)) -eq $((i - 1)) ] && [ ! -e "$dir/runs/$k.json" ]; then
    while [ $flown -gt 0 ] && [ -e "$dir/hold-$i" ]; do sleep 0.2; done
    echo "{\"k\": $k}" > "$dir/runs/$k.json.tmp" && mv "$dir/runs/$k.json.tmp" "$dir/runs/$k.json"
    echo $k >> "$dir/flown-$i"
    flown=$((flown + 1))
  fi
  k=$((k + 1))
done
)";

class SlurmShards : public Slurm {
 protected:
  void SetUp() override {
    Slurm::SetUp();
    if (IsSkipped() || HasFatalFailure()) return;
    ::setenv("SLURM_CONF", cluster_->conf().c_str(), 1);
    dir_ = cluster_->folder() / "work dir";
    fs::create_directories(dir_);
    const fs::path worker = cluster_->folder() / "worker.sh";
    std::ofstream(worker) << kWorker;
    fs::permissions(worker, fs::perms::owner_all);
    request_.kind = "sweep";
    request_.dir = dir_;
    request_.task = {worker.string(), dir_.string(), std::to_string(kTotal)};
    request_.tasks = 4;
    request_.poll_seconds = 0.5;
    request_.total = kTotal;
    const fs::path runs = dir_ / "runs";
    request_.missing = [runs] {
      std::vector<std::size_t> out;
      for (std::size_t k = 0; k < kTotal; ++k)
        if (!fs::exists(runs / (std::to_string(k) + ".json"))) out.push_back(k);
      return out;
    };
  }
  void TearDown() override { ::unsetenv("SLURM_CONF"); }

  std::vector<std::string> records() {
    std::vector<std::string> out;
    std::ifstream in(dir_ / "slurm" / "jobs");
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] != '#') out.push_back(line);
    return out;
  }

  static constexpr std::size_t kTotal = 14;
  fs::path dir_;
  sl::ArrayRequest request_;
};

// The shards run as one array of four tasks, followed to the end; every run is there.
TEST_F(SlurmShards, RunAsAnArrayFollowedToTheEnd) {
  CapturedStderr err(cluster_->folder() / "stderr.txt");
  const auto outcome = sl::run_array(request_);
  const std::string said = err.text();
  ASSERT_EQ(outcome.end, sl::ArrayEnd::complete) << outcome.message << said << cluster_->logs();
  EXPECT_TRUE(request_.missing().empty());
  EXPECT_EQ(records(), std::vector<std::string>{outcome.job + " 4 1-4 mixpilot-sweep-work_dir"});
  EXPECT_NE(said.find("slurm: submitted array job " + outcome.job + ": 4 tasks (of 4)"),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("0 pending, 0 running, 4 done, 0 failed; 14 of 14 runs"), std::string::npos)
      << said;
  // Nothing missing: the same request submits nothing.
  EXPECT_EQ(sl::run_array(request_).end, sl::ArrayEnd::complete);
  EXPECT_EQ(records().size(), 1u);
}

// An array still in the queue is followed by the next command for its folder, not submitted
// twice.
TEST_F(SlurmShards, AQueuedArrayIsFollowedNotSubmittedAgain) {
  for (int i = 1; i <= 4; ++i) std::ofstream(dir_ / ("hold-" + std::to_string(i)));
  CapturedStderr err(cluster_->folder() / "stderr.txt");
  request_.wait = false;
  const auto first = sl::run_array(request_);
  ASSERT_EQ(first.end, sl::ArrayEnd::submitted) << first.message << err.text();
  request_.wait = true;
  sl::ArrayOutcome second;
  std::thread follow([&] { second = sl::run_array(request_); });
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (err.text().find("not submitting again; following it") == std::string::npos &&
         std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  for (int i = 1; i <= 4; ++i) fs::remove(dir_ / ("hold-" + std::to_string(i)));
  follow.join();
  const std::string said = err.text();
  EXPECT_NE(said.find("slurm: array job " + first.job + " of " + dir_.string() +
                      " is still in the queue"),
            std::string::npos)
      << said;
  EXPECT_EQ(second.end, sl::ArrayEnd::complete) << said;
  EXPECT_EQ(second.job, first.job);
  EXPECT_EQ(records().size(), 1u);
  EXPECT_TRUE(request_.missing().empty());
}

// Tasks cancelled with scancel, one running (one of its runs written) and one pending, end the
// array incomplete, each named with its log; the same request again submits those two shards
// alone, which write only the runs still missing, and then every run is there.
TEST_F(SlurmShards, CancelledTasksAreSubmittedAgainAlone) {
  for (int i = 1; i <= 3; ++i) std::ofstream(dir_ / ("hold-" + std::to_string(i)));
  CapturedStderr err(cluster_->folder() / "stderr.txt");
  request_.wait = false;
  const auto first = sl::run_array(request_);
  ASSERT_EQ(first.end, sl::ArrayEnd::submitted) << first.message << err.text();
  // Two CPUs: tasks 1 and 2 run (held after their first run), 3 and 4 wait for them.
  const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  auto states = tasks(first.job);
  while ((states["2"] != "RUNNING" || states["3"] != "PENDING" ||
          !fs::exists(dir_ / "flown-2")) &&
         std::chrono::steady_clock::now() < until) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    states = tasks(first.job);
  }
  ASSERT_EQ(states["2"], "RUNNING");
  ASSERT_EQ(states["3"], "PENDING");
  ASSERT_EQ(slurp_text(dir_ / "flown-2"), "1\n");
  std::string out;
  ASSERT_EQ(cluster_->run({"scancel", first.job + "_2", first.job + "_3"}, out), 0) << out;
  fs::remove(dir_ / "hold-1");
  request_.wait = true;
  const auto ended = sl::run_array(request_);
  std::string said = err.text();
  EXPECT_EQ(ended.end, sl::ArrayEnd::incomplete) << ended.message << said;
  const std::string job = " of job " + first.job + ": ";
  EXPECT_NE(said.find("slurm: task 2 (shard 2 of 4)" + job + "CANCELLED; its log: " +
                      (dir_ / "slurm" / (first.job + "_2.err")).string()),
            std::string::npos)
      << said;
  EXPECT_NE(said.find("slurm: task 3 (shard 3 of 4)" + job), std::string::npos) << said;
  EXPECT_NE(said.find("6 of 14 runs missing (shards 2-3)"), std::string::npos) << said;
  EXPECT_EQ(request_.missing(), (std::vector<std::size_t>{2, 5, 6, 9, 10, 13}));

  for (int i = 2; i <= 3; ++i) fs::remove(dir_ / ("hold-" + std::to_string(i)));
  const auto again = sl::run_array(request_);
  said = err.text();
  ASSERT_EQ(again.end, sl::ArrayEnd::complete) << again.message << said;
  EXPECT_NE(again.job, first.job);
  EXPECT_EQ(records(), (std::vector<std::string>{first.job + " 4 1-4 mixpilot-sweep-work_dir",
                                                 again.job + " 4 2-3 mixpilot-sweep-work_dir"}));
  EXPECT_NE(said.find("slurm: submitted array job " + again.job + ": 2 tasks (of 4)"),
            std::string::npos)
      << said;
  EXPECT_TRUE(request_.missing().empty());
  // Each run written once: shard 2's first before its task was cancelled, the rest after.
  EXPECT_EQ(slurp_text(dir_ / "flown-1"), "0\n4\n8\n12\n");
  EXPECT_EQ(slurp_text(dir_ / "flown-2"), "1\n5\n9\n13\n");
  EXPECT_EQ(slurp_text(dir_ / "flown-3"), "2\n6\n10\n");
  EXPECT_EQ(slurp_text(dir_ / "flown-4"), "3\n7\n11\n");
}

// sbatch's refusal comes back with its own words and the script's path.
TEST_F(SlurmShards, ARefusalSaysWhy) {
  request_.partition = "nosuchpartition";
  CapturedStderr err(cluster_->folder() / "stderr.txt");
  const auto outcome = sl::run_array(request_);
  EXPECT_EQ(outcome.end, sl::ArrayEnd::error);
  EXPECT_NE(outcome.message.find("sbatch refused the array (its script: " +
                                 (dir_ / "slurm" / "sweep-1.sh").string() + ")"),
            std::string::npos)
      << outcome.message;
  EXPECT_NE(outcome.message.find("invalid partition"), std::string::npos) << outcome.message;
  EXPECT_TRUE(records().empty());
}

// ---- mixpilot sweep and score with --slurm --------------------------------------------------

// 40 runs of 1.5 s of the tracking smooth step: ten round trips, with and without the delay
// predictor, two horizons.
const std::string kSweep40 = "scenario = \"" + std::string(MIXPILOT_SOURCE_DIR) +
                             "/scenarios/tracking_smooth_step.toml\"\n"
                             "duration = 1.5\n"
                             "[grid]\n"
                             "\"plant.rtt\" = [0.0, 0.006, 0.009, 0.012, 0.015, 0.018, 0.021, "
                             "0.024, 0.03, 0.06]\n"
                             "\"controller.compensation\" = [true, false]\n"
                             "\"controller.N\" = [10, 20]\n";

// mixpilot run as a user would, on the cluster of the test (SLURM_CONF) with user folders of its
// own; its exit status, its output in home/<out>.
class SlurmCommand : public Slurm {
 protected:
  void SetUp() override {
    Slurm::SetUp();
    if (IsSkipped() || HasFatalFailure()) return;
    home_ = fresh_path("slurm", ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(home_);
  }
  int mixpilot(const std::vector<std::string>& args, const std::string& out, bool on_slurm = true) {
    std::vector<std::string> argv = {MIXPILOT_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<std::pair<std::string, std::string>> env = {
        {"XDG_CONFIG_HOME", (home_ / "config").string()}, {"XDG_DATA_HOME", (home_ / "data").string()}};
    if (on_slurm) env.emplace_back("SLURM_CONF", cluster_->conf().string());
    const int rc = run_to_end(argv, home_ / out, 900, env);
    said_ = slurp_text(home_ / out);
    return rc;
  }
  // The array jobs DIR/slurm/jobs remembers.
  std::vector<std::string> records(const fs::path& dir) {
    std::vector<std::string> out;
    std::ifstream in(dir / "slurm" / "jobs");
    for (std::string line; std::getline(in, line);)
      if (!line.empty() && line[0] != '#') out.push_back(line);
    return out;
  }
  // The last-write times of the run files.
  std::map<std::string, fs::file_time_type> run_times(const fs::path& dir) {
    std::map<std::string, fs::file_time_type> out;
    for (const auto& e : fs::directory_iterator(dir / "runs"))
      if (e.path().extension() == ".json") out[e.path().filename().string()] = e.last_write_time();
    return out;
  }

  fs::path home_;
  std::string said_;
};

class SlurmSweep : public SlurmCommand {
 protected:
  void SetUp() override {
    SlurmCommand::SetUp();
    if (IsSkipped() || HasFatalFailure()) return;
    file_ = home_ / "forty.toml";
    std::ofstream(file_) << kSweep40;
    // The reference: the same sweep flown here, on two cores.
    ASSERT_EQ(mixpilot({"sweep", file_.string(), "--out", (home_ / "local").string(), "--jobs", "2"},
                       "local.txt", false),
              0)
        << said_;
    local_ = non_timing(read_csv_table(home_ / "local" / "table.csv"));
    ASSERT_EQ(local_.size(), 41u);
  }
  fs::path file_;
  Table local_;
};

// The 40-run sweep as an array of four tasks, each flying its shard of ten runs into the
// folder, followed and merged: the table the local run gives (timing fields aside).
TEST_F(SlurmSweep, FortyRunsAsFourTasksGiveTheLocalTable) {
  const fs::path dir = home_ / "on slurm";
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(mixpilot({"sweep", file_.string(), "--out", dir.string(), "--slurm", "--tasks", "4",
                      "--poll", "1"},
                     "slurm.txt"),
            0)
      << said_ << cluster_->logs();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("the sweep on Slurm took %.1f s\n", seconds);
  EXPECT_EQ(non_timing(read_csv_table(dir / "table.csv")), local_);
  const auto jobs = records(dir);
  ASSERT_EQ(jobs.size(), 1u);
  const std::string job = jobs[0].substr(0, jobs[0].find(' '));
  EXPECT_EQ(jobs[0], job + " 4 1-4 mixpilot-sweep-on_slurm");
  EXPECT_NE(said_.find("slurm: submitted array job " + job + ": 4 tasks (of 4) of " + dir.string()),
            std::string::npos)
      << said_;
  EXPECT_NE(said_.find("0 pending, 0 running, 4 done, 0 failed; 40 of 40 runs"), std::string::npos)
      << said_;
  // Each task flew its own shard, ten runs, with its output in the folder.
  for (int i = 1; i <= 4; ++i) {
    const std::string log = slurp_text(dir / "slurm" / (job + "_" + std::to_string(i) + ".out"));
    EXPECT_NE(log.find("shard " + std::to_string(i) + "/4: 10 of 40 runs in " + dir.string() +
                       ", 0 finished, 10 to fly"),
              std::string::npos)
        << log;
  }
  // Done: the same command submits nothing and merges again.
  ASSERT_EQ(mixpilot({"sweep", file_.string(), "--out", dir.string(), "--slurm", "--tasks", "4"},
                     "again.txt"),
            0)
      << said_;
  EXPECT_EQ(said_.find("submitted"), std::string::npos) << said_;
  EXPECT_NE(said_.find("slurm: all 40 runs of " + dir.string() + " are there: nothing to submit"),
            std::string::npos)
      << said_;
  EXPECT_EQ(records(dir).size(), 1u);
}

// A task cancelled with scancel while it waits leaves its shard's runs missing: the command says
// so and exits 1; the same command again submits that shard alone, which flies the missing
// runs only (the others' files untouched), and the table is the local run's.
TEST_F(SlurmSweep, ACancelledTaskIsFlownAgainByTheSameCommand) {
  const fs::path dir = home_ / "cancelled";
  // Two CPUs a task, on a node of two: one task at a time, the others pending.
  const std::vector<std::string> cmd = {"sweep",   file_.string(), "--out",           dir.string(),
                                        "--slurm", "--tasks",      "4",               "--poll",
                                        "1",       "--cpus-per-task", "2"};
  std::vector<std::string> submit = cmd;
  submit.push_back("--no-wait");
  ASSERT_EQ(mixpilot(submit, "submit.txt"), 0) << said_;
  auto jobs = records(dir);
  ASSERT_EQ(jobs.size(), 1u) << said_;
  const std::string job = jobs[0].substr(0, jobs[0].find(' '));
  EXPECT_NE(said_.find("run the same command again to follow array job " + job), std::string::npos)
      << said_;
  const auto states = tasks(job);
  ASSERT_EQ(states.at("4"), "PENDING") << "task 4 ran before it could be cancelled";
  std::string out;
  ASSERT_EQ(cluster_->run({"scancel", job + "_4"}, out), 0) << out;

  ASSERT_EQ(mixpilot(cmd, "follow.txt"), 1) << said_;
  EXPECT_NE(said_.find("slurm: task 4 (shard 4 of 4) of job " + job + ": "), std::string::npos)
      << said_;
  EXPECT_NE(said_.find("its log: " + (dir / "slurm" / (job + "_4.err")).string()), std::string::npos)
      << said_;
  EXPECT_NE(said_.find("10 of 40 runs missing (shards 4); run the same command again"),
            std::string::npos)
      << said_;
  EXPECT_FALSE(fs::exists(dir / "table.csv"));
  const auto before = run_times(dir);
  ASSERT_EQ(before.size(), 30u);

  ASSERT_EQ(mixpilot(cmd, "again.txt"), 0) << said_ << cluster_->logs();
  jobs = records(dir);
  ASSERT_EQ(jobs.size(), 2u);
  const std::string again = jobs[1].substr(0, jobs[1].find(' '));
  EXPECT_EQ(jobs[1], again + " 4 4 mixpilot-sweep-cancelled");
  const std::string log = slurp_text(dir / "slurm" / (again + "_4.out"));
  EXPECT_NE(log.find("shard 4/4: 10 of 40 runs in " + dir.string() + ", 0 finished, 10 to fly"),
            std::string::npos)
      << log;
  const auto after = run_times(dir);
  EXPECT_EQ(after.size(), 40u);
  for (const auto& [name, time] : before) EXPECT_EQ(after.at(name), time) << name << " flown again";
  EXPECT_EQ(non_timing(read_csv_table(dir / "table.csv")), local_);
}

class SlurmScore : public SlurmCommand {};

// A folder of recordings scored as an array of two tasks: the table of scoring it here.
TEST_F(SlurmScore, AFolderOfRecordingsAsAnArrayGivesTheLocalTable) {
  const fs::path file = home_ / "flights.toml";
  std::ofstream(file) << "scenario = \"" MIXPILOT_SOURCE_DIR "/scenarios/mi_helix.toml\"\n"
                         "duration = 2\nrecord = true\n"
                         "pilots = [\"novice\", \"experienced\"]\n"
                         "[grid]\n\"controller.ph.r\" = [0.15, 0.175]\n";
  ASSERT_EQ(mixpilot({"sweep", file.string(), "--out", (home_ / "flown").string(), "--jobs", "2"},
                     "flown.txt", false),
            0)
      << said_;
  const fs::path recordings = home_ / "flown" / "recordings";
  ASSERT_EQ(mixpilot({"score", recordings.string(), "--out", (home_ / "local").string(), "--jobs",
                      "2"},
                     "local.txt", false),
            0)
      << said_;
  const fs::path dir = home_ / "scores";
  ASSERT_EQ(mixpilot({"score", recordings.string(), "--out", dir.string(), "--slurm", "--tasks",
                      "2", "--poll", "1"},
                     "slurm.txt"),
            0)
      << said_ << cluster_->logs();
  EXPECT_NE(said_.find("0 pending, 0 running, 2 done, 0 failed; 4 of 4 recordings"),
            std::string::npos)
      << said_;
  const auto jobs = records(dir);
  ASSERT_EQ(jobs.size(), 1u);
  EXPECT_EQ(jobs[0].substr(jobs[0].find(' ')), " 2 1-2 mixpilot-score-scores");
  const Table table = non_timing(read_csv_table(dir / "table.csv"));
  EXPECT_EQ(table.size(), 5u);
  EXPECT_EQ(table, non_timing(read_csv_table(home_ / "local" / "table.csv")));
}

// What --slurm takes and refuses, said before anything is submitted; without sbatch, the
// command says so.
TEST(SlurmCli, TheCommandLineSaysWhatItExpects) {
  const fs::path home = fresh_path("slurm", "cli");
  fs::create_directories(home);
  const fs::path file = home / "forty.toml";
  std::ofstream(file) << kSweep40;
  const auto run = [&](const std::vector<std::string>& args,
                       const std::vector<std::pair<std::string, std::string>>& env = {}) {
    std::vector<std::string> argv = {MIXPILOT_BINARY};
    argv.insert(argv.end(), args.begin(), args.end());
    auto e = env;
    e.emplace_back("XDG_DATA_HOME", (home / "data").string());
    e.emplace_back("XDG_CONFIG_HOME", (home / "config").string());
    const int rc = run_to_end(argv, home / "out.txt", 300, e);
    return std::make_pair(rc, slurp_text(home / "out.txt"));
  };
  const std::string f = file.string();
  const std::vector<std::pair<std::vector<std::string>, std::string>> usage = {
      {{"sweep", f, "--partition", "short"}, "--partition goes with --slurm"},
      {{"sweep", f, "--no-wait"}, "--no-wait goes with --slurm"},
      {{"sweep", f, "--slurm", "--shard", "1/2"}, "--slurm gives each array task its --shard"},
      {{"sweep", f, "--slurm", "--merge"}, "--slurm merges when its array ends"},
      {{"sweep", f, "--slurm", "--force"}, "give another --out"},
      {{"sweep", f, "--slurm", "--jobs", "2"}, "each task's parallel runs are --cpus-per-task"},
      {{"sweep", f, "--slurm", "--tasks", "0"}, "--tasks expects a whole number from 1"},
      {{"sweep", f, "--slurm", "--cpus-per-task", "x"}, "--cpus-per-task expects a whole number"},
      {{"sweep", f, "--slurm", "--poll", "-1"}, "--poll expects seconds"},
      {{"sweep", f, "--slurm", "--partition", "a b"}, "--partition expects a partition's name"},
      {{"sweep", f, "--check", "--slurm"}, "--check only reads the sweep file"},
      {{"score", f, "--slurm"}, "--slurm goes with a folder of recordings"},
  };
  for (const auto& [args, message] : usage) {
    const auto [rc, said] = run(args);
    EXPECT_EQ(rc, 2) << said;
    EXPECT_NE(said.find(message), std::string::npos) << said;
  }
  const auto [help_rc, help] = run({"sweep", "--help"});
  EXPECT_EQ(help_rc, 0);
  for (const char* option : {"--slurm", "--partition P", "--tasks N", "--cpus-per-task C",
                             "--poll S", "--no-wait", "docs/slurm.md"})
    EXPECT_NE(help.find(option), std::string::npos) << option;
  EXPECT_NE(run({"score", "--help"}).second.find("--cpus-per-task C"), std::string::npos);
  // No Slurm here: the runs are checked, the folder claimed, and nothing submitted.
  const auto [rc, said] = run({"sweep", f, "--out", (home / "out").string(), "--slurm"},
                              {{"PATH", "/nonexistent"}});
  EXPECT_EQ(rc, 1) << said;
  EXPECT_NE(said.find("mixpilot sweep: sbatch is not in PATH"), std::string::npos) << said;
  EXPECT_FALSE(fs::exists(home / "out" / "slurm" / "jobs"));
}

}  // namespace
}  // namespace mixpilot::test
