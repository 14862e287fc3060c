// `tega run --executor slurm` on a real one-node Slurm cluster that the test starts itself: the two
// synth shards, ready together, go out as one job array; the committed outputs equal the local
// executor's byte for byte, even when an array task's command, or a whole job with its batch
// script, is killed with SIGKILL mid-run (each is submitted again), and `tega status` shows the
// Slurm jobs, an array task as <array>_<task>.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "pipeline_test_support.h"
#include "slurm_cluster.h"
#include "tega/core/files.h"
#include "test_support.h"

namespace tega::test {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Two subjects through synth and dataset check: four shards, the two synth ones ready at once.
std::string slurm_test_config() {
  return "workspace: unused\nsubjects:\n  alice: {}\n  bob: {options: {synth: {seed: 2}}}\n"
         "stages:\n  synth:\n    options:\n" +
         tiny_synth_options(6) + "  check: {kind: dataset_check, after: synth}\n";
}

// The process whose command line is `<tega> <subcommand> ...` and mentions `text`; -1 when none.
pid_t find_shard_process(const std::string& subcommand, const std::string& text) {
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::vector<std::string> argv;
    for (std::string arg; std::getline(in, arg, '\0');) argv.push_back(arg);
    if (argv.size() < 2 || fs::path(argv[0]).filename() != "tega" || argv[1] != subcommand) continue;
    for (const auto& arg : argv) {
      if (arg.find(text) != std::string::npos) return static_cast<pid_t>(std::stol(name));
    }
  }
  return -1;
}

pid_t wait_for_shard_process(const std::string& subcommand, const std::string& text) {
  for (const auto deadline = Clock::now() + std::chrono::seconds(60); Clock::now() < deadline;) {
    if (const pid_t pid = find_shard_process(subcommand, text); pid > 0) return pid;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return -1;
}

pid_t parent_of(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  // "pid (comm) state ppid ...": comm may hold spaces, so read after its closing parenthesis.
  std::istringstream rest(line.substr(line.rfind(')') + 1));
  std::string state;
  pid_t parent = -1;
  rest >> state >> parent;
  return parent;
}

bool still_running(pid_t pid) { return ::waitpid(pid, nullptr, WNOHANG) == 0; }

// The Slurm job id that `tega run` logged for a shard's first submission; "" when none.
std::string first_slurm_job(const std::string& run_output, const std::string& shard) {
  std::smatch match;
  const std::regex submitted(shard + ": Slurm job ([0-9_]+)");
  return std::regex_search(run_output, match, submitted) ? match[1].str() : "";
}

// A `tega run` that a failed assertion left running would poll a stopped cluster for ever.
struct KillOnExit {
  pid_t pid;
  ~KillOnExit() {
    if (pid > 0 && still_running(pid)) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, 0);
    }
  }
};

TEST(SlurmExecutor, RunsShardsAsSlurmJobsAndRequeuesKilledOnes) {
  if (!tega_has_command({"synth"})) GTEST_SKIP() << "this build has no `tega synth`";
  TempDir dir;
  const fs::path config = dir / "p.yaml";
  write_text(config, slurm_test_config());
  std::string cluster_dir;
  {
    const OneNodeCluster cluster;
    if (!cluster.up()) GTEST_SKIP() << "no Slurm cluster here: " << cluster.unavailable_reason();
    cluster_dir = cluster.dir().string();
    const auto local = run_tega({"run", config.string(), "--workspace", (dir / "local").string(), "--jobs", "2"}, dir.path());
    ASSERT_EQ(local.exit_code, 0) << local.output;

    const fs::path ws = dir / "slurm";
    const fs::path output = dir / "slurm-run.txt";
    const pid_t run = spawn_tega({"run", config.string(), "--workspace", ws.string(), "--executor", "slurm"}, output);
    ASSERT_GT(run, 0);
    const KillOnExit stop_run_on_failure{run};

    // Kill bob's synth command (an array task's) the moment it runs on the node: its batch script
    // reports the signal. Stopped first, it cannot finish while `tega status` looks at its job.
    const pid_t synth = wait_for_shard_process("synth", (ws / "synth/.staging-bob").string());
    ASSERT_GT(synth, 0) << "synth/bob never ran\n" << cluster.daemon_logs();
    ::kill(synth, SIGSTOP);
    const std::string status_of_array = run_tega({"status", ws.string()}, dir.path()).output;
    ::kill(synth, SIGKILL);
    // Kill alice's check with its batch script, as a crashing node would: no exit status at all.
    const pid_t check = wait_for_shard_process("dataset", (ws / "synth/alice").string());
    ASSERT_GT(check, 0) << "check/alice never ran\n" << cluster.daemon_logs();
    const pid_t batch_script = parent_of(check);
    ASSERT_GT(batch_script, 1);
    ::kill(batch_script, SIGKILL);
    ::kill(check, SIGKILL);

    // While the run goes on, `tega status` names the Slurm job of a running shard.
    bool status_showed_a_job = false;
    while (!status_showed_a_job && still_running(run)) {
      const auto status = run_tega({"status", ws.string()}, dir.path());
      status_showed_a_job = status.output.find("running  slurm job ") != std::string::npos;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    const int exit_code = wait_for_exit(run);
    const std::string run_output = read_text_file(output);
    ASSERT_EQ(exit_code, 0) << run_output << "\n" << cluster.daemon_logs();
    EXPECT_TRUE(status_showed_a_job);
    const std::string alice_task = first_slurm_job(run_output, "synth/alice");
    const std::string array = alice_task.substr(0, alice_task.find('_'));
    EXPECT_EQ(alice_task, array + "_0") << run_output;
    EXPECT_EQ(first_slurm_job(run_output, "synth/bob"), array + "_1") << run_output;
    EXPECT_NE(status_of_array.find("slurm job " + array + "_1 "), std::string::npos) << status_of_array;
    EXPECT_NE(read_text_file(ws / "logs/synth/alice.log").find("[slurm job " + array + "_0 on "), std::string::npos);
    // Requeued alone, bob's synth went out as a plain job.
    EXPECT_TRUE(std::regex_search(run_output, std::regex("synth/bob: Slurm job [0-9]+\n"))) << run_output;
    EXPECT_NE(run_output.find("killed by signal 9; submitting it again (requeue 1 of 2)"), std::string::npos)
        << run_output;
    EXPECT_NE(run_output.find("ended without the command's exit status; submitting it again (requeue 1 of 2)"),
              std::string::npos)
        << run_output;
    EXPECT_EQ(attempts(ws, "synth", "bob"), 2);
    EXPECT_EQ(attempts(ws, "check", "alice"), 2);
    EXPECT_EQ(attempts(ws, "synth", "alice"), 1);
    EXPECT_EQ(attempts(ws, "check", "bob"), 1);
    EXPECT_EQ(committed_outputs(ws), committed_outputs(dir / "local"));
    EXPECT_TRUE(staging_dirs(ws).empty());
    EXPECT_FALSE(fs::exists(ws / "logs/synth" / ("slurm-" + alice_task + ".out")));  // appended to the log
  }
  // The cluster's daemons and every job's process are gone.
  EXPECT_TRUE(wait_until_no_process_mentions(cluster_dir, std::chrono::seconds(5)));
  EXPECT_TRUE(wait_until_no_process_mentions(dir.path().string(), std::chrono::seconds(5)));
}

}  // namespace
}  // namespace tega::test
