// `tega status` on a pipeline whose Multiface ingest had to leave images out:
// the shard is done and its dataset's gaps are reported, in text and JSON.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "multiface_fixture.h"
#include "pipeline_test_support.h"
#include "test_support.h"

namespace tega::test {
namespace {
namespace fs = std::filesystem;
using json = nlohmann::json;

TEST(TegaStatus, ReportsTheImagesAnIngestedDatasetLacks) {
  TempDir dir;
  const MultifaceFixture fixture = write_multiface_fixture(dir / "capture");
  const std::string camera = fixture.ring[2];
  fs::remove(ingest::MultifaceCapture{fixture.root}.image(camera, fixture.frames[2]));
  write_text(dir / "p.yaml", "workspace: ws\nsubjects:\n  alice: {capture: " + fixture.root.string() +
                                 "}\nstages:\n  ingest:\n    kind: ingest_multiface\n    options: {width: 168, "
                                 "height: 256, frames: 4, test_frames: 0, matte_dilation_px: 3, "
                                 "matte_feather_px: 2, threads: 2}\n");
  const auto run = run_tega({"run", (dir / "p.yaml").string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.output;

  const auto text = run_tega({"status", (dir / "p.yaml").string()}, dir.path());
  ASSERT_EQ(text.exit_code, 0) << text.output;
  const std::string gaps = "1 missing image (" + camera + ": 1)";
  EXPECT_NE(text.output.find("dataset gaps: " + gaps), std::string::npos) << text.output;

  const auto as_json = run_tega({"status", (dir / "p.yaml").string(), "--json"}, dir.path());
  ASSERT_EQ(as_json.exit_code, 0) << as_json.output;
  const json shard = json::parse(as_json.output)["stages"][0]["shards"][0];
  EXPECT_EQ(shard["state"], "done") << shard;
  EXPECT_EQ(shard["dataset_gaps"], gaps) << shard;
}

}  // namespace
}  // namespace tega::test
