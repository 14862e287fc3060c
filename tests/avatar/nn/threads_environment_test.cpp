// Not a test: registers a GoogleTest environment for tega_nn_tests (the file
// name only has to match the *_test.cpp glob). libtorch defaults to one
// thread here; CI has two cores. A fixed seed makes every run of a test see
// the same random inputs.
#include <ATen/Context.h>
#include <ATen/Parallel.h>
#include <gtest/gtest.h>

namespace {

class TorchThreads : public ::testing::Environment {
 public:
  void SetUp() override {
    at::set_num_threads(2);
    at::manual_seed(0);
  }
};

const auto* const registered = ::testing::AddGlobalTestEnvironment(new TorchThreads);

}  // namespace
