#pragma once
// The tracking-error model of the virtual studio's dataset
// (Options::tracking_error, docs/virtual-studio.md#tracking-errors): what a
// tracked mesh gets wrong, applied to the dataset's meshes only. Every error
// is a pure function of (seed, take, frame), so a dataset is reproducible
// whatever the thread count.

#include <cstdint>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"
#include "tega/synth/head.h"
#include "tega/synth/options.h"

namespace tega::synth {

// Throws tega::Error naming the option at fault.
void validate_tracking_error_options(const TrackingErrorOptions& options);

class TrackingError {
 public:
  // Throws tega::Error naming the option at fault.
  TrackingError(const Head& head, const TrackingErrorOptions& options, uint64_t seed);

  const TrackingErrorOptions& options() const { return options_; }
  bool enabled() const { return options_.enabled(); }

  // Where frame `frame` of a take looks for its (lagged) expression and pose:
  // frames `first` and `second` blended by `weight` (0: `first` only).
  struct LagSource {
    int first = 0, second = 0;
    double weight = 0;
  };
  LagSource lag_source(int frame, int frames) const;

  // The expression coefficients after the eyelid and lip misfit. `driven`:
  // the model expressions the performance sets (only those of them that are
  // lip expressions are perturbed; the blinks always are when present).
  std::vector<float> misfit(const std::vector<float>& expression, const std::vector<int>& driven,
                            const std::string& take, int frame) const;

  // The offset field of a frame, head space, V x 3 (zero without offset_m):
  // its RMS over the skin (non-eyeball) vertices is offset_m.
  Vertices offset(const std::string& take, int frame) const;
  // The shape misfit's displacement for these expression coefficients, head
  // space, V x 3 (zero without shape_misfit): each expression shape's motion of
  // a skin vertex scaled by shape_misfit times its gain field, summed with the
  // coefficients as weights.
  Vertices shape_error(const std::vector<float>& expression) const;
  // RMS and largest length of a displacement (offset, shape error) over the
  // skin (non-eyeball) vertices.
  double skin_rms(const Vertices& displacement) const;
  double skin_max(const Vertices& displacement) const;

 private:
  // The frame's draws: key frames `key` and `key + 1` blended by `weight`.
  void keys(int frame, int& key, double& weight) const;
  // A smooth random field of `components` values per vertex, face-frame
  // components: options_.offset_bumps Gaussian bumps of options_.offset_scale
  // centred in the skin's box, each with normal amplitudes; an eyeball's
  // vertices take its value at the eyeball's centre. RMS 1 over the skin.
  Eigen::MatrixXd smooth_draw(uint64_t seed, int key, int components) const;
  Eigen::MatrixXd offset_draw(uint64_t take_seed, int key) const;  // V x 3 head space, RMS 1 over the skin
  double skin_rms_of_rows(const Eigen::MatrixXd& rows) const;  // RMS of the skin vertices' row lengths

  const Head& head_;
  TrackingErrorOptions options_;
  uint64_t seed_;
  std::vector<int8_t> vertex_eye_;  // 0 skin, 1 left eyeball, 2 right eyeball
  Eigen::Vector3d box_min_, box_max_;  // the skin's neutral vertices, face frame
  int blink_left_ = -1, blink_right_ = -1;
  std::vector<char> is_lip_;  // per model expression: jaw* or mouth*
  std::vector<Eigen::VectorXd> shape_gains_;  // per model expression: g_e per vertex (0 on eyeballs)
};

// Rigid transform between a (weight 0) and b (weight 1): rotations by slerp,
// translations linearly. Returns a itself for weight 0.
RigidTransform interpolate_pose(const RigidTransform& a, const RigidTransform& b, double weight);

}  // namespace tega::synth
