#pragma once
// Frames of a take overlapped two at a time: while `finish` runs for frame n
// (fusion and the surface, on the CPU), `prepare` runs for frame n + 1 on a
// second thread (loading and the depth maps, mostly on the GPU). A frame's
// stages depend only on that frame, so the take then meshes at the rate of the
// slower half rather than of their sum (docs/mvs.md#accuracy-and-speed).
//
// At most two frames are in flight, and so in memory: the one being finished
// and the one being prepared; frame n + 2 is not begun before frame n is
// finished. `finish` runs on the calling thread, in frame order. The first
// exception stops the run and is rethrown here (an exception of the frame
// being prepared meanwhile is dropped once that preparation ends).

#include <future>
#include <type_traits>
#include <utility>

namespace tega::mvs {

// prepare(int frame) -> P, called on one other thread at a time;
// finish(int frame, P&&), called on this thread for first, first + 1, ..., end - 1.
template <class Prepare, class Finish>
void for_each_frame_overlapped(int first, int end, Prepare&& prepare, Finish&& finish) {
  using Prepared = std::invoke_result_t<Prepare&, int>;
  if (first >= end) return;
  const auto begin = [&prepare](int frame) {
    return std::async(std::launch::async, [&prepare, frame] { return prepare(frame); });
  };
  std::future<Prepared> next = begin(first);
  for (int frame = first; frame < end; ++frame) {
    Prepared current = next.get();
    if (frame + 1 < end) next = begin(frame + 1);
    finish(frame, std::move(current));
  }
}

}  // namespace tega::mvs
