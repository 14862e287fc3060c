#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace tega::synth {
namespace {

namespace fs = std::filesystem;

std::string bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Options tiny(int64_t seed, int threads) {
  Options o;
  o.studio.cameras = 2;
  o.studio.width = 64;
  o.studio.height = 48;
  o.frames = 2;
  o.calibration_frames = 1;
  o.takes = {"expressions", "freestyle"};
  o.supersampling = 2;
  o.fine_subdivisions = 1;
  o.seed = seed;
  o.threads = threads;
  return o;
}

TEST(Determinism, SameSeedGivesIdenticalFilesWhateverTheThreadCount) {
  tega::test::TempDir tmp;
  render_virtual_studio(tiny(7, 1), tmp / "a");
  render_virtual_studio(tiny(7, 3), tmp / "b");
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(tmp / "a")) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), tmp / "a");
    if (rel == "capture.json") continue;  // records the thread count among the options
    ASSERT_TRUE(fs::exists(tmp / "b" / rel)) << rel;
    EXPECT_EQ(bytes(entry.path()), bytes(tmp / "b" / rel)) << rel;
    ++compared;
  }
  EXPECT_GT(compared, 30);
}

TEST(Determinism, AnotherSeedGivesAnotherCapture) {
  tega::test::TempDir tmp;
  render_virtual_studio(tiny(7, 0), tmp / "a");
  render_virtual_studio(tiny(8, 0), tmp / "b");
  EXPECT_NE(bytes(tmp / "a/takes/expressions/cam00/000001.png"), bytes(tmp / "b/takes/expressions/cam00/000001.png"));
  EXPECT_NE(bytes(tmp / "a/takes/clean_plate/cam00/000000.png"), bytes(tmp / "b/takes/clean_plate/cam00/000000.png"));
  // The studio (rig) is the same whatever the seed.
  EXPECT_EQ(bytes(tmp / "a/rig.json"), bytes(tmp / "b/rig.json"));
}

}  // namespace
}  // namespace tega::synth
