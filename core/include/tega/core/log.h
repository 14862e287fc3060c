#pragma once
// Logging. The CLI calls init_logging() once: 0 = warnings, 1 = info
// (default), 2 = debug. Messages go to stderr, so stdout stays clean for
// results (tables, JSON).
//
// The functions below take printf-style formats and are implemented in core
// on top of spdlog. Code that is compiled against libtorch logs through them
// rather than including spdlog: libtorch 2.x ships its own fmt headers, which
// would shadow the fmt that the system's spdlog was built with.

namespace tega {

void init_logging(int verbosity);

namespace logging {
void debug(const char* format, ...) __attribute__((format(printf, 1, 2)));
void info(const char* format, ...) __attribute__((format(printf, 1, 2)));
void warn(const char* format, ...) __attribute__((format(printf, 1, 2)));
}  // namespace logging

}  // namespace tega
