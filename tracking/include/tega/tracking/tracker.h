#pragma once
// Fitting the head model to frames (docs/tracking.md): a subject's identity
// once, then every frame of a take in order, each warm-started from the one
// before. A posed vertex is
//   X_v = R (neutral_v + sum_j b_j expression_j[v] + c_v) + t,
// with the subject's neutral (model neutral + identity shapes + identity
// detail), expression coefficients b in [0, 1], per-vertex corrections c on
// the skin and the head pose (R, t) = head_to_world.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/tracking/head_model.h"
#include "tega/tracking/options.h"

namespace tega::landmarks {
class LandmarkDetector;
}

namespace tega::tracking {

class SurfaceQuery;
struct ModelEyes;

struct SubjectIdentity {
  std::vector<double> coefficients;  // one per identity shape of the model
  Vertices neutral;                  // head space
  // Per blink shape: the fraction of the open eye that the identity frames'
  // photos show as skin (lashes, the lid's rim, pixels the model's aperture
  // misses); the eyelid term measures closing from there.
  std::map<std::string, double> open_eyes_covered;
};

struct HeadState {
  RigidTransform head_to_world;
  std::vector<double> expression;  // one per expression shape of the model
  Vertices corrections;            // V x 3, head space; zero off the skin
};

// How well a frame fits, for the record and for rejecting bad frames.
struct FrameResiduals {
  double surface_median_m = 0, surface_p90_m = 0;  // fit vertices to the scan, where they found it
  double inlier_fraction = 0;                     // fit vertices that found the scan
  // Mean distance over all fit vertices, those that did not find the scan
  // counted at the bound: one number that neither a fit holding fewer
  // vertices nor one holding them loosely can win on (fits of a frame are
  // compared by it).
  double surface_capped_mean_m = 0;
  double landmark_rms_px = -1;                    // -1: no landmarks
  int landmark_count = 0;
  double flow_rms_px = -1;                        // -1: no flow
  int flow_count = 0;
  // Per blink shape: the fraction of the open eye the photos show covered
  // by skin (eyes the cameras did not see are absent).
  std::map<std::string, double> eyelids_covered;
};

// A frame's observations: its multi-view stereo mesh (world space) and,
// for the image terms, every rig camera's photo as recorded (8-bit RGB,
// distorted; an empty image where a camera has none).
struct FrameObservation {
  const Mesh* scan = nullptr;
  std::vector<Image8> images;
};

// Where a frame's time went, seconds.
struct FrameTimings {
  double image_terms_s = 0;   // optical flow, landmarks and eyelids
  double coefficients_s = 0;  // pose and expression (correspondences included)
  double corrections_s = 0;   // per-vertex corrections (correspondences included)
};

struct FrameFit {
  HeadState state;
  Vertices vertices;  // world space, the model's topology
  FrameResiduals residuals;
  FrameTimings timings;
  bool fitted_afresh = false;  // from a fresh first pose, though an earlier frame was there to start from
};

// World-space vertices of the model in `state`.
Vertices pose_vertices(const HeadModel& model, const SubjectIdentity& subject, const HeadState& state);

// A head-to-world pose to start from where no earlier frame gives one: from
// triangulated landmarks when a detector is given and finds the face in two
// or more views, else from the scan's extent and the cameras (the face looks
// towards the cameras, upright as they are), refined by rigid ICP.
RigidTransform initial_pose(const HeadModel& model, const Vertices& neutral, const FrameObservation& frame,
                            const std::vector<Camera>& cameras, const Options& options,
                            const landmarks::LandmarkDetector* landmarks);

// Fits the subject (identity coefficients, then per-vertex detail) to
// frames showing a neutral face. Throws tega::Error when it cannot.
SubjectIdentity fit_identity(const HeadModel& model, const std::vector<FrameObservation>& frames,
                             const std::vector<Camera>& cameras, const Options& options,
                             const landmarks::LandmarkDetector* landmarks);

// Tracks the frames of one take in order.
class TakeTracker {
 public:
  TakeTracker(const HeadModel& model, const SubjectIdentity& subject, std::vector<Camera> cameras,
              const Options& options, const landmarks::LandmarkDetector* landmarks);
  ~TakeTracker();

  // Fits the next frame, warm-started from the last accepted one. Where
  // that fit is rejected or has moved the head farther than
  // options.fresh_start allows, the frame is fitted again from a fresh first
  // pose and a neutral face, and the fit nearer the scan is returned. The
  // caller decides whether to accept() it (see rejection()).
  FrameFit track(const FrameObservation& frame);
  // Whether a fit is good enough to keep; the reason when it is not.
  std::optional<std::string> rejection(const FrameFit& fit) const;
  // Makes `fit` the frame the next one starts from; `frame` keeps its images
  // and scan for the flow term.
  void accept(const FrameFit& fit, const FrameObservation& frame);
  // Starts from a state read back from disk (resuming); no flow to the next frame.
  void resume_from(const HeadState& state);
  // The next frame does not follow the last accepted one (a gap): no flow.
  void break_sequence();

 private:
  struct Previous;
  // One fit of the frame: from `previous`, or afresh (initial_pose() and a
  // neutral face) where it is null.
  FrameFit fit(const FrameObservation& frame, const Previous* previous) const;
  bool moved_far(const FrameFit& fit) const;
  const HeadModel& model_;
  const SubjectIdentity& subject_;
  std::vector<Camera> cameras_;
  Options options_;
  const landmarks::LandmarkDetector* landmarks_;
  std::vector<std::pair<int, int>> fit_edges_;
  std::unique_ptr<ModelEyes> eyes_;  // null: no eyelid term
  std::unique_ptr<Previous> previous_;
};

}  // namespace tega::tracking
