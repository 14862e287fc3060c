#pragma once
// Options of the virtual studio (`tega synth`). Defaults equal
// studio_configs/studio13.yaml, which a test keeps in sync.

#include <cstdint>
#include <string>
#include <vector>

namespace tega::synth {

// The camera rig: cameras spread evenly over a spherical cap in front of the
// head, all looking at the head's centre.
struct StudioOptions {
  int cameras = 13;
  int width = 512;
  int height = 384;
  double distance_m = 1.0;
  double focal_length_mm = 70.0;
  double sensor_width_mm = 36.0;
  double cap_half_angle_deg = 60.0;
  std::vector<double> distortion = {-0.06, 0.09, 0.0004, -0.0003, 0.0};
  double distortion_spread = 0.25;
  double principal_point_spread = 0.01;

  template <class V>
  void visit(V& v) {
    v("cameras", cameras, "Number of cameras (1 or more), placed by the layout generator.");
    v("width", width, "Image width in pixels.");
    v("height", height, "Image height in pixels.");
    v("distance_m", distance_m, "Distance from each camera to the head's centre, metres.");
    v("focal_length_mm", focal_length_mm, "Lens focal length, millimetres.");
    v("sensor_width_mm", sensor_width_mm,
      "Sensor width, millimetres (square pixels: the height follows from the image's aspect).");
    v("cap_half_angle_deg", cap_half_angle_deg,
      "Half-angle of the spherical cap in front of the face that the cameras cover, degrees.");
    v("distortion", distortion, "Lens distortion k1, k2, p1, p2, k3 (OpenCV's model) of a typical camera.");
    v("distortion_spread", distortion_spread,
      "Relative per-camera variation of the distortion coefficients (0 = all lenses equal).");
    v("principal_point_spread", principal_point_spread,
      "Per-camera offset of the principal point from the image centre, as a fraction of the width.");
  }
};

// Tracking errors written into the dataset's meshes only (dataset/meshes):
// the images, ground_truth/ and the dataset's images stay those of the true
// head, so an avatar trained on the dataset meets the errors a real tracked
// mesh has. Everything is off by default (the dataset's meshes are then the
// true coarse meshes, byte for byte). Applied in this order: lag, misfit (to
// the expression coefficients), then the shape misfit and the offset field
// (to the mesh).
// docs/virtual-studio.md#tracking-errors says what each models.
struct TrackingErrorOptions {
  double offset_m = 0.0;
  double offset_scale = 1.0;
  int offset_bumps = 6;
  int period_frames = 1;
  double lag = 0.0;
  bool lag_pose = false;
  double eyelid_misfit = 0.0;
  double eyelid_gain = 1.0;
  double lip_misfit = 0.0;
  double lip_gain = 1.0;
  double shape_misfit = 0.0;

  // Whether any of the errors changes a mesh.
  bool enabled() const {
    return offset_m != 0 || lag != 0 || eyelid_misfit != 0 || eyelid_gain != 1 || lip_misfit != 0 ||
           lip_gain != 1 || shape_misfit != 0;
  }

