// Tests that need a private Linux namespace, made without root by
// `unshare -r`: 13 simulated GigE Vision cameras (arv-fake-gv-camera-0.8) on
// loopback aliases of a private network, and a small tmpfs that fills up.
// A PID namespace holds every process a test starts: when the script ends,
// the kernel stops whatever it left behind. Where namespaces are not
// allowed (some containers), the tests skip and say why.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_support.h"
#include "tega/core/take.h"
#include "test_support.h"

namespace tega::capture {
namespace {

namespace fs = std::filesystem;

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Why namespace tests cannot run here, or "" when they can: `probe` must
// succeed inside the namespace.
std::string namespaces_unavailable(const std::string& flags, const std::string& probe) {
  if (shell("unshare " + flags + " --pid --fork --kill-child sh -c '" + probe + "' > /dev/null 2>&1") != 0)
    return "unprivileged namespaces (unshare " + flags + " running: " + probe + ") are not allowed on this machine";
  return "";
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

int run_in_namespace(const std::string& flags, const fs::path& dir, const std::string& script) {
  test::write_text(dir / "script.sh", script);
  return shell("cd " + dir.string() + " && timeout 300 unshare " + flags +
               " --pid --fork --kill-child bash script.sh " + TEGA_EXECUTABLE + " > script.log 2>&1");
}

TEST(GigEVision, ThirteenSimulatedCamerasAreListedRecordedAndOneIsLostMidTake) {
  if (shell("command -v arv-fake-gv-camera-0.8 > /dev/null && command -v ip > /dev/null") != 0)
    GTEST_SKIP() << "arv-fake-gv-camera-0.8 (Debian aravis-tools) or ip (iproute2) is not installed";
  const auto why = namespaces_unavailable("-rn", "ip link set lo up && ip addr add 127.0.1.1/8 dev lo");
  if (!why.empty()) GTEST_SKIP() << why;
  test::TempDir dir;
  std::string rig =
      "source: aravis\n"
      "settings: {width: 256, height: 192, frame_rate: 10, packet_size: 8192, packet_socket: false}\n"
      "sync: {camera_timeout_ms: 1500}\n"
      "cameras:\n";
  for (int i = 1; i <= 13; ++i) {
    char line[64];
    std::snprintf(line, sizeof line, "  - {name: cam%02d, serial: GV%02d}\n", i - 1, i);
    rig += line;
  }
  test::write_text(dir / "rig.yaml", rig);
  // Camera i answers on 127.0.1.i; the fifth camera's process is killed 2 s into the second take's recording.
  const int status = run_in_namespace("-rn", dir.path(), R"(
set -u
tega=$1
ip link set lo up
cameras=()
for i in $(seq 1 13); do
  ip addr add 127.0.1.$i/8 dev lo
  arv-fake-gv-camera-0.8 -i 127.0.1.$i -s GV$(printf %02d $i) > /dev/null 2>&1 &
  cameras+=($!)
done
sleep 1
$tega capture list > list.txt 2>&1
$tega capture --rig rig.yaml --take gige --frames 10 --trigger software --out capture > gige.log 2>&1
echo $? > gige.rc
$tega capture --rig rig.yaml --take lost --seconds 6 --trigger software --out capture > lost.log 2>&1 &
recorder=$!
while [ ! -d capture/takes/lost.recording ]; do sleep 0.1; done
sleep 2
kill ${cameras[4]}
wait $recorder
echo $? > lost.rc
$tega capture validate --capture capture > validate.log 2>&1
echo $? > validate.rc
)");
  ASSERT_EQ(status, 0) << read_text(dir / "script.log");

  const std::string list = read_text(dir / "list.txt");
  for (int i = 1; i <= 13; ++i) {
    char expected[64];
    std::snprintf(expected, sizeof expected, "GV%02d             GigEVision 127.0.1.%d\n", i, i);
    EXPECT_NE(list.find(expected), std::string::npos) << list;
  }

  ASSERT_EQ(read_text(dir / "gige.rc"), "0\n") << read_text(dir / "gige.log");
  const TakeInfo gige = read_take(dir / "capture/takes/gige");
  EXPECT_EQ(gige.frames, 10);
  EXPECT_TRUE(gige.missing.empty());

  ASSERT_EQ(read_text(dir / "lost.rc"), "0\n") << read_text(dir / "lost.log");
  const TakeInfo lost = read_take(dir / "capture/takes/lost");
  const auto manifest = nlohmann::json::parse(read_text(dir / "capture/takes/lost/manifest.json"));
  ASSERT_FALSE(manifest["cameras"][4]["lost"].is_null()) << manifest.dump(2);
  const int from = manifest["cameras"][4]["lost"]["from_frame"];
  EXPECT_GT(from, 5);                 // it delivered for the first 2 s
  EXPECT_GT(lost.frames, from + 10);  // and the take went on without it for the rest
  ASSERT_EQ(lost.missing.count("cam04"), 1u);
  const auto& gap = lost.missing.at("cam04");
  ASSERT_EQ(gap.size(), size_t(lost.frames - from)) << "the gap runs from the loss to the end";
  EXPECT_EQ(gap.front(), from);
  EXPECT_EQ(lost.missing.size(), 1u) << "no other camera has a gap";
  EXPECT_NE(read_text(dir / "lost.log").find("camera cam04 lost"), std::string::npos);

  EXPECT_EQ(read_text(dir / "validate.rc"), "0\n") << read_text(dir / "validate.log");
  EXPECT_NE(shell("pgrep -f '[a]rv-fake-gv-camera-0.8 -i 127.0.1' > /dev/null"), 0) << "a simulated camera survived";
}

TEST(FullDisk, ATakeThatFillsItsDiskStopsAndStaysReadable) {
  test::TempDir dir;
  const auto why = namespaces_unavailable("-rm", "mount -t tmpfs -o size=1m tmpfs " + dir.path().string());
  if (!why.empty()) GTEST_SKIP() << why;
  // Uncompressed PNGs of 640x480 fill the 24 MB disk (16 MB of it held for the manifest) in about a second.
  test::write_text(dir / "rig.yaml",
                   "source: fake\n"
                   "settings: {width: 640, height: 480, frame_rate: 30}\n"
                   "writer: {png_compression: 0, min_free_mb: 0}\n"
                   "cameras: [{name: a, serial: D1}, {name: b, serial: D2}, {name: c, serial: D3}]\n");
  fs::create_directories(dir / "disk");
  const int status = run_in_namespace("-rm", dir.path(), R"(
set -u
tega=$1
mount -t tmpfs -o size=24m tmpfs disk || exit 3
$tega capture --rig rig.yaml --take full --seconds 30 --trigger free --out disk/capture > record.log 2>&1
echo $? > record.rc
$tega capture validate --capture disk/capture > validate.log 2>&1
echo $? > validate.rc
cp disk/capture/takes/full/take.json disk/capture/takes/full/manifest.json .
)");
  ASSERT_EQ(status, 0) << read_text(dir / "script.log");
  EXPECT_EQ(read_text(dir / "record.rc"), "1\n") << "a write error is a failed take";
  EXPECT_NE(read_text(dir / "record.log").find("No space left on device"), std::string::npos)
      << read_text(dir / "record.log");
  EXPECT_EQ(read_text(dir / "validate.rc"), "0\n") << read_text(dir / "validate.log");
  const auto take = nlohmann::json::parse(read_text(dir / "take.json"));
  EXPECT_GT(take["frames"].get<int>(), 3);
  const auto manifest = nlohmann::json::parse(read_text(dir / "manifest.json"));
  EXPECT_EQ(manifest["stop_reason"], "write error");
}

}  // namespace
}  // namespace tega::capture
