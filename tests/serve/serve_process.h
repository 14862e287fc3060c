#pragma once
// `tega serve` as a user starts it, on a free port, for the tests that talk
// to the binary.

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>
#include <thread>

namespace tega::test {

inline int free_port() {
  const int socket_fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(socket_fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  getsockname(socket_fd, reinterpret_cast<sockaddr*>(&address), &length);
  close(socket_fd);
  return ntohs(address.sin_port);
}

struct ServeProcess {
  int port = free_port();
  pid_t pid = -1;

  // `more`: further arguments of `tega serve` (e.g. --splat FILE).
  explicit ServeProcess(const std::filesystem::path& target, std::vector<std::string> more = {}) {
    std::vector<std::string> arguments{TEGA_EXECUTABLE, "-q",          "serve", target.string(), "--port",
                                       std::to_string(port), "--device", "cpu"};
    arguments.insert(arguments.end(), more.begin(), more.end());
    std::vector<char*> argv;
    for (auto& a : arguments) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid = fork();
    if (pid == 0) {
      execv(TEGA_EXECUTABLE, argv.data());
      _exit(127);
    }
  }

  std::string url() const { return "http://127.0.0.1:" + std::to_string(port); }

  // SIGTERM, then the exit status (-1 when it did not exit by itself).
  int stop() {
    if (pid <= 0) return -1;
    kill(pid, SIGTERM);
    int status = 0;
    waitpid(pid, &status, 0);
    pid = -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  ~ServeProcess() { stop(); }
};

}  // namespace tega::test
