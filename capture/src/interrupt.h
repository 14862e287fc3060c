#pragma once
// Ctrl-C (SIGINT) and SIGTERM during a take ask it to stop and finalise; a
// second Ctrl-C is not caught, so an operator can still kill a stuck process.
#include <atomic>
#include <csignal>

namespace tega::capture {

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

}  // namespace tega::capture
