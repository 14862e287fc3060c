#pragma once
// What `tega serve` serves and how (docs/render-eval-export.md#serve).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace tega::serve {

struct Options {
  // A training run (RUN of tega train) or a `tega run` workspace, whose
  // train/<subject>/run are its runs.
  std::filesystem::path target;
  // The address to listen on. The default answers this machine only; the
  // server has no authentication, so expose it deliberately.
  std::string host = "127.0.0.1";
  // 0: any free port (the tests use it; Server::port() says which).
  int port = 8080;
  // Where frames are posed: cpu or cuda; empty: each run's training device.
  std::string device;
  // The capture's frame rate, at which the page plays takes: datasets do not
  // record it.
  double fps = 30;
  // Encoded frames kept for reuse, over every run, least recently used first out.
  int64_t cache_bytes = int64_t{512} << 20;
  // How long a frame request waits while another frame of its run is being
  // posed before it is answered 503 (Retry-After): posing runs one frame
  // at a time per run, and requests must not queue without bound.
  double pose_wait_seconds = 20;
  // Threads answering requests.
  int threads = 8;
  // Directories of tracked meshes (template topology, world space; `tega track`'s TRACKED/<take>,
  // held-out takes, new performances) that every run plays as takes of their own, named after the
  // directory, frames "<take>.<file stem>", each in the head pose of the run's first training frame
  // as `tega render --meshes` poses them.
  std::vector<std::filesystem::path> meshes;
  // SPZ files (`tega export --format spz`) the page may open beside the runs, by file name
  // (?splat=NAME), seen from the first run's cameras.
  std::vector<std::filesystem::path> splats;
};

}  // namespace tega::serve
