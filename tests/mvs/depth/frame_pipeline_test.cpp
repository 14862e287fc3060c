#include "tega/mvs/frame_pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace tega::mvs {
namespace {

// A frame in flight (loaded, then prepared) that counts how many exist at once.
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

TEST(FramePipeline, FinishesEveryFrameInOrderWhileTheNextArePreparedAndLoaded) {
  Counted::alive = 0;
  Counted::most_alive = 0;
  constexpr int first = 10, end = 17;
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<int> loads_begun, preparations_begun;
  int finished = 0;
  std::vector<int> finished_frames;
  const auto load = [&](int frame) {
    std::lock_guard lock(mutex);
    // Frame n + 3 is not begun before frame n is finished: three frames in flight at most.
    EXPECT_GE(finished, frame - first - 2) << "frame " << frame << " was loaded too early";
    loads_begun.push_back(frame);
    changed.notify_all();
    return std::make_unique<Counted>(frame);
  };
  const auto prepare = [&](int frame, std::unique_ptr<Counted> loaded) {
    EXPECT_EQ(loaded->frame, frame);
    std::lock_guard lock(mutex);
    preparations_begun.push_back(frame);
    changed.notify_all();
    return loaded;
  };
  const auto finish = [&](int frame, std::unique_ptr<Counted> prepared) {
    EXPECT_EQ(prepared->frame, frame);
    std::unique_lock lock(mutex);
    // Meanwhile the next frame is prepared and the one after it loaded.
    const auto begun = [](const std::vector<int>& frames, int frame) {
      return std::find(frames.begin(), frames.end(), frame) != frames.end();
    };
    const bool overlapped = changed.wait_for(lock, std::chrono::seconds(10), [&] {
      return (frame + 1 >= end || begun(preparations_begun, frame + 1)) && (frame + 2 >= end || begun(loads_begun, frame + 2));
    });
    EXPECT_TRUE(overlapped) << "frames " << frame + 1 << " and " << frame + 2 << " were not under way while frame "
                            << frame << " finished";
    finished_frames.push_back(frame);
    ++finished;
  };
  for_each_frame_pipelined(first, end, load, prepare, finish);
  const std::vector<int> every{10, 11, 12, 13, 14, 15, 16};
  EXPECT_EQ(finished_frames, every);
  EXPECT_EQ(preparations_begun, every);
  EXPECT_EQ(loads_begun.size(), every.size());
  EXPECT_LE(Counted::most_alive, 3);
  EXPECT_EQ(Counted::alive, 0);
}

TEST(FramePipeline, AnEmptyRangeDoesNothing) {
  int calls = 0;
  for_each_frame_pipelined(
      3, 3, [&](int) { return ++calls; }, [&](int, int) { return ++calls; }, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(FramePipeline, AFailedLoadOrPreparationStopsTheRunAfterTheFramesBefore) {
  for (const bool in_load : {true, false}) {
    std::vector<int> finished;
    const auto load = [&](int frame) {
      if (in_load && frame == 3) throw std::runtime_error("frame 3 unreadable");
      return frame;
    };
    const auto prepare = [&](int frame, int) {
      if (!in_load && frame == 3) throw std::runtime_error("frame 3 has no depth");
      return frame;
    };
    EXPECT_THROW(for_each_frame_pipelined(0, 8, load, prepare, [&](int frame, int) { finished.push_back(frame); }),
                 std::runtime_error);
    EXPECT_EQ(finished, (std::vector<int>{0, 1, 2})) << (in_load ? "load" : "prepare");
  }
}

TEST(FramePipeline, AFailedFinishStopsTheRunOnceTheFramesUnderWayAreDone) {
  std::atomic<int> loaded{0}, prepared{0};
  const auto load = [&](int frame) {
    ++loaded;
    return frame;
  };
  const auto prepare = [&](int frame, int) {
    ++prepared;
    return frame;
  };
  const auto finish = [](int frame, int) {
    if (frame == 2) throw std::runtime_error("frame 2 did not fuse");
  };
  EXPECT_THROW(for_each_frame_pipelined(0, 8, load, prepare, finish), std::runtime_error);
  // Under way when frame 2 failed, and waited for: frame 3's preparation and frame 4's load; none later.
  EXPECT_EQ(prepared, 4);
  EXPECT_EQ(loaded, 5);
}

}  // namespace
}  // namespace tega::mvs