  template <class V>
  void visit(V& v) {
    v("offset_m", offset_m,
      "RMS, metres, over the skin (non-eyeball) vertices, of a smooth displacement field added to every "
      "frame's dataset mesh (0 = none): a sum of offset_bumps Gaussian bumps in the face frame, each "
      "with a random 3D direction, scaled to exactly this RMS in every frame; each eyeball moves "
      "rigidly with the field at its centre.");
    v("offset_scale", offset_scale,
      "Standard deviation of each bump of the offset field, in interocular distances (1 = about 6 cm): "
      "the field's wavelength.");
    v("offset_bumps", offset_bumps, "Number of Gaussian bumps in the offset field (1 or more).");
    v("period_frames", period_frames,
      "Frames between independent draws of the random errors (offset field, misfit errors): 1 = a new, "
      "independent draw every frame; N > 1 = draws at frames 0, N, 2N, ... of each take, blended "
      "smoothly in between (temporally correlated error).");
    v("lag", lag,
      "Temporal lag, frames (fractional allowed, 0 = none): the dataset mesh of frame t uses the "
      "expression of frame t - lag, linearly interpolated between frames, clamped at the take's first frame.");
    v("lag_pose", lag_pose,
      "Lag the rigid head pose too (interpolated by slerp; the dataset's head_to_world follows it); "
      "false = only the expression lags.");
    v("eyelid_misfit", eyelid_misfit,
      "Largest random error added to eyeBlink_L and eyeBlink_R (coefficient units, 0 = none): each eye "
      "gets its own uniform draw in [-eyelid_misfit, eyelid_misfit]; the result is clamped to [0, 1].");
    v("eyelid_gain", eyelid_gain,
      "Factor on eyeBlink_L and eyeBlink_R before the misfit error (1 = none; < 1: blinks that never "
      "quite close in the meshes).");
    v("lip_misfit", lip_misfit,
      "Largest random error added to each jaw* and mouth* expression the performance drives "
      "(coefficient units, 0 = none): a uniform draw per expression in [-lip_misfit, lip_misfit]; the "
      "result is clamped to [0, 1].");
    v("lip_gain", lip_gain,
      "Factor on the jaw* and mouth* expressions before the misfit error (1 = none; < 1: mouth shapes "
      "that the meshes under-state).");
    v("shape_misfit", shape_misfit,
      "Relative error of the tracker's expression shapes (0 = none): in the dataset's meshes each "
      "expression shape moves skin vertex v by (1 + shape_misfit * g_e(v)) times what the subject's "
      "face does, g_e a smooth random field like the offset field's (offset_bumps bumps of "
      "offset_scale) with RMS 1 over the skin, drawn once per expression from the seed: the same "
      "expression is wrong the same way in every frame and take. The eyeballs keep their motion.");
  }
};

// Cast shadows of the fine mesh from the studio's directional lights onto
// itself (creases, folds, an open mouth, the eye sockets): one shadow map per
// light per frame, filtered to a soft edge. Off by default (every image is
// then byte-identical to a studio without it).
// docs/virtual-studio.md#expression-dependent-appearance
struct SelfShadowOptions {
  bool enabled = false;
  int map_size = 1024;
  double softness_m = 0.001;

  template <class V>
  void visit(V& v) {
    v("enabled", enabled,
      "Shadow the directional lights' diffuse and specular terms by the head's own fine mesh (the "
      "ambient term and the light that wraps past the terminator stay unshadowed).");
    v("map_size", map_size,
      "Shadow map side, texels (64 .. 8192), spanning the head's bounding sphere: 1024 gives ~0.45 mm "
      "texels on ICT-FaceKit's head.");
    v("softness_m", softness_m,
      "Radius, metres, of the shadows' soft edge (percentage-closer filtering); at least one texel is used.");
  }
};

// Skin gloss (specular strength and Blinn-Phong exponent, scaled together)
// that follows the expression: stretched skin shinier, compressed skin and
// creases more matte, lips wetter as the jaw opens. Every factor is 1 by
// default, which leaves every image byte-identical.
// docs/virtual-studio.md#expression-dependent-appearance
struct ExpressionSpecularOptions {
  double stretch_exponent = 0.0;
  double crease_matte = 0.0;
  double wet_lips = 0.0;

  bool enabled() const { return stretch_exponent != 0 || crease_matte != 0 || wet_lips != 0; }

