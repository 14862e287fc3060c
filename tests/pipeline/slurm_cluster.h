#pragma once
// A one-node Slurm cluster of the test's own: munged, slurmctld and slurmd run as children of the
// test process, every file of theirs (munge key, slurm.conf, state, spool, logs) in a directory of
// its own under /tmp (removed with it), on free ports, and clients find it through SLURM_CONF. The object's death stops it, whatever the
// test did: jobs cancelled, then SIGTERM to each daemon, SIGKILL after a grace period.
//
// Needs root (slurmd runs jobs as their owner, munged's key must belong to its user) and Debian's
// slurm-wlm and munge; without them, or when the node does not become idle within 30 s, the
// cluster is not up and unavailable_reason() says why (the tests skip with it).

#include <sys/types.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace tega::test {

class OneNodeCluster {
 public:
  OneNodeCluster();
  ~OneNodeCluster();
  OneNodeCluster(const OneNodeCluster&) = delete;
  OneNodeCluster& operator=(const OneNodeCluster&) = delete;

  bool up() const { return unavailable_reason_.empty(); }
  const std::string& unavailable_reason() const { return unavailable_reason_; }
  const std::filesystem::path& dir() const { return dir_; }
  // The daemons' log files, for a failing test's message.
  std::string daemon_logs() const;

 private:
  void start();  // throws std::runtime_error saying why the cluster cannot run here
  void spawn_daemon(const std::vector<std::string>& argv, const std::string& log_name);
  void write_slurm_conf() const;
  void stop();

  std::filesystem::path dir_;
  std::string unavailable_reason_;
  std::vector<pid_t> daemons_;  // in start order; stopped in reverse
  std::optional<std::string> previous_slurm_conf_;
};

// Runs a program (found on PATH) and returns its stdout and stderr; nullopt when it exits non-zero.
std::optional<std::string> program_output(const std::vector<std::string>& argv);

}  // namespace tega::test
