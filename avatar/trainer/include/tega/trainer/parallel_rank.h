#pragma once
// A process's place among those that train one run together (data_parallel.h), apart from it so
// that the CLI passes it without libtorch's headers.

#include <filesystem>

namespace tega::trainer {

struct ParallelRank {
  int rank = 0;
  int world = 1;  // 1: alone
  // A file every process can reach, absent before the first process starts (the run directory's).
  std::filesystem::path rendezvous;
};

}  // namespace tega::trainer
