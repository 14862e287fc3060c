#pragma once
// The take's live status on stderr: on a terminal the block of lines is
// redrawn in place; otherwise one block is logged every 10 seconds.
#include <chrono>
#include <string>
#include <vector>

namespace tega::capture {

class LiveStatus {
 public:
  explicit LiveStatus(bool enabled);
  void show(const std::vector<std::string>& lines);
  void finish();  // leaves the last block on screen

 private:
  bool enabled_, tty_;
  size_t drawn_ = 0;
  std::chrono::steady_clock::time_point last_log_;
};

}  // namespace tega::capture
