#pragma once
// Options of template tracking (`tega track`, docs/tracking.md). Every term
// of the energy is a group of residuals, each divided by its `sigma` (the
// error one expects of a good fit) and the group scaled by
// sqrt(weight / count), so a weight is the term's share of the energy
// whatever the number of vertices, views or landmarks behind it.

#include <string>
#include <vector>

namespace tega::tracking {

// Point-to-plane distances from the model's fit vertices to the frame's
// multi-view stereo mesh (non-rigid ICP).
struct SurfaceTermOptions {
  double sigma_m = 0.0005;
  double weight = 1.0;
  double max_distance_m = 0.01;      // correspondences farther than this are dropped
  double final_distance_m = 0.003;   // ... the bound shrinks to this over the ICP iterations
  double max_normal_angle_deg = 60;  // ... and so are those whose normals disagree more
  double robust_scale = 3.0;         // Cauchy loss scale, in sigmas
  int coefficient_vertex_step = 2;   // pose and coefficients use every n-th fit vertex

  template <class V>
  void visit(V& v) {
    v("sigma_m", sigma_m, "Expected point-to-plane distance of a good fit, metres.");
    v("coefficient_vertex_step", coefficient_vertex_step,
      "Pose and coefficients are fitted to every n-th fit vertex (a few thousand pin down ~60 unknowns); the "
      "corrections use them all.");
    v("weight", weight, "Share of the energy of the surface term.");
    v("max_distance_m", max_distance_m, "Correspondences farther than this are dropped at the first ICP iteration.");
    v("final_distance_m", final_distance_m, "... and farther than this at the last (the bound shrinks linearly).");
    v("max_normal_angle_deg", max_normal_angle_deg,
      "Correspondences whose surface normals differ by more than this are dropped, degrees.");
    v("robust_scale", robust_scale, "Scale of the Cauchy loss, in sigmas: larger residuals count less.");
  }
};

// Image terms: where vertices must project in each camera.
struct ImageTermOptions {
  double sigma_px = 1.0;
  double weight = 0.5;
  double robust_scale = 3.0;

  template <class V>
  void visit(V& v) {
    v("sigma_px", sigma_px, "Expected reprojection error of a good fit, pixels of the captured image.");
    v("weight", weight, "Share of the energy of the term.");
    v("robust_scale", robust_scale, "Scale of the Cauchy loss, in sigmas.");
  }
};

// Multi-view optical flow between consecutive frames (OpenCV's DIS),
// back-projected through the rig, so that the surface does not slide.
struct FlowOptions {
  bool enabled = false;  // see docs/tracking.md: no gain on the studio's takes, 2-4x the time
  ImageTermOptions term{1.0, 0.3, 3.0};
  double max_forward_backward_px = 1.0;  // flow whose round trip misses by more is not trusted
  int vertex_step = 8;                   // every n-th fit vertex carries a flow target
  double max_image_side = 1024;          // images are downsampled to this before the flow

  template <class V>
  void visit(V& v) {
    v("enabled", enabled,
      "Use optical flow between consecutive frames (needs the take's images; off by default: docs/tracking.md "
      "gives the measurements).");
    v("term", term, "Weight and noise of the flow targets.");
    v("max_forward_backward_px", max_forward_backward_px,
      "Flow whose forward-backward round trip misses by more than this (pixels) is not used.");
    v("vertex_step", vertex_step, "Every n-th fit vertex carries a flow target in each camera that sees it.");
    v("max_image_side", max_image_side, "Images are downsampled so that their longer side is at most this for the flow.");
  }
};

// 2D landmarks from a user-supplied dlib 68-point shape predictor.
struct LandmarkOptions {
  std::string model;  // shape_predictor_68_face_landmarks.dat or one's own; empty = no landmarks
  ImageTermOptions term{2.0, 0.3, 3.0};
  int min_views = 2;  // landmarks seen in fewer views are not used for the first pose
  bool detector_boxes = false;  // dlib's face detector's boxes instead of the projected model's
  std::vector<int> ignored_points;  // 0-based 68-point indices left out of the per-frame term

