#pragma once
// Ctrl-C (SIGINT) and SIGTERM (a scheduler's time limit, `tega run` stopping)
// ask long work to stop at a safe point and keep what it has: a take is
// finalised, a training run saves a checkpoint. A second SIGINT or SIGTERM is
// not caught, so an operator can still kill a stuck process.
//
// SIGUSR1 is the same stop passed on by a parent process (`tega train --gpus`
// to its training processes). It is caught every time: the stop the parent
// passes on has often reached the process itself as well (a terminal's Ctrl-C,
// Slurm and `timeout` signal every process of the job), and two signals of one
// stop must not count as the operator's second.
#include <csignal>

namespace tega {

class InterruptGuard {
 public:
  InterruptGuard();
  ~InterruptGuard();  // restores the previous handlers
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;
  static bool requested();

 private:
  struct sigaction previous_int_ {}, previous_term_ {}, previous_usr1_ {};
};

}  // namespace tega
