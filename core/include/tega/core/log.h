#pragma once
// Logging goes through spdlog (include <spdlog/spdlog.h> where you log).
// The CLI calls init_logging() once: 0 = warnings, 1 = info (default), 2 = debug.

namespace tega {
void init_logging(int verbosity);
}
