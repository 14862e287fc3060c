#pragma once
// Ctrl-C (SIGINT) and SIGTERM (a scheduler's time limit, `tega run` stopping)
// ask long work to stop at a safe point and keep what it has: a take is
// finalised, a training run saves a checkpoint. A second signal is not caught,
// so an operator can still kill a stuck process.
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
  struct sigaction previous_int_ {}, previous_term_ {};
};

}  // namespace tega
