#pragma once
// Tracking scored against the virtual studio's ground truth
// (docs/virtual-studio.md): per-vertex error over the face region (what two
// of the true cameras see of the face in each frame), head rotation error,
// and how the expression coefficients follow the true ones.
// The studio's head shares the model's vertex numbering below its
// see-through eye overlays (which it removes), where the face lies.

#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/mesh.h"

namespace tega::scoring {

class StudioTruthSource;

struct TrackScores {
  int frames = 0;                         // tracked frames scored
  double vertex_median_m = 0, vertex_p95_m = 0;  // over the face region's vertices of every scored frame
  // How far the tracked head is turned from the true head: head_to_world
  // against the truth's in one head frame, the fitted subject's neutral
  // rigidly aligned onto the true one over the face region (without a fitted
  // neutral, each pose as it is). A head's pose is relative to its subject's
  // neutral, and a head model whose identity shapes turn the face
  // (ICT-FaceKit's do) would otherwise report every error of the fitted
  // identity coefficients as a turn of every pose, one the meshes do not have.
  double rotation_median_deg = 0, rotation_max_deg = 0;
  // With the fitted neutral (NaN without one): the turn that alignment
  // takes out, and the poses' error as they are, each relative to its own
  // subject's neutral.
  double subject_rotation_deg = std::numeric_limits<double>::quiet_NaN();
  double pose_rotation_median_deg = std::numeric_limits<double>::quiet_NaN();
  std::map<std::string, double> correlation;  // per true expression that varies: Pearson r over the frames
};

// Whether an expression's correlation has a target (r >= 0.9, docs/tracking.md):
// the eyelids' (eyeBlink_*) and the jaw's (jaw*), which the images must move;
// the rest (brows, smiles) are reported without one.
bool has_correlation_target(const std::string& expression);

// The studio's ground truth in tega track's layout (docs/layouts.md#tracked-meshes):
// its template as the subject (identity.json, identity_neutral.obj) and the
// true coarse meshes and poses as tracked frames of `takes` (empty: every
// performance take). Stages after tracking are tested on it apart from the
// tracker's own error. `truth_to_world` moves the meshes and poses into the
// world of another rig (a calibrated one: where tracking with it puts them).
// `out` must not exist.
void write_studio_truth_as_tracked(const std::filesystem::path& capture, const std::filesystem::path& out,
                                   const std::vector<std::string>& takes = {},
                                   const RigidTransform& truth_to_world = {});

// One tracked frame to score.
struct ScoredFrame {
  int frame = 0;
  Vertices vertices;              // world space, the model's topology
  Eigen::Matrix3d head_rotation;  // of head_to_world
  std::map<std::string, double> expression;
};

// The truth of one take of a studio capture with ground_truth/, loaded once
// to score any number of sets of tracked frames.
class TakeTruth {
 public:
  TakeTruth(const std::filesystem::path& capture, const std::string& take);
  ~TakeTruth();
  const std::string& take() const { return take_; }
  // `subject_neutral`: the tracked subject's neutral (head space, the model's topology), or null.
  TrackScores score(const std::vector<ScoredFrame>& frames, const Vertices* subject_neutral = nullptr) const;

 private:
  // The studio's face region in a frame, its head's numbering: what two
  // true cameras see of the face (StudioTruthSource), found on first use.
  const std::vector<int>& face_vertices(int frame) const;

  std::filesystem::path frames_file_;
  std::string take_;
  std::unique_ptr<const StudioTruthSource> studio_;
  mutable std::map<int, std::vector<int>> face_vertices_;  // by frame
  std::vector<int> model_vertex_;        // the model's vertex of each of the studio head's
  Vertices neutral_;                     // the true subject's neutral, head space, the studio head's numbering
  std::map<int, Eigen::Matrix3d> rotation_;                         // by frame
  std::map<int, std::map<std::string, double>> expression_;        // by frame
  std::map<int, Vertices> coarse_;                                  // by frame: the true mesh
};

// The tracked frames of TRACKED/<take> (and the subject of TRACKED/identity_neutral.obj,
// where there is one); `capture`: the studio's capture with ground_truth/.
// `tracked_to_truth` moves the tracked meshes and poses from the world of the rig tracking used (a
// calibrated rig has its own, its first camera's by default) into the studio's.
TrackScores score_against_studio(const std::filesystem::path& tracked, const std::filesystem::path& capture,
                                 const std::string& take, const RigidTransform& tracked_to_truth = {});
// The same against a truth already loaded, which keeps the face regions it
// found: for scoring several trackings of one take.
TrackScores score_against_studio(const std::filesystem::path& tracked, const TakeTruth& truth,
                                 const RigidTransform& tracked_to_truth = {});

}  // namespace tega::scoring
