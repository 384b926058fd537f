#pragma once
// A real single-node Slurm cluster for a test: Debian's slurm-wlm and munge daemons (munged,
// slurmctld, slurmd) started as this process's children, configured in a fresh temporary folder
// (/tmp/mixpilot-slurm.XXXXXX: slurm.conf, the munge key and socket, state, spool, logs), the
// node described as `slurmd -C` finds this machine, and every port on 127.0.0.1 (the controller
// and slurmd bind their address only: CommunicationParameters=NoCtldInAddrAny,NoInAddrAny),
// chosen free for the run, so clusters of tests running at once never meet. No cgroups:
// proctrack/linuxproc, task/none, jobacct_gather/none. No slurmdbd: accounting_storage/none,
// and jobcomp/filetxt keeps a completion log that `sacct -c` reads. Clients find the cluster
// through SLURM_CONF (env()).
//
// start() returns once `sinfo` shows the node idle. The destructor cancels every job, waits
// for their processes (then kills what is left of them: the processes whose environment names
// this cluster's slurm.conf), stops the daemons and removes the folder; if the test process
// dies first, the kernel stops the daemons (PR_SET_PDEATHSIG), and the next start kills the
// jobs and removes the folders such runs left.
//
// The daemons need root (slurmd starts each job as its user) and the packages; where either is
// missing start() says `unavailable`, and a test skips with the reason. Any other failure to
// start is a test failure, with the daemons' logs.
#include <sys/types.h>

#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mixpilot::test {

class SlurmCluster {
 public:
  enum class Start { started, unavailable, failed };

  static std::unique_ptr<SlurmCluster> start(Start& status, std::string& reason);
  ~SlurmCluster();
  SlurmCluster(const SlurmCluster&) = delete;
  SlurmCluster& operator=(const SlurmCluster&) = delete;

  const std::filesystem::path& folder() const { return folder_; }
  std::filesystem::path conf() const { return folder_ / "slurm.conf"; }
  // What a client process needs in its environment to reach this cluster.
  std::vector<std::pair<std::string, std::string>> env() const {
    return {{"SLURM_CONF", conf().string()}};
  }
  int controller_port() const { return ctld_port_; }
  int slurmd_port() const { return slurmd_port_; }
  // The daemons' process ids (munged, slurmctld, slurmd).
  std::vector<pid_t> daemons() const { return {munged_, slurmctld_, slurmd_}; }

  // Runs a client tool (sbatch, squeue, scancel, sinfo, sacct: found in PATH) against this
  // cluster, up to `seconds`; its exit status (-1: did not end, killed) and, in `output`, what
  // it wrote to stdout and stderr.
  int run(const std::vector<std::string>& argv, std::string& output, double seconds = 60) const;
  // The last lines of the daemons' logs, for a failure's message.
  std::string logs(std::size_t lines = 15) const;
  // The processes of this cluster's jobs still alive (slurmstepd and what it started).
  std::vector<pid_t> job_processes() const;

 private:
  SlurmCluster() = default;
  bool launch(std::string& reason, bool& port_taken);
  void stop();

  std::filesystem::path folder_;
  std::string node_line_;  // the node's hardware as `slurmd -C` reports it
  int ctld_port_ = 0;
  int slurmd_port_ = 0;
  pid_t munged_ = -1;
  pid_t slurmctld_ = -1;
  pid_t slurmd_ = -1;
};

}  // namespace mixpilot::test

// In a test fixture's SetUp: the cluster into `member`, skipping the test where none can start
// here and failing it where one should have started and did not.
#define MIXPILOT_START_SLURM(member)                                                  \
  do {                                                                               \
    ::mixpilot::test::SlurmCluster::Start slurm_status{};                            \
    std::string slurm_reason;                                                        \
    member = ::mixpilot::test::SlurmCluster::start(slurm_status, slurm_reason);      \
    if (slurm_status == ::mixpilot::test::SlurmCluster::Start::unavailable)          \
      GTEST_SKIP() << slurm_reason;                                                  \
    ASSERT_EQ(slurm_status, ::mixpilot::test::SlurmCluster::Start::started)          \
        << "the test Slurm cluster did not start: " << slurm_reason;                 \
  } while (false)
