// `tega capture` as an operator runs it: Ctrl-C finalises the take, the
// preview contact sheet, `check`, and bad input.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <thread>

#include "cli_support.h"
#include "tega/core/image.h"
#include "tega/core/take.h"
#include "test_support.h"

namespace tega::capture {
namespace {

namespace fs = std::filesystem;

const char* kRig =
    "source: fake\n"
    "settings: {width: 96, height: 64, frame_rate: 30}\n"
    "cameras: [{name: a, serial: C1}, {name: b, serial: C2}, {name: c, serial: C3}]\n";

TEST(CaptureCommand, CtrlCFinalisesTheTakeAndThePreviewShowsTheLatestFrameSet) {
  test::TempDir dir;
  test::write_text(dir / "rig.yaml", kRig);
  const std::vector<std::string> args = {TEGA_EXECUTABLE, "capture", "--rig", (dir / "rig.yaml").string(),
                                         "--take", "open", "--out", (dir / "capture").string(),
                                         "--trigger", "free", "--preview", (dir / "preview.png").string()};
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, (dir / "out.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  pid_t pid = 0;
  ASSERT_EQ(posix_spawn(&pid, argv[0], &files, nullptr, argv.data(), environ), 0);
  posix_spawn_file_actions_destroy(&files);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!fs::exists(dir / "preview.png") && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  kill(pid, SIGINT);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "Ctrl-C must finalise the take, not kill the process";
  EXPECT_EQ(WEXITSTATUS(status), 0);

  const TakeInfo take = read_take(dir / "capture/takes/open");
  EXPECT_GT(take.frames, 30);  // the preview appears after 3 s at 30 fps
  validate_capture(dir / "capture");
  // Three 96x64 cameras: a 2x2 grid of tiles, the fourth black.
  const Image8 preview = read_image_u8(dir / "preview.png");
  EXPECT_EQ(preview.width, 192);
  EXPECT_EQ(preview.height, 128);
  EXPECT_EQ(preview.at(150, 100, 0), 0);
  EXPECT_NE(preview.at(30, 20, 0) + preview.at(40, 20, 0), 0);
}

TEST(CaptureCommand, CheckReportsEveryCameraAndTheFrameSet) {
  test::TempDir dir;
  test::write_text(dir / "rig.yaml", kRig);
  const auto r = test::run_tega("capture check --trigger free --rig " + (dir / "rig.yaml").string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("\"frame_set_spread_ms\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("\"region\": \"96x64+0+0\""), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("serial C3"), std::string::npos) << r.output;
}

TEST(CaptureCommand, BadInputIsNamedAndNothingIsWritten) {
  test::TempDir dir;
  auto r = test::run_tega("capture --take t --out " + (dir / "capture").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--rig is required"), std::string::npos) << r.output;

  test::write_text(dir / "typo.yaml", std::string(kRig) + "sync: {tolerence_ms: 3}\n");
  r = test::run_tega("capture --take t --rig " + (dir / "typo.yaml").string() + " --out " + (dir / "capture").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("typo.yaml"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("sync.tolerence_ms"), std::string::npos) << r.output;

  test::write_text(dir / "wide.yaml", std::string(kRig) + "writer: {format: jpeg}\n");
  r = test::run_tega("capture --take t --rig " + (dir / "wide.yaml").string() + " --out " + (dir / "capture").string());
  EXPECT_NE(r.output.find("writer.format must be png or tiff"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir / "capture/takes/t"));
}

}  // namespace
}  // namespace tega::capture
