#include <dlib/image_processing.h>
#include <dlib/serialize.h>

#include <iostream>
#include <string>

#include "dlib_conversions.h"
#include "mirroring.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/thread_pool.h"
#include "tega/landmarks/landmarks.h"

namespace tega::landmarks {

namespace {

void check_training_input(const std::vector<LandmarkSample>& samples, const LandmarkTrainingOptions& options,
                          const std::filesystem::path& out) {
  const auto fail = [&](const std::string& what) { throw Error(out, "cannot train a landmark predictor: " + what); };
  if (samples.empty()) fail("no training samples");
  if (options.cascade_depth < 1 || options.tree_depth < 1 || options.trees_per_cascade_level < 1 ||
      options.oversampling < 1)
    fail("cascade_depth, tree_depth, trees_per_cascade_level and oversampling must be 1 or more");
  if (!(options.nu > 0 && options.nu <= 1)) fail("nu must lie in (0, 1], got " + std::to_string(options.nu));
  if (options.threads < 0) fail("threads must be 0 (one per hardware thread) or more");
  std::vector<bool> landmark_seen(kLandmarkCount, false);
  for (size_t i = 0; i < samples.size(); ++i) {
    const LandmarkSample& sample = samples[i];
    const std::string name = "sample " + std::to_string(i);
    if (sample.landmarks.size() != kLandmarkCount)
      fail(name + " has " + std::to_string(sample.landmarks.size()) + " landmarks, not " +
           std::to_string(kLandmarkCount));
    if (sample.image.empty()) fail(name + " has no image");
    if (sample.box.isEmpty() || sample.box.sizes().minCoeff() < 1) fail(name + " has an empty face box");
    for (int j = 0; j < kLandmarkCount; ++j)
      if (sample.landmarks[j].allFinite()) landmark_seen[j] = true;
  }
  for (int j = 0; j < kLandmarkCount; ++j)
    if (!landmark_seen[j]) fail("landmark " + std::to_string(j) + " is unknown in every sample");
}

// dlib prints its progress to std::cout, and stdout is for results: for as
// long as it lives, what goes to std::cout goes to stderr.
class ProgressToStderr {
 public:
  explicit ProgressToStderr(bool active) : previous_(active ? std::cout.rdbuf(std::cerr.rdbuf()) : nullptr) {}
  ~ProgressToStderr() {
    if (previous_) std::cout.rdbuf(previous_);
  }
  ProgressToStderr(const ProgressToStderr&) = delete;
  ProgressToStderr& operator=(const ProgressToStderr&) = delete;

 private:
  std::streambuf* previous_;
};

int worker_threads(int requested) {
  return requested > 0 ? requested : default_thread_count();
}

}  // namespace

void train_landmark_predictor(const std::vector<LandmarkSample>& samples, const LandmarkTrainingOptions& options,
                              const std::filesystem::path& out) {
  check_training_input(samples, options, out);
  dlib::array<dlib::array2d<unsigned char>> images;
  std::vector<std::vector<dlib::full_object_detection>> shapes;
  const auto add = [&](const LandmarkSample& sample) {
    images.push_back(to_dlib_grey(sample.image));
    shapes.push_back({to_dlib_shape(sample.box, sample.landmarks)});
  };
  for (const LandmarkSample& sample : samples) {
    add(sample);
    if (options.add_mirrored_samples) add(mirrored(sample));
  }

  dlib::shape_predictor_trainer trainer;
  trainer.set_cascade_depth(options.cascade_depth);
  trainer.set_tree_depth(options.tree_depth);
  trainer.set_num_trees_per_cascade_level(options.trees_per_cascade_level);
  trainer.set_oversampling_amount(options.oversampling);
  trainer.set_nu(options.nu);
  trainer.set_num_threads(worker_threads(options.threads));
  if (options.print_progress) trainer.be_verbose();
  const ProgressToStderr progress_to_stderr(options.print_progress);
  dlib::shape_predictor predictor;
  try {
    predictor = trainer.train(images, shapes);
  } catch (const std::exception& e) {
    throw Error(out, std::string("training the landmark predictor failed: ") + e.what());
  }
  write_file_atomic(out, [&](const std::filesystem::path& temp) { dlib::serialize(temp.string()) << predictor; });
}

}  // namespace tega::landmarks
