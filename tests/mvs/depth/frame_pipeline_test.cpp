#include "tega/mvs/frame_pipeline.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace tega::mvs {
namespace {

// A prepared frame that counts how many exist at once.
struct Counted {
  static inline std::atomic<int> alive{0}, most_alive{0};
  int frame;
  explicit Counted(int f) : frame(f) {
    const int now = ++alive;
    for (int most = most_alive; now > most && !most_alive.compare_exchange_weak(most, now);) {
    }
  }
  ~Counted() { --alive; }
};

TEST(FramePipeline, FinishesEveryFrameInOrderWhileTheNextIsPrepared) {
  Counted::alive = 0;
  Counted::most_alive = 0;
  constexpr int first = 10, end = 16;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<int> started;  // frames whose preparation began
  int finished = 0;
  std::vector<int> finished_frames;
  const auto prepare = [&](int frame) {
    std::lock_guard lock(mutex);
    // Frame n + 2 is not begun before frame n is finished: two frames in flight at most.
    EXPECT_GE(finished, frame - first - 1) << "frame " << frame << " began too early";
    started.push_back(frame);
    changed.notify_all();
    return std::make_unique<Counted>(frame);
  };
  const auto finish = [&](int frame, std::unique_ptr<Counted> prepared) {
    EXPECT_EQ(prepared->frame, frame);
    std::unique_lock lock(mutex);
    if (frame + 1 < end) {  // the next frame is prepared meanwhile
      const bool overlapped = changed.wait_for(lock, std::chrono::seconds(10), [&] {
        return !started.empty() && started.back() == frame + 1;
      });
      EXPECT_TRUE(overlapped) << "frame " << frame + 1 << " was not prepared while frame " << frame << " finished";
    }
    finished_frames.push_back(frame);
    ++finished;
  };
  for_each_frame_overlapped(first, end, prepare, finish);
  EXPECT_EQ(finished_frames, (std::vector<int>{10, 11, 12, 13, 14, 15}));
  EXPECT_EQ(started, (std::vector<int>{10, 11, 12, 13, 14, 15}));
  EXPECT_LE(Counted::most_alive, 2);
  EXPECT_EQ(Counted::alive, 0);
}

TEST(FramePipeline, AnEmptyRangeDoesNothing) {
  int calls = 0;
  for_each_frame_overlapped(
      3, 3, [&](int) { return ++calls; }, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(FramePipeline, AFailedPreparationStopsTheRunAfterTheFramesBefore) {
  std::vector<int> finished;
  const auto prepare = [](int frame) {
    if (frame == 3) throw std::runtime_error("frame 3 unreadable");
    return frame;
  };
  EXPECT_THROW(for_each_frame_overlapped(0, 8, prepare, [&](int frame, int) { finished.push_back(frame); }),
               std::runtime_error);
  EXPECT_EQ(finished, (std::vector<int>{0, 1, 2}));
}

TEST(FramePipeline, AFailedFinishStopsTheRunOnceThePreparedFrameIsDone) {
  std::atomic<int> prepared_frames{0};
  const auto prepare = [&](int frame) {
    ++prepared_frames;
    return frame;
  };
  const auto finish = [](int frame, int) {
    if (frame == 2) throw std::runtime_error("frame 2 did not fuse");
  };
  EXPECT_THROW(for_each_frame_overlapped(0, 8, prepare, finish), std::runtime_error);
  // Frames 0 to 3: the one after the failed frame was under way and is waited for, none later.
  EXPECT_EQ(prepared_frames, 4);
}

}  // namespace
}  // namespace tega::mvs