  template <class V>
  void visit(V& v) {
    v("stretch_exponent", stretch_exponent,
      "Gloss factor (area ratio)^stretch_exponent, the area ratio being that of the coarse mesh around "
      "a point against the neutral pose: > 1 stretched (shinier), < 1 compressed (more matte); 0 = none.");
    v("crease_matte", crease_matte,
      "Gloss factor (crease shading)^crease_matte in the wrinkles' creases, whose crease shading is "
      "1 - crease_darkening at the bottom of a full crease; 0 = none.");
    v("wet_lips", wet_lips,
      "Gloss factor 1 + wet_lips * lips * jawOpen: the lips (weight 1 at their centre) grow wetter as "
      "the jaw opens; 0 = none.");
  }
};

struct Options {
  StudioOptions studio;
  int frames = 30;
  int calibration_frames = 16;
  int64_t seed = 1;
  std::string head;
  double head_metres_per_unit = 0.01;
  std::vector<int> head_eyeball_polygons;
  std::vector<double> head_identity;
  double head_shape_detail_m = 0.0;
  std::vector<std::string> takes = {"expressions", "speech", "freestyle"};
  std::vector<std::string> test_takes = {"freestyle"};
  int test_cameras = 2;
  double fps = 30.0;
  int supersampling = 3;
  int fine_subdivisions = 2;
  double wrinkle_depth_m = 0.0012;
  double crease_darkening = 0.5;
  double noise_sigma = 0.004;
  bool write_fine_meshes = true;
  bool truth_apart = false;
  TrackingErrorOptions tracking_error;
  SelfShadowOptions self_shadowing;
  ExpressionSpecularOptions expression_specular;
  int threads = 0;

  template <class V>
  void visit(V& v) {
    v("studio", studio, "The virtual camera rig.");
    v("frames", frames, "Frames of each performance take.");
    v("calibration_frames", calibration_frames,
      "Frames of the calibration take (ChArUco board poses; needs OpenCV, skipped without it).");
    v("seed", seed, "Seed of everything random: skin texture, head motion, board poses, sensor noise.");
    v("head", head,
      "Blendshape model directory laid out like ICT-FaceKit; empty = the built-in procedural head.");
    v("head_metres_per_unit", head_metres_per_unit,
      "Units of the `head` model's files (ICT-FaceKit: 0.01, centimetres).");
    v("head_eyeball_polygons", head_eyeball_polygons,
      "First and last polygon index of the `head` model's eyeballs; empty = ICT-FaceKit's "
      "[21496, 24691] when the model has ICT-FaceKit's topology.");
    v("head_identity", head_identity,
      "Coefficients of the head model's identity shapes that make the subject (missing ones are 0; "
      "empty = the model's neutral head).");
    v("head_shape_detail_m", head_shape_detail_m,
      "Largest offset, metres, of a smooth shape detail added along the skin's normals that no "
      "combination of the model's shapes can express (0 = none): a subject the model only approximates.");
    v("takes", takes, "Performance takes to render, by script name: expressions, speech, freestyle.");
    v("test_takes", test_takes, "Performance takes whose frames form the dataset's test split.");
    v("test_cameras", test_cameras,
      "Cameras held out for the dataset's test split (clamped to 1 .. cameras - 1).");
    v("fps", fps, "Frame rate written into take.json (scripts span the take whatever its frame count).");
    v("supersampling", supersampling, "Samples per pixel along each axis (antialiasing).");
    v("fine_subdivisions", fine_subdivisions,
      "Subdivision levels from the coarse (tracked) mesh to the rendered fine mesh (each x4 triangles).");
    v("wrinkle_depth_m", wrinkle_depth_m, "Depth of the expression wrinkles at full activation, metres.");
    v("crease_darkening", crease_darkening,
      "Shading loss at the bottom of a fully formed wrinkle (0 = none, 1 = black).");
    v("noise_sigma", noise_sigma, "Standard deviation of sensor noise, in [0, 1] intensity units.");
    v("write_fine_meshes", write_fine_meshes,
      "Write the fine (rendered) mesh of every frame into ground_truth/ (large for long takes).");
    v("truth_apart", truth_apart,
      "Write the ground truth (the true rig.json, ground_truth/ and dataset/) into the sibling directory "
      "OUT.truth/ instead of into the capture OUT/, which then holds only what a capture session records "
      "(capture.json and takes/, no rig): a raw capture whose later stages cannot read the truth.");
    v("tracking_error", tracking_error,
      "Tracking errors in the dataset's meshes only (dataset/meshes; never the images or ground_truth/); "
      "all off by default.");
    v("self_shadowing", self_shadowing, "Cast shadows of the head on itself from the studio's lights; off by default.");
    v("expression_specular", expression_specular,
      "Skin gloss that changes with the expression (stretch, creases, wet lips); off by default.");
    v("threads", threads, "Worker threads; 0 = one per hardware thread.");
  }
};

}  // namespace tega::synth
