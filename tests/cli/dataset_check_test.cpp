#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>

#include "cli_support.h"
#include "tega/core/files.h"
#include "test_support.h"

namespace {

using tega::test::run_tega;

TEST(CliDatasetCheck, NotADatasetFailsNamingTheDirectory) {
  tega::test::TempDir tmp;
  const auto r = run_tega("dataset check --data " + tmp.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find(tmp.path().string() + ": is not a tega dataset"), std::string::npos) << r.output;
}

TEST(CliDatasetCheck, MalformedManifestFailsNamingTheFile) {
  tega::test::TempDir tmp;
  tega::test::write_text(tmp / "dataset.json", "{ not json");
  const auto r = run_tega("dataset check --data " + tmp.path().string());
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("dataset.json: is not valid JSON"), std::string::npos) << r.output;
}

TEST(CliDatasetCheck, ReportsRecordedGapsAndFailsOnAnUnrecordedOne) {
  tega::test::TempDir tmp;
  tega::test::write_tiny_dataset(tmp.path());
  const auto image = tmp / "images/cam01/smile_000000.png";
  std::filesystem::remove(image);
  const auto unrecorded = run_tega("dataset check --data " + tmp.path().string());
  EXPECT_EQ(unrecorded.exit_code, 1) << unrecorded.output;
  EXPECT_NE(unrecorded.output.find(image.string() + ": is missing"), std::string::npos) << unrecorded.output;

  auto manifest = nlohmann::json::parse(tega::read_text_file(tmp / "dataset.json"));
  manifest["missing_images"] = {{{"camera", "cam01"}, {"frame", "smile_000000"}, {"reason", "cam01.png: is missing"}}};
  tega::write_text_atomic(tmp / "dataset.json", manifest.dump());
  const auto recorded = run_tega("dataset check --data " + tmp.path().string());
  EXPECT_EQ(recorded.exit_code, 0) << recorded.output;
  EXPECT_NE(recorded.output.find(": ok: 2 frames"), std::string::npos) << recorded.output;
  EXPECT_NE(recorded.output.find("gaps (training and evaluation skip them): 1 missing image (cam01: 1)"),
            std::string::npos)
      << recorded.output;
  EXPECT_NE(recorded.output.find("missing images per frame: smile_000000: 1"), std::string::npos) << recorded.output;
  EXPECT_NE(recorded.output.find("missing image: camera cam01, frame smile_000000: cam01.png: is missing"),
            std::string::npos)
      << recorded.output;
}

}  // namespace
