#include "live_status.h"

#include <unistd.h>

#include <cstdio>

#include "tega/core/log.h"

namespace tega::capture {

namespace {
constexpr auto kLogInterval = std::chrono::seconds(10);
}

LiveStatus::LiveStatus(bool enabled)
    : enabled_(enabled), tty_(isatty(STDERR_FILENO) != 0), last_log_(std::chrono::steady_clock::now()) {}

void LiveStatus::show(const std::vector<std::string>& lines) {
  if (!enabled_) return;
  if (!tty_) {
    const auto now = std::chrono::steady_clock::now();
    if (now - last_log_ < kLogInterval) return;
    last_log_ = now;
    for (const auto& line : lines) logging::info("%s", line.c_str());
    return;
  }
  std::string text;
  if (drawn_ > 0) text += "\033[" + std::to_string(drawn_) + "F";  // back to the block's first line
  for (const auto& line : lines) text += "\033[2K" + line + "\n";
  std::fputs(text.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = lines.size();
}

void LiveStatus::finish() { drawn_ = 0; }

}  // namespace tega::capture
