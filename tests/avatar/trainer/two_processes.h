#pragma once
// Two processes' worth of a data-parallel group as two threads of this one.

#include <array>
#include <exception>
#include <functional>
#include <string>
#include <thread>
#include <vector>

namespace tega::test {

constexpr int kTwoProcesses = 2;

// Runs `process(rank)` for ranks 0 and 1 at once; returns what each threw ("" where nothing).
inline std::array<std::string, kTwoProcesses> as_two_processes(const std::function<void(int rank)>& process) {
  std::array<std::string, kTwoProcesses> failures;
  std::vector<std::thread> threads;
  for (int rank = 0; rank < kTwoProcesses; ++rank) {
    threads.emplace_back([&, rank] {
      try {
        process(rank);
      } catch (const std::exception& e) {
        failures[rank] = e.what();
      }
    });
  }
  for (auto& t : threads) t.join();
  return failures;
}

}  // namespace tega::test
