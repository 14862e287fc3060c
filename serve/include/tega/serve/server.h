#pragma once
// `tega serve`: an HTTP server (cpp-httplib) for a browser player of trained
// avatars (docs/render-eval-export.md#serve):
//
//   GET /                                          the page (serve/web, built into the binary)
//   GET /app/<file>                                its scripts and styles
//   GET /api/runs                                  the runs served (a workspace's subjects)
//   GET /api/runs/<run>/index.json                 cameras, takes and frames, fps, eval numbers
//   GET /api/runs/<run>/static.bin                 what no frame changes (frame_stream.h)
//   GET /api/runs/<run>/frames/<frame>.bin         one frame's posed Gaussians (frame_stream.h)
//   GET /api/runs/<run>/images/<camera>/<frame>.png  the dataset's image
//   GET /api/splats, /api/splats/<name>            the --splat SPZ files, by file name
//
// Nothing else is served: run, camera and frame names are looked up among
// the run's own, and files are read only where they resolve inside the
// dataset. Unknown names are 404, malformed requests 400, a byte range beyond
// a body 416, and a frame whose run is busy posing another past
// Options::pose_wait_seconds 503.

#include <memory>

#include "tega/serve/options.h"

namespace tega::serve {

class Server {
 public:
  // Loads every run; throws tega::Error naming a run or dataset that cannot be read.
  explicit Server(const Options& options);
  ~Server();  // stops
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and answers on background threads; throws tega::Error when the
  // address cannot be bound.
  void start();
  int port() const;  // the bound port, after start()
  void stop();       // waits for the requests being answered

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Serves until SIGINT or SIGTERM, then stops gracefully.
void serve(const Options& options);

}  // namespace tega::serve
