#pragma once
// OpenCV's own worker threads, off while the stage's workers run: they
// parallelise over images already, and OpenCV splitting each resize, remap or
// filter across the same cores only adds contention (about 10 % of a dataset
// build on 2 cores). Process-wide, restored on destruction.

#include <opencv2/core/utility.hpp>

namespace tega::matting {

class OpenCvSingleThreaded {
 public:
  OpenCvSingleThreaded() : previous_(cv::getNumThreads()) { cv::setNumThreads(1); }
  ~OpenCvSingleThreaded() { cv::setNumThreads(previous_); }
  OpenCvSingleThreaded(const OpenCvSingleThreaded&) = delete;
  OpenCvSingleThreaded& operator=(const OpenCvSingleThreaded&) = delete;

 private:
  int previous_;
};

}  // namespace tega::matting
