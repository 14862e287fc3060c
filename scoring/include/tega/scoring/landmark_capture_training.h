#pragma once
// A landmark predictor trained on virtual-studio captures (`tega landmarks
// train`, docs/tracking.md#training-a-predictor-on-studio-captures): the
// photos of each capture's performance takes, with the true landmarks of
// landmark_studio_truth.h, chosen by take, camera, view angle and frame.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/landmarks/landmarks.h"

namespace tega::scoring {

// Which photos of a capture become samples.
struct LandmarkSamplingOptions {
  std::vector<std::string> takes;    // empty: every performance take
  std::vector<std::string> cameras;  // empty: every camera of the rig
  double max_view_angle_deg = 35;
  int frame_stride = 1;

  template <class V>
  void visit(V& v) {
    v("takes", takes, "Performance takes to sample (empty: every performance take).");
    v("cameras", cameras, "Cameras to sample (empty: every camera of the rig).");
    v("max_view_angle_deg", max_view_angle_deg,
      "A photo is used when its camera lies within this angle of the face's front in that frame, degrees "
      "(the 68-point markup is for faces seen from the front; the head turns within a take).");
    v("frame_stride", frame_stride, "Every n-th frame of each take, from frame 0.");
  }
};

// Options of `tega landmarks train`.
struct LandmarkPredictorOptions {
  std::string model;  // empty: the head model each capture rendered
  LandmarkSamplingOptions sampling;
  bool hold_out = true;
  landmarks::LandmarkTrainingOptions training;

  template <class V>
  void visit(V& v) {
    v("model", model,
      "Head model directory whose vertex_indices.json lists the 68 landmark vertices (idx_to_landmark_verts); "
      "empty: the model each capture was rendered with (its ground_truth/head/head.json's source).");
    v("sampling", sampling, "Which photos of each capture are samples.");
    v("hold_out", hold_out,
      "Keep every other sampled frame of the last capture (at frame_stride 1 its odd frames) out of training "
      "and report the predictor's error on them.");
    v("training", training, "dlib's shape_predictor_trainer.");
  }
};

// One photo of a capture as a sample.
struct CaptureLandmarkSample {
  std::string take, camera;
  int frame = 0;
  int frame_position = 0;  // which sampled frame of its take: 0, 1, 2, ...
  landmarks::LandmarkSample sample;
};

// Throws tega::Error naming the capture's file that is missing or malformed,
// or capture.json / rig.json for a take or camera it does not have; and for
// options out of range.
std::vector<CaptureLandmarkSample> capture_landmark_samples(const std::filesystem::path& capture,
                                                            const std::vector<int>& landmark_vertices,
                                                            const LandmarkSamplingOptions& options);

struct LandmarkPredictorSummary {
  std::vector<int> samples_per_capture;  // trained on
  int held_out_images = 0;
  int held_out_landmarks = 0;  // known (not hidden) landmarks scored
  double held_out_median_px = 0, held_out_p95_px = 0;
  double training_seconds = 0;
};

// Trains on every capture's samples (but the held-out ones) and writes the
// predictor to `out` atomically; prints progress. Throws tega::Error naming
// the offending file.
LandmarkPredictorSummary train_landmark_predictor_on_captures(const std::vector<std::filesystem::path>& captures,
                                                              const LandmarkPredictorOptions& options,
                                                              const std::filesystem::path& out);

}  // namespace tega::scoring