  template <class V>
  void visit(V& v) {
    v("model", model, "A dlib 68-point shape predictor file (.dat); empty = track without landmarks.");
    v("term", term, "Weight and noise of the detected landmarks.");
    v("min_views", min_views, "Views a landmark needs to be triangulated for the first frame's pose.");
    v("detector_boxes", detector_boxes,
      "Find faces with dlib's frontal face detector (the boxes dlib's own predictor was trained on) instead of "
      "around the projected model's landmarks (the boxes train_landmark_predictor uses).");
    v("ignored_points", ignored_points,
      "Landmarks (0-based, iBUG 68-point numbering) the per-frame fit leaves out, e.g. [36, 37, ..., 47] for the "
      "eyelids with dlib's stock predictor, whose eye points do not follow closing lids (docs/tracking.md).");
  }
};

// Eyelid closure seen in the photos (docs/tracking.md#eyelids): the fraction
// of each open eye's eyeball that the photos show covered by skin, against
// what the model's lid covers at each value of the eye's blink shape.
struct EyelidOptions {
  bool enabled = true;
  std::vector<std::string> shapes = {"eyeBlink_L", "eyeBlink_R"};
  double sigma = 0.05;               // blink values outside the agreeing range cost (distance / sigma)^2
  double weight = 0.3;
  double tolerance = 0.03;           // covered fractions that differ by at most this agree
  double max_view_angle_deg = 45;    // cameras farther than this from the eye's front are not used
  int sample_step = 3;               // every n-th eyeball vertex is tested
  int min_samples = 30;              // an eye seen at fewer eyeball points is left out of the frame
  double skin_distance_factor = 1.5;  // a pixel is skin within this many times the skin's median colour spread
  double min_skin_distance = 12;      // ... and always within this colour distance

  template <class V>
  void visit(V& v) {
    v("enabled", enabled, "Fit each eye's blink to how much of the open eye the photos show covered by skin.");
    v("shapes", shapes,
      "The expression shapes that close the eyes (one per eye; each is paired with the eye whose skin it moves "
      "most).");
    v("sigma", sigma, "Blink values outside the range that agrees with the photos cost ((distance) / sigma)^2.");
    v("weight", weight, "Share of the energy of the eyelid term.");
    v("tolerance", tolerance,
      "The model's lid agrees with the photos when the fractions of the eye they cover differ by at most this.");
    v("max_view_angle_deg", max_view_angle_deg,
      "Cameras more than this many degrees from an eye's front are not used for it.");
    v("sample_step", sample_step, "Every n-th eyeball vertex is tested for being seen or covered.");
    v("min_samples", min_samples, "An eye seen at fewer eyeball points than this is left out of the frame.");
    v("skin_distance_factor", skin_distance_factor,
      "A pixel counts as skin when its colour lies within this many times the median colour spread of the skin "
      "around the eye ...");
    v("min_skin_distance", min_skin_distance,
      "... or within this distance of its median colour (chromaticity in 8-bit levels, brightness 40 levels per "
      "e-fold).");
  }
};

// Priors on the blendshape coefficients and the pose.
struct CoefficientOptions {
  double expression_sigma = 1.0;      // prior towards 0 (the neutral face)
  double expression_temporal_sigma = 0.3;  // frame-to-frame change
  double identity_sigma = 1.0;        // prior towards 0 (the model's mean), in the model's units
  double rotation_temporal_sigma_deg = 3.0;
  double translation_temporal_sigma_m = 0.005;
  double weight = 0.05;               // share of the energy of these priors
  int solver_iterations = 5;          // Levenberg-Marquardt iterations per ICP iteration

  template <class V>
  void visit(V& v) {
    v("expression_sigma", expression_sigma, "Prior on each expression coefficient towards 0.");
    v("expression_temporal_sigma", expression_temporal_sigma, "Expected change of a coefficient from one frame to the next.");
    v("identity_sigma", identity_sigma, "Prior on each identity coefficient towards 0 (the model's mean head).");
    v("rotation_temporal_sigma_deg", rotation_temporal_sigma_deg, "Expected head rotation between frames, degrees.");
    v("translation_temporal_sigma_m", translation_temporal_sigma_m, "Expected head translation between frames, metres.");
    v("weight", weight, "Share of the energy of the priors.");
    v("solver_iterations", solver_iterations, "Levenberg-Marquardt iterations per ICP iteration.");
  }
};

// Per-vertex corrections on top of the blendshapes, held smooth by a
// Laplacian (membrane) term: the identity's detail once, on all the skin;
// then each frame's detail, on the fit vertices.
struct CorrectionOptions {
  bool enabled = true;
  double smoothness_sigma_m = 0.0002;  // expected difference of neighbouring corrections
  double magnitude_sigma_m = 0.005;    // corrections are small
  double temporal_sigma_m = 0.0005;    // a frame's corrections stay near the previous frame's
  double weight = 1.0;                 // share of the energy of the smoothness term
  int iterations = 1;                  // correspondence updates per frame (the identity's detail gets one more)
  int solver_iterations = 3;           // Levenberg-Marquardt iterations per correspondence update

