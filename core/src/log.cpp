#include "tega/core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <cstdarg>
#include <cstdio>
#include <string>

namespace tega {

void init_logging(int verbosity) {
  auto logger = spdlog::get("tega");
  if (!logger) logger = spdlog::stderr_color_mt("tega");
  logger->set_pattern("[%H:%M:%S] %^%l%$ %v");
  logger->set_level(verbosity <= 0 ? spdlog::level::warn
                                   : verbosity == 1 ? spdlog::level::info : spdlog::level::debug);
  spdlog::set_default_logger(logger);
}

namespace logging {
namespace {

void log(spdlog::level::level_enum level, const char* format, va_list args) {
  if (!spdlog::should_log(level)) return;
  va_list copy;
  va_copy(copy, args);
  const int size = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string text(size > 0 ? static_cast<size_t>(size) : 0, '\0');
  std::vsnprintf(text.data(), text.size() + 1, format, args);
  spdlog::log(level, "{}", text);
}

}  // namespace

#define TEGA_LOG_FUNCTION(name, level)   \
  void name(const char* format, ...) {   \
    va_list args;                        \
    va_start(args, format);              \
    log(level, format, args);            \
    va_end(args);                        \
  }
TEGA_LOG_FUNCTION(debug, spdlog::level::debug)
TEGA_LOG_FUNCTION(info, spdlog::level::info)
TEGA_LOG_FUNCTION(warn, spdlog::level::warn)
#undef TEGA_LOG_FUNCTION

}  // namespace logging
}  // namespace tega
