#pragma once
// Frames of a take in three stages, each on a thread of its own: while `finish`
// runs for frame n (fusion, the surface, writing), `prepare` runs for frame
// n + 1 (the depth maps, mostly on the GPU) and `load` for frame n + 2 (its
// photos and masks, on the CPU). A frame's stages depend only on that frame, so
// the take meshes at the rate of the slowest stage rather than of their sum
// (docs/mvs.md#accuracy-and-speed).
//
// At most three frames are in flight, and so in memory: the one being finished,
// the one being prepared and the one loaded; frame n + 3 is not begun before
// frame n is finished. `finish` runs on the calling thread, in frame order. The
// first exception stops the run and is rethrown here (exceptions of the frames
// under way meanwhile are dropped once they end).

#include <future>
#include <type_traits>
#include <utility>

namespace tega::mvs {

// load(int frame) -> L and prepare(int frame, L) -> P, each called on one other
// thread at a time; finish(int frame, P), called on this thread for first,
// first + 1, ..., end - 1.
template <class Load, class Prepare, class Finish>
void for_each_frame_pipelined(int first, int end, Load&& load, Prepare&& prepare, Finish&& finish) {
  using Loaded = std::invoke_result_t<Load&, int>;
  using Prepared = std::invoke_result_t<Prepare&, int, Loaded>;
  if (first >= end) return;
  const auto begin_load = [&load](int frame) {
    return std::async(std::launch::async, [&load, frame] { return load(frame); });
  };
  const auto begin_prepare = [&prepare](int frame, std::future<Loaded> loaded) {
    return std::async(std::launch::async,
                      [&prepare, frame, loaded = std::move(loaded)]() mutable { return prepare(frame, loaded.get()); });
  };
  std::future<Loaded> next_loaded = begin_load(first);
  std::future<Prepared> next_prepared = begin_prepare(first, std::move(next_loaded));
  if (first + 1 < end) next_loaded = begin_load(first + 1);
  for (int frame = first; frame < end; ++frame) {
    Prepared current = next_prepared.get();
    if (frame + 1 < end) {
      next_prepared = begin_prepare(frame + 1, std::move(next_loaded));
      if (frame + 2 < end) next_loaded = begin_load(frame + 2);
    }
    finish(frame, std::move(current));
  }
}

}  // namespace tega::mvs
