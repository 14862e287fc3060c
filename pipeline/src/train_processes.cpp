#include "train_processes.h"

#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

#include "tega/core/error.h"
#include "tega/core/log.h"

namespace tega::cli {
namespace fs = std::filesystem;

namespace {

constexpr const char* kRank = "TEGA_TRAIN_RANK";
constexpr const char* kWorld = "TEGA_TRAIN_WORLD";
constexpr const char* kRendezvous = "TEGA_TRAIN_RENDEZVOUS";

void interrupt_wait(int) {}  // wait() returns EINTR, and the loop passes the stop on

// This process's command line without --gpus/--processes and their values.
std::vector<std::string> own_arguments_without_spreading() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> arguments;
  for (size_t start = 0; start < all.size();) {
    const size_t end = all.find('\0', start);
    arguments.push_back(all.substr(start, end - start));
    start = end == std::string::npos ? all.size() : end + 1;
  }
  std::vector<std::string> kept;
  for (size_t i = 0; i < arguments.size(); ++i) {
    const std::string& a = arguments[i];
    if (a == "--gpus" || a == "--processes") {
      ++i;  // and its value
    } else if (a.rfind("--gpus=", 0) != 0 && a.rfind("--processes=", 0) != 0) {
      kept.push_back(a);
    }
  }
  return kept;
}

}  // namespace

int run_training_processes(int world, const std::vector<std::string>& gpus, const fs::path& run) {
  fs::create_directories(run);
  const fs::path rendezvous = run / ".rendezvous";
  fs::remove(rendezvous);  // c10d's file store would take an old one's contents for this run's
  const std::vector<std::string> arguments = own_arguments_without_spreading();
  logging::info("tega train: %d processes%s", world,
                gpus.empty() ? " on the CPU" : (" on GPUs " + [&] {
                  std::string listed;
                  for (const auto& g : gpus) listed += (listed.empty() ? "" : ", ") + g;
                  return listed;
                }()).c_str());
  // The training processes not yet waited for: only these get signals (a waited-for one's number
  // may be reused).
  std::vector<pid_t> running;
  const pid_t parent = ::getpid();
  for (int rank = 0; rank < world; ++rank) {
    std::vector<std::string> argv{"/proc/self/exe"};
    if (rank > 0) argv.push_back("--quiet");  // one process logs the run
    argv.insert(argv.end(), arguments.begin() + 1, arguments.end());
    std::vector<std::string> environment{std::string(kRank) + "=" + std::to_string(rank),
                                         std::string(kWorld) + "=" + std::to_string(world),
                                         std::string(kRendezvous) + "=" + rendezvous.string()};
    if (!gpus.empty()) environment.push_back("CUDA_VISIBLE_DEVICES=" + gpus[rank]);
    std::vector<char*> args;
    for (auto& a : argv) args.push_back(a.data());
    args.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) throw Error(std::string("tega train: cannot start a training process: ") + std::strerror(errno));
    if (pid == 0) {
      ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // none outlives the launcher
      if (::getppid() != parent) ::_exit(125);
      for (auto& e : environment) ::putenv(e.data());
      ::execv("/proc/self/exe", args.data());
      ::_exit(127);
    }
    running.push_back(pid);
  }
  // A stop for this process is passed on to the training processes, which stop together at one
  // step with a checkpoint (SIGTERM from `tega run` or a scheduler, Ctrl-C); this one waits for them.
  // It is passed on as SIGUSR1, which they catch every time (tega/core/interrupt.h): the same stop
  // often reaches them directly too (a terminal, Slurm and `timeout` signal the whole job), and
  // passed on as itself it would be their second SIGTERM or SIGINT, which kills without a
  // checkpoint. An operator's second Ctrl-C still reaches them directly and kills.
  struct sigaction on_stop {}, previous_int {}, previous_term {};
  on_stop.sa_handler = interrupt_wait;  // no SA_RESTART: wait() returns to pass the stop on
  ::sigaction(SIGINT, &on_stop, &previous_int);
  ::sigaction(SIGTERM, &on_stop, &previous_term);
  int exit_status = 0;
  while (!running.empty()) {
    int status = 0;
    const pid_t done = ::wait(&status);
    if (done < 0 && errno == EINTR) {
      for (const pid_t child : running) ::kill(child, SIGUSR1);
      continue;
    }
    if (done < 0) break;
    running.erase(std::remove(running.begin(), running.end(), done), running.end());
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code != 0 && exit_status == 0) {
      exit_status = code;
      // The others would wait for its gradients until Gloo's timeout.
      for (const pid_t child : running) ::kill(child, SIGKILL);
    }
  }
  ::sigaction(SIGINT, &previous_int, nullptr);
  ::sigaction(SIGTERM, &previous_term, nullptr);
  fs::remove(rendezvous);
  return exit_status;
}

std::optional<trainer::ParallelRank> parallel_rank_from_environment() {
  const char* rank = std::getenv(kRank);
  const char* world = std::getenv(kWorld);
  const char* rendezvous = std::getenv(kRendezvous);
  if (!rank || !world || !rendezvous) return std::nullopt;
  return trainer::ParallelRank{std::atoi(rank), std::atoi(world), rendezvous};
}

}  // namespace tega::cli
