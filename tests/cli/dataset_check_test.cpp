#include <gtest/gtest.h>

#include "cli_support.h"
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

}  // namespace
