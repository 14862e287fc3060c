#pragma once
// Progress of long work: "label  123/390 images  31.2 images/s  ETA 0:07".
// On a terminal the line redraws itself (at most 10 times a second). When
// stderr is not a terminal (a log file: every pipeline shard's) the line is
// logged once every `log_interval`, so that the log, and `tega run` which shows
// each running shard's last log line, tell the rate and the ETA; finish() logs
// the summary line. advance() is thread-safe.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <string>

namespace tega {

class Progress {
 public:
  Progress(std::string label, int64_t total, std::string unit = "items",
           std::chrono::milliseconds log_interval = std::chrono::seconds(30));
  ~Progress();  // finish() if not yet finished
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void advance(int64_t n = 1);
  void finish();
  int64_t done() const { return done_.load(); }

  static std::string format_duration(double seconds);  // "1:02:03", "2:03"

 private:
  void draw(bool final_line);

  std::string label_, unit_;
  int64_t total_;
  std::atomic<int64_t> done_{0};
  std::chrono::milliseconds log_interval_;
  std::chrono::steady_clock::time_point start_, last_draw_;
  std::mutex mutex_;
  bool tty_, finished_ = false;
};

}  // namespace tega
