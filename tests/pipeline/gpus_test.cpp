#include "tega/pipeline/gpus.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "test_support.h"

namespace tega::pipeline {
namespace {

using Gpus = std::vector<std::string>;

TEST(Gpus, ParsesAListOfIndicesOrUuids) {
  EXPECT_EQ(parse_gpu_list("0,1,3", "--gpus"), (Gpus{"0", "1", "3"}));
  EXPECT_EQ(parse_gpu_list("GPU-8a1c,MIG-2", "--gpus"), (Gpus{"GPU-8a1c", "MIG-2"}));
  EXPECT_EQ(parse_gpu_list("", "--gpus"), Gpus{});
}

TEST(Gpus, RefusesEmptyOrRepeatedEntriesNamingWhereTheyCameFrom) {
  for (const char* bad : {"0,,1", "0,", ",1", "0, 1"}) {
    try {
      parse_gpu_list(bad, "--gpus");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("--gpus"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(parse_gpu_list("2,0,2", "--gpus"), Error);
}

TEST(Gpus, TheMachinesAreThoseCudaVisibleDevicesLeavesElseTheDriversElseNone) {
  test::TempDir driver;
  for (const char* bus : {"0000:17:00.0", "0000:65:00.0", "0000:ca:00.0"}) std::filesystem::create_directory(driver / bus);
  EXPECT_EQ(machine_gpus("4,5", driver.path()), (Gpus{"4", "5"}));
  EXPECT_EQ(machine_gpus("", driver.path()), Gpus{});  // CUDA_VISIBLE_DEVICES= hides every GPU
  EXPECT_EQ(machine_gpus(std::nullopt, driver.path()), (Gpus{"0", "1", "2"}));
  EXPECT_EQ(machine_gpus(std::nullopt, driver / "absent"), Gpus{});
}

TEST(Gpus, AChildIsPinnedToTheGpuThisProcessNumbersSo) {
  EXPECT_EQ(child_visible_device("1", std::string("4,6,7"), "--gpus"), "6");  // this process's device 1
  EXPECT_EQ(child_visible_device("0", std::string("GPU-8a1c,GPU-22"), "--gpus"), "GPU-8a1c");
  EXPECT_EQ(child_visible_device("GPU-22", std::string("GPU-8a1c,GPU-22"), "--gpus"), "GPU-22");
  EXPECT_EQ(child_visible_device("3", std::nullopt, "--gpus"), "3");  // nothing hidden: the machine's 3
  try {
    child_visible_device("2", std::string("4,6"), "tega train --gpus");
    ADD_FAILURE() << "device 2 of two was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("tega train --gpus: GPU 2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("CUDA_VISIBLE_DEVICES=4,6"), std::string::npos) << e.what();
  }
  EXPECT_THROW(child_visible_device("0", std::string(""), "--gpus"), Error);  // every GPU hidden
}

}  // namespace
}  // namespace tega::pipeline