  template <class V>
  void visit(V& v) {
    v("enabled", enabled, "Fit per-vertex corrections after the blendshape coefficients.");
    v("smoothness_sigma_m", smoothness_sigma_m, "Expected difference between neighbouring vertices' corrections, metres.");
    v("magnitude_sigma_m", magnitude_sigma_m, "Expected size of a correction, metres.");
    v("temporal_sigma_m", temporal_sigma_m, "Expected change of a frame's corrections from the previous frame's, metres.");
    v("weight", weight, "Share of the energy of the smoothness term.");
    v("iterations", iterations,
      "Correspondence updates while fitting a frame's corrections (the identity's detail gets one more).");
    v("solver_iterations", solver_iterations, "Levenberg-Marquardt iterations per correspondence update.");
  }
};

// When a frame is fitted a second time, from scratch: the warm-started fit
// moved the head this far from the previous frame (a fast move, or frames
// that are key poses rather than video).
struct FreshStartOptions {
  double rotation_deg = 2.0;
  double translation_m = 0.005;

  template <class V>
  void visit(V& v) {
    v("rotation_deg", rotation_deg,
      "A frame whose fit turned the head more than this from the previous frame (degrees) is also fitted from a "
      "fresh first pose and a neutral face; the fit nearer the scan is kept.");
    v("translation_m", translation_m, "... or moved it more than this, metres.");
  }
};

struct Options {
  std::string model;     // the head model directory
  std::string identity;  // an identity.json to reuse; empty: fit one
  double model_metres_per_unit = 0.01;
  std::vector<int> identity_frames = {0};
  SurfaceTermOptions surface;
  FlowOptions flow;
  LandmarkOptions landmarks;
  EyelidOptions eyelids;
  CoefficientOptions coefficients;
  CorrectionOptions corrections;
  int icp_iterations = 5;
  FreshStartOptions fresh_start;
  double min_inlier_fraction = 0.6;  // a frame whose fit vertices find the mesh less often fails
  double max_median_distance_m = 0.003;  // ... or whose median distance to it is larger
  int photo_max_side = 1536;            // the image terms read photos at a whole fraction of their size within this
  int report_overlays = 3;              // frames of each take drawn over the photos in the report
  int threads = 0;

  template <class V>
  void visit(V& v) {
    v("model", model,
      "The head model directory: ICT-FaceKit's layout (generic_neutral_mesh.obj, identityNNN.obj, expression "
      "shapes) with vertex_indices.json.");
    v("identity", identity, "An identity.json from an earlier run of this subject to reuse; empty = fit the identity.");
    v("model_metres_per_unit", model_metres_per_unit, "Units of the model directory's files (ICT-FaceKit: 0.01, cm).");
    v("identity_frames", identity_frames,
      "Frames of the first take, with a neutral face, that the subject's identity is fitted to.");
    v("surface", surface, "The surface (non-rigid ICP) term.");
    v("flow", flow, "The optical-flow term.");
    v("landmarks", landmarks, "The 2D landmark term.");
    v("eyelids", eyelids, "The eyelid term: blinks seen in the photos.");
    v("coefficients", coefficients, "Priors on the coefficients and the pose.");
    v("corrections", corrections, "Per-vertex corrections.");
    v("icp_iterations", icp_iterations, "Correspondence updates while fitting pose and coefficients.");
    v("fresh_start", fresh_start, "When a frame is fitted again from scratch (besides when its fit is rejected).");
    v("min_inlier_fraction", min_inlier_fraction,
      "A frame fails (is recorded, not written) when fewer of its fit vertices than this find the mesh.");
    v("max_median_distance_m", max_median_distance_m,
      "... or when their median distance to the mesh is larger than this, metres.");
    v("photo_max_side", photo_max_side,
      "The image terms (landmarks, eyelids, flow) read the photos downsampled by the smallest whole factor that "
      "brings their longer side to at most this many pixels (0: full size).");
    v("report_overlays", report_overlays, "Frames of each take drawn over the photos in the take's report.");
    v("threads", threads, "Worker threads (0: one per hardware thread).");
  }
};

}  // namespace tega::tracking
