#include "tega/core/log.h"

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

namespace tega {

void init_logging(int verbosity) {
  // Logs go to stderr so that stdout stays clean for results (tables, JSON).
  auto logger = spdlog::get("tega");
  if (!logger) logger = spdlog::stderr_color_mt("tega");
  logger->set_pattern("[%H:%M:%S] %^%l%$ %v");
  logger->set_level(verbosity <= 0 ? spdlog::level::warn
                                   : verbosity == 1 ? spdlog::level::info : spdlog::level::debug);
  spdlog::set_default_logger(logger);
}

}  // namespace tega
