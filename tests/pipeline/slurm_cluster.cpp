#include "slurm_cluster.h"

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "tega/core/files.h"

extern char** environ;

namespace tega::test {
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr auto kIdleTimeout = std::chrono::seconds(30);
constexpr auto kStopGrace = std::chrono::seconds(10);

std::optional<fs::path> find_program(const std::string& name) {
  std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  path += ":/usr/sbin:/sbin";  // the daemons, where root's PATH may not reach
  std::istringstream dirs(path);
  for (std::string dir; std::getline(dirs, dir, ':');) {
    if (!dir.empty() && ::access((fs::path(dir) / name).c_str(), X_OK) == 0) return fs::path(dir) / name;
  }
  return std::nullopt;
}

std::string short_hostname() {
  char name[256] = {};
  ::gethostname(name, sizeof name - 1);
  const std::string host = name;
  return host.substr(0, host.find('.'));
}

// Two ports nobody listens on now (both sockets held at once, so they differ).
std::pair<int, int> free_ports() {
  int fds[2];
  int ports[2];
  for (int i = 0; i < 2; ++i) {
    fds[i] = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof address;
    if (fds[i] < 0 || ::bind(fds[i], reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::getsockname(fds[i], reinterpret_cast<sockaddr*>(&address), &length) != 0) {
      throw std::runtime_error("cannot find a free TCP port for slurmctld and slurmd");
    }
    ports[i] = ntohs(address.sin_port);
  }
  ::close(fds[0]);
  ::close(fds[1]);
  return {ports[0], ports[1]};
}

bool alive(pid_t pid) { return ::waitpid(pid, nullptr, WNOHANG) == 0; }

}  // namespace

std::optional<std::string> program_output(const std::vector<std::string>& args) {
  const auto program = find_program(args[0]);
  if (!program) return std::nullopt;
  char output_template[] = "/tmp/tega-slurm-test-output-XXXXXX";
  const int fd = ::mkstemp(output_template);
  if (fd < 0) return std::nullopt;
  std::vector<std::string> strings = args;
  strings[0] = program->string();
  std::vector<char*> argv;
  for (auto& a : strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, fd, STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, fd, STDERR_FILENO);
  pid_t pid = -1;
  const int error = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(fd);
  int status = 0;
  const bool ok = error == 0 && ::waitpid(pid, &status, 0) == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  std::string output = read_text_file(output_template);
  fs::remove(output_template);
  if (!ok) return std::nullopt;
  return output;
}

OneNodeCluster::OneNodeCluster() {
  if (const char* previous = std::getenv("SLURM_CONF")) previous_slurm_conf_ = previous;
  try {
    // Short: munged's socket path must fit in 108 bytes.
    char dir_template[] = "/tmp/tega-slurm-XXXXXX";
    if (!::mkdtemp(dir_template)) throw std::runtime_error("cannot create a directory under /tmp");
    dir_ = dir_template;
    start();
  } catch (const std::exception& e) {
    unavailable_reason_ = e.what();
    stop();
  }
}

OneNodeCluster::~OneNodeCluster() {
  stop();
  if (!dir_.empty()) remove_tree(dir_);
}

void OneNodeCluster::spawn_daemon(const std::vector<std::string>& args, const std::string& log_name) {
  std::vector<std::string> strings = args;
  strings[0] = find_program(args[0])->string();
  std::vector<char*> argv;
  for (auto& a : strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  const fs::path log = dir_ / "log" / log_name;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  pid_t pid = -1;
  const int error = ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (error != 0) throw std::runtime_error(args[0] + " cannot be started");
  daemons_.push_back(pid);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  if (!alive(pid)) {
    daemons_.pop_back();
    throw std::runtime_error(args[0] + " exited at once; its log (" + log.string() + "):\n" + read_text_file(log));
  }
}

void OneNodeCluster::write_slurm_conf() const {
  const auto [controller_port, node_port] = free_ports();
  const std::string host = short_hostname();
  const std::string d = dir_.string();
  const unsigned cpus = std::max(1u, std::thread::hardware_concurrency());
  std::ostringstream conf;
  conf << "ClusterName=tegatest\n"
       << "SlurmctldHost=" << host << "(127.0.0.1)\n"
       << "SlurmctldPort=" << controller_port << "\nSlurmdPort=" << node_port << "\n"
       << "SlurmUser=root\nSlurmdUser=root\n"
       << "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=" << d << "/munge-socket/munge.socket\n"
       << "StateSaveLocation=" << d << "/state\nSlurmdSpoolDir=" << d << "/spool\n"
       << "SlurmctldPidFile=" << d << "/slurmctld.pid\nSlurmdPidFile=" << d << "/slurmd.pid\n"
       << "SlurmctldLogFile=" << d << "/log/slurmctld.log\nSlurmdLogFile=" << d << "/log/slurmd.log\n"
       // No cgroups: the test may run in a container without a writable cgroup tree.
       << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nJobAcctGatherType=jobacct_gather/none\n"
       << "SelectType=select/cons_tres\nSelectTypeParameters=CR_Core\nSchedulerType=sched/backfill\n"
       << "ReturnToService=2\nAccountingStorageType=accounting_storage/none\nJobCompType=jobcomp/none\n"
       << "MpiDefault=none\nMailProg=/bin/true\n"
       << "NodeName=" << host << " NodeAddr=127.0.0.1 CPUs=" << cpus << " RealMemory=500 State=UNKNOWN\n"
       << "PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP\n";
  std::ofstream(dir_ / "slurm.conf") << conf.str();
}

void OneNodeCluster::start() {
  for (const char* program : {"munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "sinfo"}) {
    if (!find_program(program)) throw std::runtime_error(std::string(program) + " is not installed (Debian: slurm-wlm, munge)");
  }
  if (::geteuid() != 0) throw std::runtime_error("the one-node Slurm cluster needs root (slurmd, munged's key)");

  // munged refuses a key readable by others and a socket directory that others cannot enter.
  for (const char* sub : {"munge", "munge-socket", "state", "spool", "log"}) fs::create_directories(dir_ / sub);
  fs::permissions(dir_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                            fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(dir_ / "munge-socket", fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                            fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(dir_ / "munge", fs::perms::owner_all);
  {
    std::random_device random;
    std::string key(1024, '\0');
    for (auto& c : key) c = static_cast<char>(random());
    std::ofstream(dir_ / "munge/munge.key", std::ios::binary) << key;
  }
  fs::permissions(dir_ / "munge/munge.key", fs::perms::owner_read);
  const std::string d = dir_.string();
  spawn_daemon({"munged", "--foreground", "--force", "--key-file=" + d + "/munge/munge.key",
                "--socket=" + d + "/munge-socket/munge.socket", "--pid-file=" + d + "/munge/munged.pid",
                "--log-file=" + d + "/log/munged.log", "--seed-file=" + d + "/munge/munged.seed"},
               "munged.out");

  write_slurm_conf();
  const std::string conf = (dir_ / "slurm.conf").string();
  ::setenv("SLURM_CONF", conf.c_str(), 1);
  spawn_daemon({"slurmctld", "-D", "-f", conf}, "slurmctld.out");
  spawn_daemon({"slurmd", "-D", "-f", conf}, "slurmd.out");

  const auto deadline = Clock::now() + kIdleTimeout;
  std::string state;
  while (Clock::now() < deadline) {
    state = program_output({"sinfo", "--noheader", "--format=%t"}).value_or("(sinfo failed)");
    if (state.rfind("idle", 0) == 0) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
  }
  throw std::runtime_error("the node did not become idle within 30 s (sinfo: " + state + ")\n" + daemon_logs());
}

std::string OneNodeCluster::daemon_logs() const {
  std::string logs;
  for (const char* name : {"munged.out", "slurmctld.out", "slurmd.out", "slurmctld.log", "slurmd.log"}) {
    if (fs::exists(dir_ / "log" / name)) logs += "--- " + std::string(name) + ":\n" + read_text_file(dir_ / "log" / name);
  }
  return logs;
}

void OneNodeCluster::stop() {
  // Jobs first, while slurmd can still end them: their slurmstepd would outlive it.
  if (daemons_.size() == 3) {
    const auto deadline = Clock::now() + kStopGrace;
    for (;;) {
      const auto jobs = program_output({"squeue", "--noheader", "--format=%i"});
      if (!jobs || jobs->empty() || Clock::now() > deadline) break;
      std::vector<std::string> scancel = {"scancel"};
      std::istringstream ids(*jobs);
      for (std::string id; ids >> id;) scancel.push_back(id);
      program_output(scancel);
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
  }
  for (auto it = daemons_.rbegin(); it != daemons_.rend(); ++it) {
    ::kill(*it, SIGTERM);
    const auto deadline = Clock::now() + kStopGrace;
    while (alive(*it) && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (alive(*it)) {
      ::kill(*it, SIGKILL);
      ::waitpid(*it, nullptr, 0);
    }
  }
  daemons_.clear();
  if (previous_slurm_conf_) {
    ::setenv("SLURM_CONF", previous_slurm_conf_->c_str(), 1);
  } else {
    ::unsetenv("SLURM_CONF");
  }
}

}  // namespace tega::test
